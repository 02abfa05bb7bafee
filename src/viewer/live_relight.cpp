// Live relighting in the viewer (see live_relight.h).
#include "viewer/live_relight.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <variant>

#include "bake/relight.h"
#include "core/cancel.h"
#include "core/error.h"
#include "core/parallel.h"
#include "light/lights.h"

namespace pl {
namespace {

constexpr float kSunStepDegrees = 5.0f;
constexpr float kMaxElevationDegrees = 89.0f;
constexpr float kDimmer = 0.8f, kBrighter = 1.25f, kDarker = 0.9f, kLighter = 1.1f;

/// The colours C cycles a source through (multiplying its baked emission).
constexpr Rgb kColours[] = {Rgb(1.0f), Rgb(1.0f, 0.75f, 0.5f), Rgb(0.6f, 0.8f, 1.0f),
                            Rgb(1.0f, 0.2f, 0.2f), Rgb(0.2f, 1.0f, 0.2f), Rgb(0.3f, 0.3f, 1.0f)};
constexpr const char* kColourNames[] = {"white", "warm", "cool", "red", "green", "blue"};
constexpr uint32_t kColourCount = sizeof(kColours) / sizeof(kColours[0]);

/// Azimuth and elevation (degrees; y up) of the direction towards a light travelling `travel`.
void sunAngles(const Vec3& travel, float& azimuth, float& elevation) {
  const Vec3 towards = -glm::normalize(travel);
  elevation = glm::degrees(std::asin(std::clamp(towards.y, -1.0f, 1.0f)));
  azimuth = glm::degrees(std::atan2(towards.x, towards.z));
}
Vec3 sunTravel(float azimuth, float elevation) {
  const float a = glm::radians(azimuth), e = glm::radians(elevation);
  return -Vec3(std::cos(e) * std::sin(a), std::sin(e), std::cos(e) * std::cos(a));
}

}  // namespace

LiveRelight::LiveRelight(const LightField& lightField, const Accel& accel, const std::string& visibilityPath,
                         RelightShare share)
    : original_(lightField), accel_(accel), visibilityPath_(visibilityPath), share_(share) {
  const Scene& scene = lightField.scene;
  lights_ = scene.lights;
  for (const Light& l : lights_) {
    savedLight_.push_back(lightEmission(l));
    baseLight_.push_back(lightEmission(l));
  }
  lightColour_.assign(lights_.size(), 0);
  for (uint32_t m = 0; m < scene.materials.size(); ++m) {
    const Material& material = scene.materials[m];
    emission_.push_back(material.emission);
    baseEmission_.push_back(material.emission);
    const auto* lambert = std::get_if<LambertBsdf>(&material.bsdf);
    albedo_.push_back(lambert ? lambert->albedo : Rgb(0.0f));
    if (lambert) lambertian_.push_back(m);
  }
  thread_ = std::thread([this] { work(); });
}

LiveRelight::~LiveRelight() {
  {
    const std::lock_guard lock(mutex_);
    quit_ = true;
  }
  restart_ = true;
  wake_.notify_all();
  // A set-up or an iteration in progress (minutes and seconds on a large scene) stops at its
  // next cancellation point (core/cancel.h): the viewer is closing, nothing else runs.
  requestCancellation();
  thread_.join();
  clearCancellation();
}

void LiveRelight::press(RelightKey key) {
  const size_t sources = lights_.size() + 1;  // the lights, then the emitters
  const bool emitters = source_ == lights_.size();
  // The sun the arrows turn: the selected light when directional, else the first directional one.
  auto sun = [&]() -> DirectionalLight* {
    if (!emitters)
      if (auto* d = std::get_if<DirectionalLight>(&lights_[source_])) return d;
    for (Light& l : lights_)
      if (auto* d = std::get_if<DirectionalLight>(&l)) return d;
    return nullptr;
  };
  auto scaleSource = [&](float factor) {
    if (emitters) {
      emitterScale_ *= factor;
    } else {
      savedLight_[source_] *= factor;
      if (!isBlack(lightEmission(lights_[source_]))) setLightEmission(lights_[source_], savedLight_[source_]);
    }
  };
  auto turnSun = [&](float dAzimuth, float dElevation) {
    DirectionalLight* d = sun();
    if (!d) return;
    float azimuth = 0.0f, elevation = 0.0f;
    sunAngles(d->direction, azimuth, elevation);
    elevation = std::clamp(elevation + dElevation, -kMaxElevationDegrees, kMaxElevationDegrees);
    d->direction = sunTravel(azimuth + dAzimuth, elevation);
  };
  const std::lock_guard lock(mutex_);
  switch (key) {
    case RelightKey::NextSource: source_ = (source_ + 1) % sources; return;  // selection only
    case RelightKey::NextMaterial:
      if (!lambertian_.empty()) material_ = (material_ + 1) % lambertian_.size();
      return;
    case RelightKey::ToggleSource:
      if (emitters) {
        emittersOn_ = !emittersOn_;
      } else {
        const bool on = !isBlack(lightEmission(lights_[source_]));
        setLightEmission(lights_[source_], on ? Rgb(0.0f) : savedLight_[source_]);
      }
      break;
    case RelightKey::Dimmer: scaleSource(kDimmer); break;
    case RelightKey::Brighter: scaleSource(kBrighter); break;
    case RelightKey::NextColour:
      if (emitters) {
        emitterColour_ = (emitterColour_ + 1) % kColourCount;
      } else {
        // The light's baked colour tinted, at its current strength (luminance).
        uint32_t& colour = lightColour_[source_];
        colour = (colour + 1) % kColourCount;
        const Rgb tinted = baseLight_[source_] * kColours[colour];
        savedLight_[source_] = tinted * (luminance(savedLight_[source_]) / std::max(1e-20f, luminance(tinted)));
        if (!isBlack(lightEmission(lights_[source_]))) setLightEmission(lights_[source_], savedLight_[source_]);
      }
      break;
    case RelightKey::SunLeft: turnSun(-kSunStepDegrees, 0.0f); break;
    case RelightKey::SunRight: turnSun(kSunStepDegrees, 0.0f); break;
    case RelightKey::SunUp: turnSun(0.0f, kSunStepDegrees); break;
    case RelightKey::SunDown: turnSun(0.0f, -kSunStepDegrees); break;
    case RelightKey::Darker:
    case RelightKey::Lighter:
      if (lambertian_.empty()) return;
      {
        Rgb& a = albedo_[lambertian_[material_]];
        a = glm::min(a * (key == RelightKey::Darker ? kDarker : kLighter), Rgb(1.0f));
      }
      break;
  }
  for (size_t m = 0; m < emission_.size(); ++m)
    emission_[m] = emittersOn_ ? baseEmission_[m] * emitterScale_ * kColours[emitterColour_] : Rgb(0.0f);
  pending_ = true;
  idle_ = false;
  restart_ = true;  // the propagation in progress stops at its next iteration
  wake_.notify_all();
}

void LiveRelight::work() {
  applyRelightPriority(share_);
  try {
    runWithThreads(1, [&] {
      relighter_ = std::make_unique<Relighter>(original_, visibilityPath_);
      buffers_[0] = original_;
      buffers_[1] = original_;
    });
    const std::lock_guard lock(mutex_);
    status_.ready = true;
  } catch (const std::exception& e) {
    const std::lock_guard lock(mutex_);
    status_.message = fmt::format("relighting off: {}", e.what());
    quit_ = true;
  }
  for (;;) {
    std::vector<Light> lights;
    std::vector<Rgb> emission, albedo;
    {
      std::unique_lock lock(mutex_);
      if (!pending_) {
        idle_ = true;
        idleChanged_.notify_all();
      }
      wake_.wait(lock, [&] { return pending_ || quit_; });
      if (quit_) {
        idle_ = true;
        idleChanged_.notify_all();
        return;
      }
      pending_ = false;
      restart_ = false;
      lights = lights_;
      emission = emission_;
      albedo = albedo_;
      status_.running = true;
      status_.message.clear();
    }
    try {
      for (uint32_t l = 0; l < lights.size(); ++l) relighter_->setLight(l, lights[l]);
      for (uint32_t m = 0; m < emission.size(); ++m) {
        if (emission[m] != relighter_->scene().materials[m].emission) relighter_->setEmission(m, emission[m]);
        const auto* lambert = std::get_if<LambertBsdf>(&relighter_->scene().materials[m].bsdf);
        if (lambert && lambert->albedo != albedo[m]) relighter_->setAlbedo(m, albedo[m]);
      }
      RelightStats stats;
      runWithThreads(1, [&] {
        stats = relighter_->relight([&](const RelightProgress& p) {
          // The buffer off screen, withdrawn from the viewer (ready_ = −1) while it is written.
          int back = 0;
          {
            const std::lock_guard lock(mutex_);
            back = shown_ == 0 ? 1 : 0;
            ready_ = -1;
          }
          renderers_[back].reset();
          relighter_->update(buffers_[back]);
          renderers_[back].emplace(buffers_[back], accel_);
          const std::lock_guard lock(mutex_);
          ready_ = back;
          status_.iteration = p.iteration;
          status_.residual = p.residual;
          status_.converged = p.converged;
          return !restart_.load();
        });
      });
      const std::lock_guard lock(mutex_);
      status_.running = false;
      status_.firstFrameSeconds = stats.firstFrameSeconds;
      status_.seconds = stats.seconds;
      status_.sunMaskSeconds = stats.sunMaskSeconds;
      status_.firstShotSeconds = stats.firstShotSeconds;
    } catch (const std::exception& e) {
      // A refusal: back to the lighting the Relighter holds.
      const std::lock_guard lock(mutex_);
      status_.running = false;
      status_.message = e.what();
      lights_ = relighter_->scene().lights;
      for (uint32_t m = 0; m < emission_.size(); ++m) {
        const Material& material = relighter_->scene().materials[m];
        emission_[m] = material.emission;
        if (const auto* lambert = std::get_if<LambertBsdf>(&material.bsdf)) albedo_[m] = lambert->albedo;
      }
    }
  }
}

bool LiveRelight::update() {
  std::unique_lock lock(mutex_, std::try_to_lock);
  if (!lock.owns_lock() || ready_ < 0) return false;
  shown_ = ready_;
  ready_ = -1;
  return true;
}

const FastRenderer* LiveRelight::renderer() const { return shown_ >= 0 ? &*renderers_[shown_] : nullptr; }

const LightField& LiveRelight::lightField() const { return shown_ >= 0 ? buffers_[shown_] : original_; }

RelightStatus LiveRelight::status() const {
  const std::lock_guard lock(mutex_);
  return status_;
}

bool LiveRelight::busy() const {
  const std::lock_guard lock(mutex_);
  if (!status_.ready) return status_.message.empty();  // setting up, or off
  return status_.running || pending_;
}

bool LiveRelight::showsNewest() const {
  const std::lock_guard lock(mutex_);
  return shown_ >= 0 && ready_ < 0;
}

void LiveRelight::waitIdle() {
  std::unique_lock lock(mutex_);
  idleChanged_.wait(lock, [&] { return (idle_ && !pending_) || quit_; });
}

std::string LiveRelight::sourceLine() const {
  if (source_ == lights_.size())
    return fmt::format("EMITTERS  X{:.2f}  {}  {}", emitterScale_, kColourNames[emitterColour_], emittersOn_ ? "ON" : "OFF");
  const Light& l = lights_[source_];
  const Rgb e = lightEmission(l);
  std::string line = fmt::format("LIGHT {}/{} {}  {} {:.3g} {:.3g} {:.3g}  {}", source_ + 1, lights_.size(), lightTypeName(l),
                                 lightEmissionName(l), savedLight_[source_].r, savedLight_[source_].g,
                                 savedLight_[source_].b, isBlack(e) ? "OFF" : "ON");
  if (const auto* d = std::get_if<DirectionalLight>(&l)) {
    float azimuth = 0.0f, elevation = 0.0f;
    sunAngles(d->direction, azimuth, elevation);
    line += fmt::format("  AZ {:.0f} EL {:.0f}", azimuth, elevation);
  }
  return line;
}

std::vector<std::string> LiveRelight::hudLines() const {
  std::vector<std::string> lines;
  const RelightStatus s = status();
  lines.push_back(sourceLine());
  if (!lambertian_.empty()) {
    const uint32_t m = lambertian_[material_];
    const Rgb a = albedo_[m];
    lines.push_back(fmt::format("MATERIAL {} ALBEDO {:.2f} {:.2f} {:.2f}", original_.scene.materials[m].name, a.r, a.g, a.b));
  }
  if (!s.ready && s.message.empty()) lines.push_back("RELIGHT: PREPARING");
  else if (s.ready)
    lines.push_back(s.running ? fmt::format("RELIGHT: ITERATION {}  RESIDUAL {:.1e}", s.iteration, s.residual)
                              : fmt::format("RELIGHT: {} AFTER {} ITERATIONS ({:.2f} S, FIRST FRAME {:.2f} S)",
                                            s.converged ? "CONVERGED" : "STOPPED", s.iteration, s.seconds,
                                            s.firstFrameSeconds));
  if (!s.message.empty()) lines.push_back(s.message);
  return lines;
}

}  // namespace pl
