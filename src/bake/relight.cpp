// Relighting (see relight.h).
#include "bake/relight.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <optional>
#include <variant>

#include "accel/accel.h"
#include "bake/first_shot.h"
#include "bake/propagation.h"
#include "bake/shard.h"
#include "core/error.h"
#include "core/hash.h"
#include "core/parallel.h"
#include "core/timing.h"
#include "light/lights.h"
#include "plf/plv_file.h"

namespace pl {

using Values = std::vector<Rgb>;
using Note = std::function<void(const std::string&)>;

std::string rebakeCommand(const Scene& scene, const BakeSettings& settings) {
  return fmt::format("plenoptic bake {} --preset {} -o NEW.plf", scene.sourcePath,
                     settings.preset.empty() ? std::string("default") : settings.preset);
}

std::string visibilityPathFor(const std::string& plfPath) {
  return std::filesystem::path(plfPath).replace_extension(".plv").string();
}

namespace {

/// The same sky: the same map object, or maps of the same texels, scale and rotation (a scene
/// loaded again, or read from a .plf, holds its own copy of an unchanged map).
bool sameEnvironment(const Environment& a, const Environment& b) {
  if (a.constant != b.constant) return false;
  if (a.map == b.map) return true;
  if (!a.map || !b.map) return false;
  const Image &x = a.map->map().image, &y = b.map->map().image;
  return a.map->scale() == b.map->scale() && a.map->rotationDegrees() == b.map->rotationDegrees() &&
         x.width == y.width && x.height == y.height && x.pixels == y.pixels;
}

/// The per-channel factor k with after = k ⊙ before, when there is one: every channel of
/// `before` positive (or both black: k unset, any factor fits).
std::optional<Rgb> channelFactor(const Rgb& before, const Rgb& after) {
  if (!(before.r > 0.0f && before.g > 0.0f && before.b > 0.0f)) return std::nullopt;
  return after / before;
}

bool sameFactor(const Rgb& a, const Rgb& b) {
  for (int k = 0; k < 3; ++k)
    if (std::abs(a[k] - b[k]) > 1e-6f * std::max(std::abs(a[k]), std::abs(b[k]))) return false;
  return true;
}

}  // namespace

struct Relighter::Impl {
  Note log;
  Scene scene;  ///< every edit so far (the transport state reads it)
  BakeSettings settings;
  BakeStats stats;
  std::unique_ptr<Accel> accel;
  Parameterisation param;
  VisibilityShard vis;
  std::unique_ptr<TransportState> state;
  // The first shot by source (relight.h): per light at unit emission, and the emitters'.
  std::vector<Values> lightDirect, lightPunctual;
  Values emitterDirect;
  // What the current solution was computed for (the last relight()).
  std::vector<Light> appliedLights;
  std::vector<Material> appliedMaterials;
  Environment appliedEnvironment;
  std::vector<Light> bakedLights;      ///< the lights the parameterisation's sides were decided for
  std::vector<uint8_t> lightMoved;      ///< per light: its D_l must be traced again
  bool firstShotRead = false;           ///< the first shot by source came from a .pls
  uint64_t visHash = 0;                 ///< the visibility field's hash (this light field's)
  std::string unreadVisibility;         ///< the .plv whose reading waits until a gather needs it
  uint64_t unreadBudget = 0;            ///< its decodedBudget
  bool converged = true;                ///< the baked values are converged

  /// The visibility field: in memory, or the path of its .plv.
  using VisibilitySource = std::variant<VisibilityShard, std::string>;

