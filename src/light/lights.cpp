// Lights (see lights.h): each type's validation, power and sampling, then the generic steps
// built on the parameters() hook.
#include "light/lights.h"

#include <algorithm>
#include <cmath>
#include <set>
#include <utility>

#include "core/error.h"

namespace pl {

namespace {

/// The light of a point source of intensity I·falloff at `position`: wi, the distance and the
/// irradiance I·falloff/d² normal to wi. `falloff(wi)` is the spot's cone (1 for a point light).
template <class Falloff>
std::optional<IncidentLight> incidentFromPoint(const Vec3& position, const Rgb& intensity, const Vec3& x,
                                               Falloff&& falloff) {
  const Vec3 toLight = position - x;
  const float distanceSquared = glm::dot(toLight, toLight);
  if (!(distanceSquared > 0.0f)) return std::nullopt;
  IncidentLight in;
  in.distance = std::sqrt(distanceSquared);
  in.wi = toLight / in.distance;
  const float f = falloff(in.wi);
  if (!(f > 0.0f)) return std::nullopt;
  in.incident = intensity * (f / distanceSquared);
  in.target = position;
  return in;
}

}  // namespace

// ---- Point -------------------------------------------------------------------------------

std::string PointLight::problem() const {
  return isFinite(position) && isFinite(intensity) ? "" : "has a non-finite position or intensity";
}

float PointLight::power(float) const { return 4.0f * kPi * luminance(intensity); }

std::optional<IncidentLight> PointLight::sample(const Vec3& x, Vec2) const {
  return incidentFromPoint(position, intensity, x, [](const Vec3&) { return 1.0f; });
}

// ---- Spot --------------------------------------------------------------------------------

void SpotLight::prepare() {
  axis = glm::normalize(direction);
  cosInner = std::cos(innerAngle);
  cosOuter = std::cos(outerAngle);
}

std::string SpotLight::problem() const {
  if (!isFinite(position) || !isFinite(intensity) || !isFinite(direction) || glm::length(direction) == 0.0f)
    return "has a non-finite position/intensity or no direction";
  if (!(innerAngle >= 0.0f && innerAngle <= outerAngle && outerAngle <= kPi))
    return fmt::format("needs 0 <= inner angle ({}) <= outer angle ({}) <= pi", innerAngle, outerAngle);
  return "";
}

float SpotLight::power(float) const { return 2.0f * kPi * (1.0f - 0.5f * (cosInner + cosOuter)) * luminance(intensity); }

std::optional<IncidentLight> SpotLight::sample(const Vec3& x, Vec2) const {
  return incidentFromPoint(position, intensity, x, [&](const Vec3& wi) {
    const float c = glm::dot(axis, -wi);
    if (cosInner <= cosOuter) return c >= cosInner ? 1.0f : 0.0f;
    const float t = std::clamp((c - cosOuter) / (cosInner - cosOuter), 0.0f, 1.0f);
    return t * t * (3.0f - 2.0f * t);
  });
}

// ---- Directional -------------------------------------------------------------------------

std::string DirectionalLight::problem() const {
  return isFinite(direction) && isFinite(irradiance) && glm::length(direction) != 0.0f
             ? ""
             : "has a non-finite irradiance or no direction";
}

float DirectionalLight::power(float sceneRadius) const { return kPi * sceneRadius * sceneRadius * luminance(irradiance); }

std::optional<IncidentLight> DirectionalLight::sample(const Vec3&, Vec2) const {
  IncidentLight in;
  in.wi = -travel();
  in.incident = irradiance;
  return in;
}

// ---- Sphere ------------------------------------------------------------------------------

std::string SphereLight::problem() const {
  if (!isFinite(position) || !isFinite(intensity) || !(std::min({intensity.r, intensity.g, intensity.b}) >= 0.0f))
    return "has a non-finite position or a negative or non-finite intensity";
  if (!(radius > 0.0f && std::isfinite(radius))) return fmt::format("needs a finite radius > 0 (got {})", radius);
  return "";
}

float SphereLight::power(float) const { return 4.0f * kPi * luminance(intensity); }

namespace {
/// The cone a sphere of radius² r2 at distance² d2 > r2 subtends: 1 − cos α, from
/// sin²α = r2/d2 as sin²α/(1 + cos α), which keeps its digits when the sphere is small or far.
float oneMinusCosCone(float r2, float d2) {
  const float sin2 = r2 / d2;
  return sin2 / (1.0f + std::sqrt(std::max(0.0f, 1.0f - sin2)));
}
}  // namespace

std::optional<IncidentLight> SphereLight::sample(const Vec3& x, Vec2 u) const {
  const Vec3 toCentre = position - x;
  const float d2 = glm::dot(toCentre, toCentre), r2 = radius * radius;
  if (!(d2 > r2)) return std::nullopt;
  const float d = std::sqrt(d2);
  const float coneWidth = oneMinusCosCone(r2, d2);
  // Uniform over the cone: 1 − cos θ = u.x·(1 − cos α), φ = 2π·u.y about the axis to the centre.
  const float oneMinusCos = u.x * coneWidth;
  const float cosTheta = 1.0f - oneMinusCos;
  const float sin2Theta = std::max(0.0f, oneMinusCos * (2.0f - oneMinusCos));
  const float sinTheta = std::sqrt(sin2Theta), phi = kTwoPi * u.y;
  IncidentLight in;
  const Vec3 local(sinTheta * std::cos(phi), sinTheta * std::sin(phi), cosTheta);
  in.wi = glm::normalize(Frame::fromNormal(toCentre / d).toWorld(local));
  // The near point where wi meets the sphere: t = d·cos θ − √(r² − d²·sin²θ).
  in.distance = std::max(0.0f, d * cosTheta - std::sqrt(std::max(0.0f, r2 - d2 * sin2Theta)));
  in.target = x + in.distance * in.wi;
  in.incident = intensity / (kPi * r2);
  in.pdf = 1.0f / (kTwoPi * coneWidth);
  return in;
}

float SphereLight::pdf(const Vec3& x, const Vec3& wi) const {
  const Vec3 toCentre = position - x;
  const float d2 = glm::dot(toCentre, toCentre), r2 = radius * radius;
  if (!(d2 > r2)) return 0.0f;
  const float coneWidth = oneMinusCosCone(r2, d2);
  const float cosTheta = glm::dot(wi, toCentre) / std::sqrt(d2);
  return cosTheta >= 1.0f - coneWidth ? 1.0f / (kTwoPi * coneWidth) : 0.0f;
}

// ---- Creating lights ---------------------------------------------------------------------

namespace {

/// The parameter names of a type, for messages: "position, intensity".
template <class T>
std::string parameterNames() {
  std::string names;
  T light;
  T::parameters(light, [&](const char* name, LightParameterKind, auto&) {
    names += names.empty() ? name : fmt::format(", {}", name);
  });
  return names;
}

template <size_t... I>
std::optional<Light> lightNamed(std::string_view type, std::index_sequence<I...>) {
  std::optional<Light> light;
  ((type == std::variant_alternative_t<I, Light>::kType ? (void)light.emplace(std::in_place_index<I>) : (void)0), ...);
  return light;
}

template <size_t... I>
std::optional<Light> lightAtIndex(size_t index, std::index_sequence<I...>) {
  std::optional<Light> light;
  ((index == I ? (void)light.emplace(std::in_place_index<I>) : (void)0), ...);
  return light;
}

constexpr auto kLightIndices = std::make_index_sequence<std::variant_size_v<Light>>();

}  // namespace

std::string lightTypeNames() {
  std::string names;
  for (size_t i = 0; i < std::variant_size_v<Light>; ++i) {
    if (i > 0) names += ", ";
    names += lightTypeName(*lightOfIndex(i));
  }
  return names;
}

std::optional<Light> lightOfIndex(size_t index) { return lightAtIndex(index, kLightIndices); }

Light createLight(std::string_view type, const LightParameters& parameters, const std::string& where,
                  LightCreation options) {
  std::optional<Light> light = lightNamed(type, kLightIndices);
  if (!light) fail("{}: unknown light type '{}' ({})", where, type, lightTypeNames());
  setLightParameters(*light, parameters, where, options);
  return *light;
}

void setLightParameters(Light& light, const LightParameters& parameters, const std::string& where,
                        LightCreation options) {
  std::set<std::string_view> known;
  std::visit(
      [&](auto& l) {
        using T = std::decay_t<decltype(l)>;
        T::parameters(l, [&](const char* name, LightParameterKind kind, auto& field) {
          known.insert(name);
          const auto at = parameters.find(std::string_view(name));
          if (at == parameters.end()) return;
          using Field = std::decay_t<decltype(field)>;
          if constexpr (std::is_same_v<Field, Vec3>) {
            if (const Vec3* v = std::get_if<Vec3>(&at->second)) field = *v;
            else if (kind == LightParameterKind::Emission) field = Rgb(std::get<float>(at->second));
            else fail("{}.{}: expected [x, y, z], got one number", where, name);
          } else {
            const float* v = std::get_if<float>(&at->second);
            if (!v) fail("{}.{}: expected a number, got three", where, name);
            field = kind == LightParameterKind::Angle && options.anglesInDegrees ? glm::radians(*v) : *v;
          }
        });
        if (!options.ignoreUnknown)
          for (const auto& entry : parameters)
            if (!known.count(entry.first))
              fail("{}: unknown key '{}' for a {} light ({})", where, entry.first, T::kType, parameterNames<T>());
      },
      light);
  prepareLight(light);
}

// ---- Generic steps over the parameters ---------------------------------------------------

const char* lightTypeName(const Light& light) {
  return std::visit([](const auto& l) { return std::decay_t<decltype(l)>::kType; }, light);
}

void prepareLight(Light& light) {
  std::visit(
      [](auto& l) {
        if constexpr (requires { l.prepare(); }) l.prepare();
      },
      light);
}

std::string lightProblem(const Light& light) {
  return std::visit([](const auto& l) { return l.problem(); }, light);
}

void transformLight(Light& light, const Mat4& m) {
  const Mat3 linear(m);
  const float lengthScale = std::cbrt(std::abs(glm::determinant(linear)));
  visitLightParameters(light, [&](const char*, LightParameterKind kind, auto& field) {
    using Field = std::decay_t<decltype(field)>;
    if constexpr (std::is_same_v<Field, Vec3>) {
      if (kind == LightParameterKind::Position) field = Vec3(m * Vec4(field, 1.0f));
      if (kind == LightParameterKind::Direction) field = linear * field;
    } else {
      if (kind == LightParameterKind::Length) field *= lengthScale;
    }
  });
  prepareLight(light);
}

void normaliseLightDirections(Light& light) {
  // A direction already unit to float precision (|d|² within 1e-6 of 1, as normalize leaves
  // it) is kept bit for bit: normalising it again may move its last bits, so a scene finalized
  // twice (a light field's, read and finalized by a relighter) would no longer be the scene
  // that was baked (the .pls and .plt keys hash these bits).
  visitLightParameters(light, [](const char*, LightParameterKind kind, auto& field) {
    if constexpr (std::is_same_v<std::decay_t<decltype(field)>, Vec3>)
      if (kind == LightParameterKind::Direction && !(std::abs(glm::dot(field, field) - 1.0f) <= 1e-6f))
        field = glm::normalize(field);
  });
  prepareLight(light);
}

namespace {
/// The Emission parameter's field and name (every type has exactly one).
template <class L>
std::pair<std::conditional_t<std::is_const_v<L>, const Rgb*, Rgb*>, const char*> emissionOf(L& light) {
  std::pair<std::conditional_t<std::is_const_v<L>, const Rgb*, Rgb*>, const char*> found{nullptr, ""};
  visitLightParameters(light, [&](const char* name, LightParameterKind kind, auto& field) {
    if constexpr (std::is_same_v<std::decay_t<decltype(field)>, Vec3>)
      if (kind == LightParameterKind::Emission) found = {&field, name};
  });
  return found;
}
}  // namespace

Rgb lightEmission(const Light& light) { return *emissionOf(light).first; }
const char* lightEmissionName(const Light& light) { return emissionOf(light).second; }
void setLightEmission(Light& light, const Rgb& emission) {
  *emissionOf(light).first = emission;
  prepareLight(light);
}

// ---- What the samplers and renderers ask -------------------------------------------------

bool isDeltaLight(const Light& light) {
  return std::visit([](const auto& l) { return std::decay_t<decltype(l)>::kDelta; }, light);
}

bool isAtInfinity(const Light& light) {
  return std::visit([](const auto& l) { return std::decay_t<decltype(l)>::kAtInfinity; }, light);
}

std::optional<ParallelLight> parallelLight(const Light& light) {
  return std::visit(
      [](const auto& l) -> std::optional<ParallelLight> {
        if constexpr (requires { l.parallel(); }) return l.parallel();
        else return std::nullopt;
      },
      light);
}

float lightPower(const Light& light, float sceneRadius) {
  return std::visit([&](const auto& l) { return l.power(sceneRadius); }, light);
}

std::optional<IncidentLight> sampleLight(const Light& light, const Vec3& x, Vec2 u) {
  return std::visit([&](const auto& l) { return l.sample(x, u); }, light);
}

float lightPdf(const Light& light, const Vec3& x, const Vec3& wi) {
  return std::visit(
      [&](const auto& l) {
        if constexpr (std::decay_t<decltype(l)>::kDelta) return 0.0f;
        else return l.pdf(x, wi);
      },
      light);
}

bool shinesBehindPlane(const Light& light, const Vec3& n, float d0) {
  return std::visit([&](const auto& l) { return l.shinesBehindPlane(n, d0); }, light);
}

}  // namespace pl
