#pragma once
// Lights: the scene's light sources besides emissive surfaces and the environment — a closed
// set of types dispatched statically through std::variant, as the BSDF models are
// (bsdf/bsdf.h). The contract, written once:
//
//  * Each type is one struct: its parameters, listed by its parameters() hook, and what every
//    renderer asks of it. Nothing outside light/ switches on the type: loaders, the .plf file,
//    transforms, validation and the Python module go through the hook (createLight and the
//    functions after it), the samplers and the renderers through those at the end of this file.
//  * Units: positions and lengths in scene units; intensity I in W·sr⁻¹, irradiance E in
//    W·m⁻², radiance L in W·sr⁻¹·m⁻². A `direction` is the way the light travels.
//  * sample(x, u) gives the light arriving at a receiver at x (IncidentLight). A delta light
//    (kDelta: point, spot, directional) arrives from one direction: u is not used, `incident`
//    is the irradiance on a surface normal to wi and pdf is 1. Any other light is sampled:
//    wi has solid-angle density pdf (sr⁻¹) and `incident` is the radiance arriving along it.
//    Either way incident·max(0, n·wi)/pdf, times the shadow ray's transmittance, estimates the
//    irradiance on a surface of normal n (exactly, for a delta light).
//  * None of these lights is geometry: camera rays and rays after mirrors never see them and
//    nothing is shadowed by them. Shadow rays find them; a BSDF-sampled ray from a non-delta
//    vertex finds a sphere light by asking (light.h LightSampler::sphereLightAlong), so the
//    path tracer MIS-weights sphere lights between the two and counts the delta lights by
//    next-event estimation alone, and the light field holds their light where it lands on
//    surfaces.
//  * power(R) is the selection weight of the light samplers (light/light.h): an estimate of
//    the emitted flux's luminance, R the radius of the scene's bounding sphere (for lights at
//    infinity).
//
// Adding a light type: its struct below (kType, kDelta, kAtInfinity, the parameters() hook,
// problem, power, sample, shinesBehindPlane; pdf for a non-delta light; prepare and parallel
// where it needs them) and its entry at the end of the `Light` variant (the index is the .plf
// light number). The JSON scene format, the .plf file, transforms, validation, the path
// tracer, the bake and the renderers then take it as it is (docs/design.md "A new light").
#include "core/math.h"

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <variant>

namespace pl {

// ---- The parameter map -------------------------------------------------------------------

/// What a light parameter is: how a scene file gives it and how a transform moves it.
enum class LightParameterKind : uint8_t {
  Position,   ///< Vec3: a point (scene units), moved by transforms
  Direction,  ///< Vec3: the way light travels; turned by transforms, unit after Scene::finalize
  Emission,   ///< Rgb: the light's strength, intensity (W·sr⁻¹) or irradiance (W·m⁻²); files
              ///< may give one number for grey. Every type has exactly one.
  Angle,      ///< float: radians (JSON scenes give degrees)
  Length,     ///< float: scene units, scaled by transforms
};

/// One light's parameters by name, as a loader collected them: each a number, or three (a
/// position, direction or colour). The names are those of the types' parameters() hooks
/// (the JSON scene keys); values are in the struct's units (angles in radians unless
/// LightCreation::anglesInDegrees).
using LightParameterValue = std::variant<float, Vec3>;
using LightParameters = std::map<std::string, LightParameterValue, std::less<>>;

// ---- What a light gives a receiver -------------------------------------------------------

/// The light arriving at a receiver from one light (the contract above).
struct IncidentLight {
  Vec3 wi{0.0f};               ///< unit, from the receiver towards the light
  Rgb incident{0.0f};          ///< delta lights: irradiance normal to wi (W·m⁻²); others: radiance
  float pdf = 1.0f;            ///< solid-angle density of wi (sr⁻¹); 1 for delta lights
  float distance = kInfinity;  ///< to the point the light leaves from; ∞ at infinity
  Vec3 target{0.0f};           ///< where a shadow ray ends (finite distance only)
};

/// What a delta light at infinity (a sun) gives every point alike: the direction towards it
/// and its irradiance on a surface facing it. The light field's sun masks store the
/// visibility of that one direction (lightfield.h "Sun masks").
struct ParallelLight {
  Vec3 towardsLight{0.0f};
  Rgb irradiance{0.0f};
};

// ---- The types ---------------------------------------------------------------------------

/// Isotropic point light: intensity I; irradiance at distance d on a surface facing it I/d².
struct PointLight {
  static constexpr const char* kType = "point";
  static constexpr bool kDelta = true, kAtInfinity = false;
  Vec3 position{0.0f};
  Rgb intensity{1.0f};