  Impl(const LightField& lf, VisibilitySource source, std::optional<Parameterisation> given, Note note,
       uint64_t decodedBudget = 0)
      : log(std::move(note)), scene(lf.scene), settings(lf.settings), stats(lf.stats) {
    const auto start = std::chrono::steady_clock::now();
    scene.finalize();  // a copied scene lacks the vertex padding the BVH shares (scene.h)
    accel = std::make_unique<Accel>(scene);
    const std::string* path = std::get_if<std::string>(&source);
    if (given) {
      param = std::move(*given);
    } else {
      param = buildCharts(scene, *accel, settings);
      if (!path || !readSavedTixelSetup(*path, lf)) fillTixels(scene, *accel, param, 0, uint32_t(param.charts.size()));
    }
    const double setupSeconds = secondsSince(start);
    const uint64_t hash = visibilityHash(scene, param, settings);
    visHash = hash;
    state = std::make_unique<TransportState>(scene, *accel, param, settings);
    // The first shot by source: read from the .pls beside the .plv when one was written for
    // this light field (first_shot.h), else shot below. When it is read, the visibility field
    // is read only once something needs it (a gather: an iteration, or D_e shot again), so a
    // change that needs neither (a recolour that scales the solution, nothing changed) never
    // decodes it; its header is checked now.
    const bool stored = path && (firstShotRead = readStoredFirstShot(*path, hash));
    if (stored) {
      const VisibilityFileInfo info = readVisibilityInfo(*path);
      if (info.hash != hash || info.tixelCount != param.tixelCount)
        fail("{}: relighting needs the visibility field {} that was baked with this light field, but it was traced "
             "for another scene or settings (hash {:016x}, {} tixels; this light field's {:016x}, {} tixels)",
             scene.sourcePath, *path, info.hash, info.tixelCount, hash, param.tixelCount);
      unreadVisibility = *path;
      unreadBudget = decodedBudget;
    } else if (path) {
      readVisibilityField(*path, decodedBudget);
    } else {
      vis = std::move(std::get<VisibilityShard>(source));
    }
    if (unreadVisibility.empty() &&
        (vis.ranges.size() != 1 || vis.ranges[0] != TixelRange{0, param.tixelCount} || vis.field.hash != hash))
      fail("{}: the visibility field in memory (hash {:016x}, {} tixels) was not traced for this light field (hash "
           "{:016x}, {} tixels): relighting needs the .plv baked with it",
           scene.sourcePath, vis.field.hash, vis.field.tixelCount, hash, param.tixelCount);
    if (lf.values.size() != param.valueCount || lf.charts.size() != param.charts.size() ||
        lf.sunMaskLightCount != param.sunMaskLights.size())
      fail("{}: the light field's values ({} values, {} charts, {} sun-mask lights) do not match its parameterisation "
           "({} values, {} charts, {} sun-mask lights)",
           scene.sourcePath, lf.values.size(), lf.charts.size(), lf.sunMaskLightCount, param.valueCount,
           param.charts.size(), param.sunMaskLights.size());
    const auto shotStart = std::chrono::steady_clock::now();
    if (!stored) {
      lightDirect.resize(scene.lights.size());
      lightPunctual.resize(scene.lights.size());
      for (uint32_t l = 0; l < scene.lights.size(); ++l) shootLight(l);
      shootEmitters();
    }
    const double shotSeconds = secondsSince(shotStart);
    bakedLights = scene.lights;
    snapshot();
    state->direct = combine(lightDirect, emitterDirect);
    if (!state->punctualGlossy.empty()) state->punctualGlossy = combine(lightPunctual, {});
    beginIteration(*state);  // allocates the transport; the warm start replaces current below
    state->current = unfinished(lf.values);
    updateTransport(*state, 0, param.tixelCount);
    lightMoved.assign(scene.lights.size(), 0);
    if (log)
      log(fmt::format("relight: ready ({} lights, {} tixels): BVH and parameterisation {:.2f} s, first shot by source "
                      "{:.2f} s{}",
                      scene.lights.size(), param.tixelCount, setupSeconds, shotSeconds,
                      stored ? fmt::format(" (read from {})", firstShotPathFor(*path)) : std::string()));
  }

  /// Reads the visibility field at `path` into vis, decoded when that takes at most `budget`
  /// bytes; pl::Error when it does not belong to this light field.
  void readVisibilityField(const std::string& path, uint64_t budget) {
    VisibilityField field;
    std::string why;
    const uint64_t side = gatherGridSide(settings.gatherDirections);
    const bool hold = param.tixelCount > 0 && param.tixelCount * side * side * sizeof(VisibilityEntry) <= budget;
    std::vector<VisibilityEntry> decoded;
    if (!readVisibility(path, visHash, field, &why, param.tixelCount, hold ? &decoded : nullptr))
      fail("{}: relighting needs the visibility field {} that was baked with this light field, but {}",
           scene.sourcePath, path, why);
    vis = VisibilityShard::of(std::move(field), {TixelRange{0, param.tixelCount}});
    if (hold) vis.decoded = FieldArray<VisibilityEntry>(std::move(decoded));
  }
  /// The visibility field, read now if its reading was put off (see the constructor).
  const VisibilityShard& visibility() {
    if (!unreadVisibility.empty()) {
      readVisibilityField(unreadVisibility, unreadBudget);
      unreadVisibility.clear();
    }
    return vis;
  }

  /// The first shot by source from the .pls beside the .plv at `visibilityPath`, when one was
  /// written for this light field (its key: first_shot.h). False, with a note saying why when
  /// there is a file, when there is none that fits (the caller shoots).
  bool readStoredFirstShot(const std::string& visibilityPath, uint64_t hash) {
    const std::string shotPath = firstShotPathFor(visibilityPath);
    FirstShotBySource shot;
    std::string why;
    std::error_code ec;
    const bool exists = std::filesystem::exists(shotPath, ec);
    if (!exists || !readFirstShot(shotPath, hash, firstShotKey(scene, param, settings, hash),
                                  uint32_t(scene.lights.size()), param.valueCount, !state->punctualGlossy.empty(),
                                  shot, &why)) {
      if (exists && log) log(fmt::format("relight: shooting the first shot by source again, because {}", why));
      return false;
    }
    lightDirect = std::move(shot.lightDirect);
    lightPunctual = std::move(shot.lightPunctual);
    lightPunctual.resize(scene.lights.size());
    emitterDirect = std::move(shot.emitterDirect);
    refreshEmitters(*state);  // the light sampler's powers, as shootEmitters leaves them
    return true;
  }

  /// Writes the first shot by source of the applied scene (the last relight()) to `path`.
  void saveFirstShot(const std::string& path) const {
    if (pending()) fail("{}: the first shot by source is saved after relight(), with no edit pending", path);
    Scene applied = scene;
    applied.lights = appliedLights;
    applied.materials = appliedMaterials;
    applied.environment = appliedEnvironment;
    FirstShotBySource shot;
    shot.lightDirect = lightDirect;
    if (!state->punctualGlossy.empty()) shot.lightPunctual = lightPunctual;
    shot.emitterDirect = emitterDirect;
    writeFirstShot(path, visHash, firstShotKey(applied, param, settings, visHash), shot);
  }

  /// The tixel setup saved beside the .plv at `visibilityPath` (parameterisation.h
  /// readTixelSetup) into param, whose charts buildCharts made: false, with a note saying why,
  /// when there is none that belongs to that .plv (the caller fills the tixels again).
  bool readSavedTixelSetup(const std::string& visibilityPath, const LightField& lf) {
    const std::string setupPath = tixelSetupPathFor(visibilityPath);
    std::string why;
    std::error_code ec;
    if (!std::filesystem::exists(visibilityPath, ec))  // (before minutes of filling the tixels)
      fail("{}: relighting needs the visibility field {} that was baked with this light field, but {} does not exist",
           scene.sourcePath, visibilityPath, visibilityPath);
    const uint64_t hash = readVisibilityInfo(visibilityPath).hash;
    // First keyed against the light field's scene (parameterisation.h reuseTixelSetup): a .plt
    // written for another light field of the same geometry, or one whose charts a warm-started
    // bake marked (warm_start.h), gets the charts of each changed material filled again and the
    // masks of each moved light traced again. Else taken as it is (a .plt without keys).
    TixelSetupReuse reuse;
    if (lf.sunMaskLightCount != param.sunMaskLights.size())
      why = "the light field's sun masks do not match its charts";
    else if (reuseTixelSetup(setupPath, hash, scene, *accel, param, reuse, &why) ||
             readTixelSetup(setupPath, hash, lf.sunMasks, param, &why))
      return true;
    if (log)
      log(fmt::format("relight: filling the tixels again (buried-point probes, footprints, sun masks), because {}; "
                      "a bake writes {} beside its .plv",
                      why, setupPath));
    return false;
  }

  void snapshot() {
    appliedLights = scene.lights;
    appliedMaterials = scene.materials;
    appliedEnvironment = scene.environment;
  }

  [[noreturn]] void refuse(const std::string& why) const {
    fail("{}: cannot relight: {}; the stored visibility field does not serve this change. Re-bake the edited scene: {}",
         scene.sourcePath, why, rebakeCommand(scene, settings));
  }

  /// Runs shootShadowRays for `sources` alone into zeroed first-shot arrays and returns them
  /// (direct, punctual glossy part).
  std::pair<Values, Values> shoot(const ShadowRaySources& sources) {
    Values direct(param.valueCount, Rgb(0.0f)), punctual;
    if (!state->punctualGlossy.empty()) punctual.assign(param.valueCount, Rgb(0.0f));
    {
      const SwappedIn swapped(*state, direct, punctual);
      shootShadowRays(*state, 0, param.tixelCount, nullptr, sources);
    }
    return {std::move(direct), std::move(punctual)};
  }