  /// The serialisation hook every type has: f(name, kind, field) for each parameter, in the
  /// order of the .plf encoding (plf/plf_file.cpp); Self is the type, const or not.
  template <class Self, class F>
  static void parameters(Self& l, F&& f) {
    f("position", LightParameterKind::Position, l.position);
    f("intensity", LightParameterKind::Emission, l.intensity);
  }
  /// "" when valid, else what is wrong (completing "point light N …").
  std::string problem() const;
  /// 4π·Y(I).
  float power(float sceneRadius) const;
  std::optional<IncidentLight> sample(const Vec3& x, Vec2 u) const;
  /// Whether the light can reach the back of the plane {p : n·p = d0} (n unit): the side n·p < d0.
  bool shinesBehindPlane(const Vec3& n, float d0) const { return glm::dot(n, position) - d0 < 0.0f; }
};

/// Spot light: intensity I on its axis, full inside innerAngle, falling smoothly (smoothstep
/// in cos) to zero at outerAngle (a step when they coincide); angles in radians from the axis.
struct SpotLight {
  static constexpr const char* kType = "spot";
  static constexpr bool kDelta = true, kAtInfinity = false;
  Vec3 position{0.0f};
  Vec3 direction{0.0f, -1.0f, 0.0f};  ///< the way the light shines
  Rgb intensity{1.0f};
  float innerAngle = 0.3f;
  float outerAngle = 0.5f;
  /// Derived by prepare() (createLight and Scene::finalize call it): the unit axis and the
  /// cone cosines, computed once instead of per receiver.
  Vec3 axis{0.0f, -1.0f, 0.0f};
  float cosInner = 1.0f, cosOuter = 1.0f;

  template <class Self, class F>
  static void parameters(Self& l, F&& f) {
    f("position", LightParameterKind::Position, l.position);
    f("direction", LightParameterKind::Direction, l.direction);
    f("intensity", LightParameterKind::Emission, l.intensity);
    f("inner_angle", LightParameterKind::Angle, l.innerAngle);
    f("outer_angle", LightParameterKind::Angle, l.outerAngle);
  }
  void prepare();
  std::string problem() const;
  /// 2π·(1 − (cos θinner + cos θouter)/2)·Y(I) (pbrt's estimate).
  float power(float sceneRadius) const;
  std::optional<IncidentLight> sample(const Vec3& x, Vec2 u) const;
  bool shinesBehindPlane(const Vec3& n, float d0) const { return glm::dot(n, position) - d0 < 0.0f; }
};

/// Directional light at infinity (the sun): irradiance E on a surface facing it.
struct DirectionalLight {
  static constexpr const char* kType = "directional";
  static constexpr bool kDelta = true, kAtInfinity = true;
  Vec3 direction{0.0f, -1.0f, 0.0f};  ///< the way the light travels
  Rgb irradiance{1.0f};

  template <class Self, class F>
  static void parameters(Self& l, F&& f) {
    f("direction", LightParameterKind::Direction, l.direction);
    f("irradiance", LightParameterKind::Emission, l.irradiance);
  }
  std::string problem() const;
  /// π R²·Y(E): the flux through the disk of the scene's bounding sphere.
  float power(float sceneRadius) const;
  /// wi = −travel(), at infinity.
  std::optional<IncidentLight> sample(const Vec3& x, Vec2 u) const;
  /// The sun masks' direction and irradiance: −direction as the scene holds it.
  ParallelLight parallel() const { return {-direction, irradiance}; }
  bool shinesBehindPlane(const Vec3& n, float) const { return glm::dot(travel(), n) > 0.0f; }
  /// The travel direction sampling uses: normalize(direction). `direction` is unit already
  /// after Scene::finalize, but normalising again may move its last bits, and baked files
  /// depend on them: sampling uses this, the sun masks `direction` itself.
  Vec3 travel() const { return glm::normalize(direction); }
};

/// A sphere of radius r around `position` whose surface emits uniformly and diffusely,
/// outwards: radiance L = I/(π r²), so that from outside it has intensity I (W·sr⁻¹) in every
/// direction, as a point light of intensity I at its centre has, and the same flux 4π·I. A
/// receiver at distance d > r with the whole sphere above its tangent plane (d·cos θc ≥ r, θc
/// the angle to the centre) gets exactly that point light's irradiance I·cos θc/d² (Lambert:
/// E = L·π sin²α·cos θc with sin α = r/d, α the half-angle the sphere subtends); nearer the
/// horizon its light fades out smoothly, and its shadows are soft. Sampled uniformly over
/// that cone (pdf 1/(2π(1 − cos α))). A receiver inside the sphere gets nothing. Like every
/// light here it is no geometry: the camera and mirrors do not see the sphere itself.
struct SphereLight {
  static constexpr const char* kType = "sphere";
  static constexpr bool kDelta = false, kAtInfinity = false;
  Vec3 position{0.0f};
  float radius = 0.0f;  ///< scene units, > 0: no default, a scene must give it
  Rgb intensity{1.0f};