  /// Swaps scratch arrays into state.direct and state.punctualGlossy for a first-shot stage,
  /// and back when it ends, also by an exception (a cancelled relight leaves the state whole).
  struct SwappedIn {
    TransportState& state;
    Values &direct, &punctual;
    SwappedIn(TransportState& s, Values& d, Values& p) : state(s), direct(d), punctual(p) { swap(); }
    ~SwappedIn() { swap(); }
    void swap() {
      std::swap(state.direct, direct);
      std::swap(state.punctualGlossy, punctual);
    }
  };

  /// D_l: light l's first shot at unit emission.
  void shootLight(uint32_t l) {
    ShadowRaySources sources;
    sources.lights.assign(scene.lights.size(), 0);
    sources.lights[l] = 1;
    sources.emitters = false;
    sources.unitEmission = true;
    auto [direct, punctual] = shoot(sources);
    lightDirect[l] = std::move(direct);
    lightPunctual[l] = std::move(punctual);
  }

  /// D_e: the emissive surfaces' shadow rays, the gathered emission and environment, caustics.
  void shootEmitters() {
    refreshEmitters(*state);
    ShadowRaySources sources;
    sources.lights.assign(scene.lights.size(), 0);
    auto [direct, punctual] = shoot(sources);
    {
      const SwappedIn swapped(*state, direct, punctual);
      gatherEmission(*state, visibility(), 0, param.tixelCount);
      shootCaustics(*state);
      finishFirstShot(*state);
    }
    emitterDirect = std::move(direct);
  }

  /// Σ_l E_l ⊙ perLight[l] (+ `rest` when not empty), with the scene's current emissions.
  Values combine(const std::vector<Values>& perLight, const Values& rest) const {
    Values out = combineFirstShot(scene, perLight, rest);
    if (out.empty()) out.assign(param.valueCount, Rgb(0.0f));
    return out;
  }


  /// The iterate behind stored values (finishValues and removeSunMaskedDirect undone): the
  /// masked lights' first shot back on diffuse tixels, the glossy emission out, the punctual
  /// highlights back in. (What those steps clamped at 0 stays lost: a warm start only.)
  Values unfinished(const Values& stored) const {
    Values it = stored;
    std::vector<uint8_t> masked(scene.lights.size(), 0);
    for (uint32_t l : param.sunMaskLights) masked[l] = 1;
    parallelFor(param.charts.size(), [&](uint64_t ci) {
      const Chart& c = param.charts[ci];
      if (c.kind == ChartKind::Specular) return;
      const uint64_t v0 = c.firstValue, v1 = c.firstValue + c.tixelCount() * c.valuesPerTixel();
      if (c.kind == ChartKind::Diffuse) {
        // (A subsurface chart has no sun masks: its first shot traced the masked lights too.)
        if (isSubsurfaceChart(scene, c)) return;
        for (uint32_t l = 0; l < scene.lights.size(); ++l) {
          if (!masked[l]) continue;
          const Rgb e = lightEmission(scene.lights[l]);
          for (uint64_t v = v0; v < v1; ++v) it[v] += e * lightDirect[l][v];
        }
        return;
      }
      for (uint64_t local = 0; local < c.tixelCount(); ++local) {
        const Rgb le = tixelEmittedRadiance(scene, param, c, c.firstTixel + local, 1.0f);
        for (uint64_t t = 0; t < c.directionTexels(); ++t) it[c.firstValue + local * c.valuesPerTixel() + t] -= le;
      }
      if (!state->punctualGlossy.empty())
        for (uint64_t v = v0; v < v1; ++v) it[v] += state->punctualGlossy[v];
      for (uint64_t v = v0; v < v1; ++v) it[v] = glm::max(it[v], Rgb(0.0f));
    });
    return it;
  }

  // ---- Edits ----------------------------------------------------------------------------

  void requireLight(uint32_t index) const {
    if (index >= scene.lights.size())
      fail("{}: light {} does not exist ({} lights)", scene.sourcePath, index, scene.lights.size());
  }
  void requireMaterial(uint32_t index) const {
    if (index >= scene.materials.size())
      fail("{}: material {} does not exist ({} materials)", scene.sourcePath, index, scene.materials.size());
  }