  template <class Self, class F>
  static void parameters(Self& l, F&& f) {
    f("position", LightParameterKind::Position, l.position);
    f("radius", LightParameterKind::Length, l.radius);
    f("intensity", LightParameterKind::Emission, l.intensity);
  }
  std::string problem() const;
  /// 4π·Y(I), the point light's.
  float power(float sceneRadius) const;
  std::optional<IncidentLight> sample(const Vec3& x, Vec2 u) const;
  float pdf(const Vec3& x, const Vec3& wi) const;
  bool shinesBehindPlane(const Vec3& n, float d0) const { return glm::dot(n, position) - d0 < radius; }
};

/// The closed set of light types. Adding one: its struct above and an entry here, at the end
/// (the index is the .plf light number).
using Light = std::variant<PointLight, SpotLight, DirectionalLight, SphereLight>;

// ---- Creating lights ---------------------------------------------------------------------

/// How createLight reads a parameter map.
struct LightCreation {
  bool anglesInDegrees = false;  ///< Angle parameters are given in degrees (JSON scenes)
  bool ignoreUnknown = false;    ///< skip parameters the type does not have (a glTF node gives
                                 ///< every light a position and a direction)
};

/// The one step the scene loaders (JSON, glTF) create lights through: a light of type `type`
/// (its kType, e.g. "point") with `parameters` set, the others at the type's defaults,
/// prepared. (The .plf reader fills a lightOfIndex through the same parameters() hook.) Throws pl::Error, its message starting with `where` (e.g.
/// "scene.json: lights[2]"), for an unknown type, an unknown parameter name or a value of the
/// wrong shape. Ranges are checked by lightProblem (Scene::finalize).
Light createLight(std::string_view type, const LightParameters& parameters, const std::string& where,
                  LightCreation options = {});
/// Sets the named parameters of an existing light (createLight's step after choosing the
/// type; the same errors), then prepares it. Ranges are not checked (lightProblem).
void setLightParameters(Light& light, const LightParameters& parameters, const std::string& where,
                        LightCreation options = {});
/// The type names, in variant order: "point, spot, directional, sphere".
std::string lightTypeNames();
/// A default light of variant index `index` (the .plf light number), for filling through
/// visitLightParameters; nullopt for an index no type has.
std::optional<Light> lightOfIndex(size_t index);

/// Calls f(name, kind, field) for every parameter of `light` (a Light or const Light), in the
/// .plf order.
template <class L, class F>
void visitLightParameters(L& light, F&& f) {
  std::visit([&](auto& l) { std::decay_t<decltype(l)>::parameters(l, f); }, light);
}

/// The type's name (kType).
const char* lightTypeName(const Light& light);
/// Recomputes what the type derives from its parameters (SpotLight::prepare); after any
/// change of a parameter. createLight, transformLight, setLightEmission and Scene::finalize
/// call it.
void prepareLight(Light& light);
/// "" when the parameters are valid (finite, directions non-zero, angles in range), else what
/// is wrong, completing "<type> light N …" (Scene::finalize prefixes file and index).
std::string lightProblem(const Light& light);
/// Moves a light by the affine transform m: positions by m, directions by its linear part,
/// lengths by the cube root of its |determinant| (exact for uniform scales).
void transformLight(Light& light, const Mat4& m);
/// Normalises every direction (Scene::finalize, after lightProblem found none zero); one unit
/// already to float precision is kept bit for bit, so that finalizing twice changes nothing.
void normaliseLightDirections(Light& light);
/// The light's Emission parameter (its intensity or irradiance), its name, and setting it.
Rgb lightEmission(const Light& light);
const char* lightEmissionName(const Light& light);
void setLightEmission(Light& light, const Rgb& emission);

// ---- What the samplers and renderers ask -------------------------------------------------

/// Whether the light is a delta light (one direction per receiver, no sampling).
bool isDeltaLight(const Light& light);
/// Whether the light is at infinity (its shadow rays are unbounded).
bool isAtInfinity(const Light& light);
/// A delta light at infinity's direction and irradiance (ParallelLight); nullopt for others.
std::optional<ParallelLight> parallelLight(const Light& light);
float lightPower(const Light& light, float sceneRadius);
/// The light arriving at x for the 2-D sample u (unused by delta lights); nullopt when none
/// does (x at a point light, outside a spot's cone, inside a sphere light).
std::optional<IncidentLight> sampleLight(const Light& light, const Vec3& x, Vec2 u);
/// The solid-angle density sampleLight has for wi at x; 0 for delta lights.
float lightPdf(const Light& light, const Vec3& x, const Vec3& wi);
/// Whether the light can reach the back (n·p < d0) of the plane {p : n·p = d0}, n unit.
bool shinesBehindPlane(const Light& light, const Vec3& n, float d0);

}  // namespace pl