  /// Under a black environment the bake gave back sides only to open surfaces that something
  /// lights or sees from behind (parameterisation.h "Sides"): a one-sided chart with the whole
  /// scene in front of it and no baked light behind it may be open, and a light that now
  /// shines behind it would have made the bake store its back.
  void requireNoNewBackSide(uint32_t index, const Light& light) const {
    if (!scene.environment.isBlack()) return;
    Vec3 lo, hi;
    scene.bounds(lo, hi);
    const float tolerance = 1e-4f * glm::length(hi - lo);
    for (const Chart& c : param.charts) {
      if (c.sides != 1 || c.kind == ChartKind::Specular) continue;
      const float d0 = glm::dot(c.normal, c.origin);
      if (!shinesBehindPlane(light, c.normal, d0)) continue;
      bool lit = false;
      for (int k = 0; k < 8 && !lit; ++k) {
        const Vec3 corner((k & 1) ? hi.x : lo.x, (k & 2) ? hi.y : lo.y, (k & 4) ? hi.z : lo.z);
        lit = glm::dot(c.normal, corner) - d0 < -tolerance;
      }
      for (const Light& baked : bakedLights) lit = lit || shinesBehindPlane(baked, c.normal, d0);
      if (!lit)
        refuse(fmt::format("light {} would shine on the back of a one-sided surface (material '{}'), which the bake "
                           "stored without a back side",
                           index, scene.materials[c.material].name));
    }
  }

  void setLight(uint32_t index, Light light) {
    requireLight(index);
    if (light.index() != scene.lights[index].index())
      refuse(fmt::format("light {} would change from a {} light to a {} light", index, lightTypeName(scene.lights[index]),
                         lightTypeName(light)));
    if (const std::string problem = lightProblem(light); !problem.empty())
      fail("{}: {} light {} {}", scene.sourcePath, lightTypeName(light), index, problem);
    normaliseLightDirections(light);
    prepareLight(light);
    if (lightPlacement(light) != lightPlacement(scene.lights[index])) {
      requireNoNewBackSide(index, light);
      lightMoved[index] = 1;
    }
    scene.lights[index] = light;
  }

  void setEmission(uint32_t m, const Rgb& emission) {
    requireMaterial(m);
    Material& material = scene.materials[m];
    if (!(std::isfinite(emission.r) && std::isfinite(emission.g) && std::isfinite(emission.b)) || emission.r < 0.0f ||
        emission.g < 0.0f || emission.b < 0.0f)
      fail("{}: material '{}': emission must be finite and non-negative", scene.sourcePath, material.name);
    if (!material.isEmissive() && !isBlack(emission)) {
      for (const Chart& c : param.charts)
        if (c.material == m && c.curved)
          refuse(fmt::format("material '{}' would start to emit, and emitters get planar charts, not the curved ones it "
                             "was baked with",
                             material.name));
      if (material.emissionTexture >= 0 && param.emissionModulation.empty())
        refuse(fmt::format("material '{}' would start to emit through an emission texture, which the bake did not "
                           "sample",
                           material.name));
    }
    material.emission = emission;
  }

  /// The subsurface operator (bake/subsurface.h) was built by random walks for the material's
  /// albedo and radius: changing them needs new walks, which the relighting does not trace.
  [[noreturn]] void refuseSubsurfaceEdit(const Material& material) const {
    refuse(fmt::format("material '{}' is subsurface, and its albedo and radius shape the light carried through the "
                       "object, whose random walks the bake traced",
                       material.name));
  }

  void setAlbedo(uint32_t m, const Rgb& albedo) {
    requireMaterial(m);
    Material& material = scene.materials[m];
    auto* lambert = std::get_if<LambertBsdf>(&material.bsdf);
    if (subsurfaceMedium(material.bsdf)) refuseSubsurfaceEdit(material);
    if (!lambert)
      refuse(fmt::format("material '{}' is not Lambertian: only a Lambertian albedo can change without re-baking",
                         material.name));
    for (int k = 0; k < 3; ++k)
      if (!(albedo[k] >= 0.0f && albedo[k] <= 1.0f))
        fail("{}: material '{}': albedo must be in [0, 1]", scene.sourcePath, material.name);
    if (material.albedoVaries() && !channelFactor(lambert->albedo, albedo) && !isBlack(albedo))
      refuse(fmt::format("material '{}' has a textured albedo with a zero channel, whose texture the bake did not "
                         "average",
                         material.name));
    lambert->albedo = albedo;
  }

  void setScene(const Scene& edited) {
    if (edited.lights.size() != scene.lights.size())
      refuse(fmt::format("the scene has {} lights, the light field {}: lights cannot be added or removed",
                         edited.lights.size(), scene.lights.size()));
    if (edited.materials.size() != scene.materials.size() || visibilityHash(edited, param, settings) != visHash)
      refuse("its geometry, its materials' kinds or their mirror and glass parameters changed");
    if (edited.environment.isBlack() != scene.environment.isBlack())
      refuse("the environment would turn black or stop being black, which decides the surfaces' back sides");
    for (uint32_t m = 0; m < scene.materials.size(); ++m) {
      const Material &a = scene.materials[m], &b = edited.materials[m];
      const bool lambert = std::holds_alternative<LambertBsdf>(a.bsdf) && std::holds_alternative<LambertBsdf>(b.bsdf);
      if (!lambert && modelParameterHash(a.bsdf) != modelParameterHash(b.bsdf) && subsurfaceMedium(a.bsdf) && subsurfaceMedium(b.bsdf))
        refuseSubsurfaceEdit(a);
      if (!lambert && modelParameterHash(a.bsdf) != modelParameterHash(b.bsdf))
        refuse(fmt::format("material '{}' changed its model or its parameters", a.name));
      if (a.emissionTexture != b.emissionTexture || a.twoSidedEmission != b.twoSidedEmission ||
          a.albedoTexture != b.albedoTexture)
        refuse(fmt::format("material '{}' changed its textures or emitting sides", a.name));
    }
    // Each setter checks its own change; a refusal leaves every edit of this call undone.
    const std::vector<Light> lights = scene.lights;
    const std::vector<Material> materials = scene.materials;
    const std::vector<uint8_t> moved = lightMoved;
    try {
      for (uint32_t l = 0; l < scene.lights.size(); ++l) setLight(l, edited.lights[l]);
      for (uint32_t m = 0; m < scene.materials.size(); ++m) {
        const Material& b = edited.materials[m];
        if (b.emission != scene.materials[m].emission) setEmission(m, b.emission);
        if (const auto* lb = std::get_if<LambertBsdf>(&b.bsdf))
          if (lb->albedo != std::get<LambertBsdf>(scene.materials[m].bsdf).albedo) setAlbedo(m, lb->albedo);
      }
    } catch (...) {
      scene.lights = lights;
      scene.materials = materials;
      lightMoved = moved;
      throw;
    }
    scene.environment = edited.environment;
  }

  bool emittersChanged() const {
    if (!sameEnvironment(scene.environment, appliedEnvironment)) return true;
    for (size_t m = 0; m < scene.materials.size(); ++m)
      if (scene.materials[m].emission != appliedMaterials[m].emission) return true;
    return false;
  }
  std::vector<uint32_t> albedoChanges() const {
    std::vector<uint32_t> changed;
    for (uint32_t m = 0; m < scene.materials.size(); ++m) {
      const auto* now = std::get_if<LambertBsdf>(&scene.materials[m].bsdf);
      const auto* before = std::get_if<LambertBsdf>(&appliedMaterials[m].bsdf);
      if (now && before && now->albedo != before->albedo) changed.push_back(m);
    }
    return changed;
  }
  bool pending() const {
    if (emittersChanged() || !albedoChanges().empty()) return true;
    for (size_t l = 0; l < scene.lights.size(); ++l)
      if (lightMoved[l] || lightEmission(scene.lights[l]) != lightEmission(appliedLights[l])) return true;
    return false;
  }

  // ---- Relighting ----------------------------------------------------------------------

  /// When D_e is the old one scaled per channel: the one emissive material of a scene under a
  /// black environment, recoloured (relight.h). Returns the factor.
  std::optional<Rgb> emitterScale() const {
    if (!scene.environment.isBlack() || !appliedEnvironment.isBlack()) return std::nullopt;
    std::optional<uint32_t> only;
    for (uint32_t m = 0; m < scene.materials.size(); ++m) {
      if (!appliedMaterials[m].isEmissive() && !scene.materials[m].isEmissive()) continue;
      if (only) return std::nullopt;
      only = m;
    }
    if (!only) return Rgb(1.0f);
    return channelFactor(appliedMaterials[*only].emission, scene.materials[*only].emission);
  }

  /// The transport albedo of material m's tixels for its new Lambertian albedo (fillTixels'
  /// value: the albedo, or on a textured material its footprint mean, which scales with it).
  void applyAlbedo(uint32_t m) {
    const Rgb now = std::get<LambertBsdf>(scene.materials[m].bsdf).albedo;
    const Rgb before = std::get<LambertBsdf>(appliedMaterials[m].bsdf).albedo;
    const bool textured = scene.materials[m].modelVaries();
    const Rgb factor = textured ? channelFactor(before, now).value_or(Rgb(0.0f)) : Rgb(0.0f);
    for (const Chart& c : param.charts) {
      if (c.material != m || c.kind != ChartKind::Diffuse) continue;
      for (uint64_t g = c.firstTixel; g < c.firstTixel + c.tixelCount(); ++g)
        param.transportAlbedo[g] = textured ? param.transportAlbedo[g] * factor : now;
    }
  }

  RelightStats relight(const RelightCallback& onIteration) {
    const auto start = std::chrono::steady_clock::now();
    RelightStats out;
    const bool changes = pending();
    if (!changes && converged) {
      out.converged = true;
      if (onIteration) onIteration({0, 0.0, true, 0.0});
      return out;
    }
    // 1. The sources' first shot. Per light: its factor k_l (new emission over old), unset
    // when it moved or was black and stays black.
    bool scalable = true;
    std::optional<Rgb> k;
    auto factor = [&](const Rgb& before, const Rgb& after) {
      if (isBlack(before) && isBlack(after)) return;
      const std::optional<Rgb> f = channelFactor(before, after);
      if (!f || (k && !sameFactor(*k, *f))) scalable = false;
      else k = f;
    };
    for (uint32_t l = 0; l < scene.lights.size(); ++l) {
      if (lightMoved[l]) {
        scalable = false;
        const int slot = sunMaskSlot(param, l);
        if (slot >= 0) {
          const auto masksStart = std::chrono::steady_clock::now();
          recomputeSunMasks(scene, *accel, param, size_t(slot));
          out.sunMaskSeconds += secondsSince(masksStart);
          ++out.sunMasksTraced;
        }
        const auto shotStart = std::chrono::steady_clock::now();
        shootLight(l);
        out.firstShotSeconds += secondsSince(shotStart);
        ++out.lightsShot;
        lightMoved[l] = 0;
      } else {
        factor(lightEmission(appliedLights[l]), lightEmission(scene.lights[l]));
      }
    }
    if (emittersChanged()) {
      const auto shotStart = std::chrono::steady_clock::now();
      if (const std::optional<Rgb> scale = emitterScale()) {
        for (Rgb& v : emitterDirect) v *= *scale;
        refreshEmitters(*state);  // the sampler's powers, for the next time D_e is traced
        out.emittersScaled = true;
        for (uint32_t m = 0; m < scene.materials.size(); ++m)
          factor(appliedMaterials[m].emission, scene.materials[m].emission);
      } else {
        shootEmitters();
        out.emittersShot = true;
        scalable = false;
      }
      out.firstShotSeconds += secondsSince(shotStart);
    } else {
      for (uint32_t m = 0; m < scene.materials.size(); ++m)
        factor(appliedMaterials[m].emission, scene.materials[m].emission);
      if (!scene.environment.isBlack()) factor(Rgb(1.0f), Rgb(1.0f));
    }
    // 2. Albedo, direct, warm start.
    const auto warmStart = std::chrono::steady_clock::now();
    const std::vector<uint32_t> albedo = albedoChanges();
    for (uint32_t m : albedo) applyAlbedo(m);
    Values direct = combine(lightDirect, emitterDirect);
    Values& current = state->current;
    out.scaledWarmStart = scalable && k.has_value();
    if (out.scaledWarmStart) {
      const Rgb f = *k;
      parallelForRange(current.size(), 4096, [&](uint64_t v0, uint64_t v1) {
        for (uint64_t v = v0; v < v1; ++v) current[v] *= f;
      });
    } else {
      // current + the change of the first shot, which on subsurface tixels leaves through the object.
      Values delta(current.size());
      const Values& before = state->direct;
      parallelForRange(current.size(), 4096, [&](uint64_t v0, uint64_t v1) {
        for (uint64_t v = v0; v < v1; ++v) delta[v] = direct[v] - before[v];
      });
      subsurfaceDirectChange(*state, delta);
      parallelForRange(current.size(), 4096, [&](uint64_t v0, uint64_t v1) {
        for (uint64_t v = v0; v < v1; ++v) current[v] = glm::max(Rgb(0.0f), current[v] + delta[v]);
      });
    }
    state->direct = std::move(direct);
    if (!state->punctualGlossy.empty()) state->punctualGlossy = combine(lightPunctual, {});
    updateTransport(*state, 0, param.tixelCount);
    snapshot();
    // A converged solution scaled exactly stays converged (with the albedo unchanged).
    converged = converged && out.scaledWarmStart && albedo.empty();
    out.warmStartSeconds = secondsSince(warmStart);
    out.firstFrameSeconds = secondsSince(start);
    out.converged = converged;
    if (onIteration && !onIteration({0, 0.0, converged, out.firstFrameSeconds})) out.cancelled = true;
    // 3. The bake's iteration and stopping rule.
    if (!converged && !out.cancelled) {
      const VisibilityShard& field = visibility();
      StoppingRule stopping(transportPower(*state, current), settings.tolerance);
      PropagationResult result;
      for (uint32_t iteration = 1; iteration <= settings.maxIterations; ++iteration) {
        iterateTransport(*state, field, stopping.omega());
        const double power = transportPower(*state, current);
        if (!std::isfinite(power))
          fail("{}: light propagation overflowed in relighting iteration {}: the total power is not finite; scale the "
               "emission down",
               scene.sourcePath, iteration);
        converged = stopping.converged(iteration, power, transportChange(*state), result);
        out.iterations = iteration;
        out.residual = result.residual;
        if (onIteration && !onIteration({iteration, result.residual, converged, secondsSince(start)})) {
          out.cancelled = !converged;
          break;
        }
        if (converged) break;
      }
    }
    out.converged = converged;
    out.seconds = secondsSince(start);
    return out;
  }

  void update(LightField& lf) const {
    Values values = state->current;
    finishValues(*state, values);
    lf.scene.lights = appliedLights;
    lf.scene.materials = appliedMaterials;
    lf.scene.environment = appliedEnvironment;
    lf.settings = settings;
    storeLightField(lf, param, std::move(values));
  }
};

Relighter::Relighter(const LightField& lightField, VisibilityShard visibility, const Note& log)
    : impl_(std::make_unique<Impl>(lightField, std::move(visibility), std::nullopt, log)) {}
Relighter::Relighter(const LightField& lightField, VisibilityShard visibility, Parameterisation param, const Note& log)
    : impl_(std::make_unique<Impl>(lightField, std::move(visibility), std::move(param), log)) {}
Relighter::Relighter(const LightField& lightField, const std::string& visibilityPath, const Note& log,
                     uint64_t decodedBudget)
    : impl_(std::make_unique<Impl>(lightField, visibilityPath, std::nullopt, log, decodedBudget)) {}
Relighter::~Relighter() = default;
Relighter::Relighter(Relighter&&) noexcept = default;
Relighter& Relighter::operator=(Relighter&&) noexcept = default;

const Scene& Relighter::scene() const { return impl_->scene; }
const Parameterisation& Relighter::parameterisation() const { return impl_->param; }

void Relighter::setLightEmission(uint32_t index, const Rgb& emission) {
  impl_->requireLight(index);
  Light light = impl_->scene.lights[index];
  pl::setLightEmission(light, emission);
  impl_->setLight(index, light);
}
void Relighter::setLight(uint32_t index, const Light& light) { impl_->setLight(index, light); }
void Relighter::setEmission(uint32_t material, const Rgb& emission) { impl_->setEmission(material, emission); }
void Relighter::setAlbedo(uint32_t material, const Rgb& albedo) { impl_->setAlbedo(material, albedo); }
void Relighter::setScene(const Scene& edited) { impl_->setScene(edited); }
bool Relighter::pending() const { return impl_->pending(); }
RelightStats Relighter::relight(const RelightCallback& onIteration) { return impl_->relight(onIteration); }
void Relighter::update(LightField& lf) const { impl_->update(lf); }
void Relighter::saveFirstShot(const std::string& path) const { impl_->saveFirstShot(path); }
bool Relighter::firstShotRead() const { return impl_->firstShotRead; }

LightField Relighter::lightField() const {
  LightField lf;
  lf.scene = impl_->scene;
  lf.stats = impl_->stats;
  update(lf);
  return lf;
}

}  // namespace pl
