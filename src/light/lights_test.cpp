// The light types (lights.h): every type created from its parameter map, through the JSON
// scene format and moved by a transform, the messages for bad parameter maps, and each type's
// sampling against its closed form.
#include "light/lights.h"

#include <gtest/gtest.h>

#include <cmath>
#include <glm/gtc/matrix_transform.hpp>
#include <fstream>
#include <vector>

#include "core/error.h"
#include "scene/scene.h"
#include "support/light_parameters.h"
#include "support/temp_dir_test.h"

namespace pl {
namespace {

using test_support::lightParameterFloats;

/// The parameters of lightWithDistinctParameters(index) as a parameter map, its angles ×100
/// in degrees when `degrees` (0.4 → 40°).
LightParameters distinctParameters(size_t index, bool degrees) {
  LightParameters parameters;
  const Light light = test_support::lightWithDistinctParameters(index);
  visitLightParameters(light, [&](const char* name, LightParameterKind kind, const auto& field) {
    if constexpr (std::is_same_v<std::decay_t<decltype(field)>, Vec3>) parameters[name] = field;
    else parameters[name] = kind == LightParameterKind::Angle && degrees ? 100.0f * field : field;
  });
  return parameters;
}

// Every type: createLight sets each parameter from the map (the JSON keys are the hook's
// names), the type is known by its name, and its index is the .plf light number.
TEST(Lights, EveryTypeIsCreatedFromItsParameterMap) {
  for (size_t index = 0; index < std::variant_size_v<Light>; ++index) {
    const std::string type = lightTypeName(*lightOfIndex(index));
    SCOPED_TRACE(type);
    const LightParameters parameters = distinctParameters(index, false);
    const Light light = createLight(type, parameters, "test");
    EXPECT_EQ(light.index(), index);
    visitLightParameters(light, [&](const char* name, LightParameterKind, const auto& field) {
      const LightParameterValue& given = parameters.at(name);
      if constexpr (std::is_same_v<std::decay_t<decltype(field)>, Vec3>) EXPECT_EQ(field, std::get<Vec3>(given)) << name;
      else EXPECT_EQ(field, std::get<float>(given)) << name;
    });
    EXPECT_EQ(lightProblem(light), "");
    int emissions = 0;
    visitLightParameters(light, [&](const char*, LightParameterKind kind, const auto&) {
      emissions += kind == LightParameterKind::Emission;
    });
    EXPECT_EQ(emissions, 1);
    EXPECT_NE(lightTypeNames().find(type), std::string::npos);
  }
  EXPECT_FALSE(lightOfIndex(std::variant_size_v<Light>).has_value());
}

// Bad maps are refused with the place, the key and what was expected.
TEST(Lights, BadParameterMapsNameTheProblem) {
  auto message = [](auto&& create) {
    try {
      create();
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(message([] { createLight("laser", {}, "s.json: lights[0]"); }),
            "s.json: lights[0]: unknown light type 'laser' (" + lightTypeNames() + ")");
  EXPECT_EQ(message([] { createLight("point", {{"radius", 1.0f}}, "s.json: lights[1]"); }),
            "s.json: lights[1]: unknown key 'radius' for a point light (position, intensity)");
  EXPECT_EQ(message([] { createLight("point", {{"position", 1.0f}}, "w"); }),
            "w.position: expected [x, y, z], got one number");
  EXPECT_EQ(message([] { createLight("spot", {{"inner_angle", Vec3(1.0f)}}, "w"); }),
            "w.inner_angle: expected a number, got three");
  // Unknown names pass when asked to (a glTF node gives every light its whole pose).
  EXPECT_NO_THROW(createLight("point", {{"direction", Vec3(1.0f)}}, "w", {.ignoreUnknown = true}));
  // A colour may be one number (grey).
  EXPECT_EQ(lightEmission(createLight("point", {{"intensity", 2.0f}}, "w")), Rgb(2.0f));
}

// The JSON scene format is the parameter map: one light of every type, angles in degrees,
// comes out as createLight makes it (with its directions made unit by Scene::finalize).
class LightsJson : public test_support::TempDirTest {};
TEST_F(LightsJson, EveryTypeLoadsFromAJsonScene) {
  std::string lights;
  std::vector<Light> expected;
  for (size_t index = 0; index < std::variant_size_v<Light>; ++index) {
    const std::string type = lightTypeName(*lightOfIndex(index));
    const LightParameters parameters = distinctParameters(index, true);
    std::string entry = "{\"type\": \"" + type + "\"";
    for (const auto& [name, value] : parameters) {
      if (const Vec3* v = std::get_if<Vec3>(&value)) entry += fmt::format(", \"{}\": [{}, {}, {}]", name, v->x, v->y, v->z);
      else entry += fmt::format(", \"{}\": {}", name, std::get<float>(value));
    }
    lights += (lights.empty() ? "" : ", ") + entry + "}";
    Light light = createLight(type, parameters, "test", {.anglesInDegrees = true});
    normaliseLightDirections(light);
    expected.push_back(light);
  }
  std::ofstream(path("lights.json")) << "{\"include_cornell\": true, \"lights\": [" << lights << "]}";
  const Scene scene = loadScene(path("lights.json"));
  ASSERT_EQ(scene.lights.size(), expected.size());
  for (size_t i = 0; i < expected.size(); ++i) {
    EXPECT_EQ(scene.lights[i].index(), expected[i].index());
    EXPECT_EQ(lightParameterFloats(scene.lights[i]), lightParameterFloats(expected[i])) << lightTypeName(expected[i]);
  }
}

// Finalizing twice changes no bit of a light: a light field's scene, read back and finalized
// again (a relighter's), must still be the scene that was baked, whose lights the .pls and
// .plt keys hash. Directions far from unit (here 1.07 and 3.1 long) are normalised once.
TEST(Lights, NormalisingTwiceKeepsEveryBit) {
  for (const Vec3 direction : {Vec3(0.25f, -1.0f, 0.3f), Vec3(-1.7f, 2.3f, 1.3f), Vec3(0.0f, -1.0f, 0.0f)}) {
    Light once = createLight("directional", {{"direction", direction}, {"irradiance", 3.0f}}, "test");
    normaliseLightDirections(once);
    Light twice = once;
    normaliseLightDirections(twice);
    EXPECT_EQ(lightParameterFloats(once), lightParameterFloats(twice));
    const Vec3 unit = std::get<DirectionalLight>(once).direction;
    EXPECT_NEAR(glm::length(unit), 1.0f, 1e-6f);
    EXPECT_NEAR(glm::dot(unit, glm::normalize(direction)), 1.0f, 1e-6f);
  }
}

// A transform moves positions, turns directions and scales lengths, by the kind of each
// parameter.
TEST(Lights, TransformsMoveEachParameterByItsKind) {
  const Mat4 m = glm::translate(glm::scale(Mat4(1.0f), Vec3(2.0f)), Vec3(1.0f, 0.0f, 0.0f));  // x ↦ 2x + (2, 0, 0)
  for (size_t index = 0; index < std::variant_size_v<Light>; ++index) {
    const Light before = createLight(lightTypeName(*lightOfIndex(index)), distinctParameters(index, false), "test");
    Light after = before;
    transformLight(after, m);
    std::vector<Vec3> vectorsBefore, vectorsAfter;
    std::vector<float> numbersBefore, numbersAfter;
    std::vector<LightParameterKind> kinds;
    auto collect = [&](std::vector<Vec3>& vectors, std::vector<float>& numbers) {
      return [&](const char*, LightParameterKind kind, const auto& field) {
        kinds.push_back(kind);
        if constexpr (std::is_same_v<std::decay_t<decltype(field)>, Vec3>) vectors.push_back(field);
        else numbers.push_back(field);
      };
    };
    visitLightParameters(before, collect(vectorsBefore, numbersBefore));
    kinds.clear();
    visitLightParameters(after, collect(vectorsAfter, numbersAfter));
    size_t v = 0, n = 0;
    for (const LightParameterKind kind : kinds) {
      switch (kind) {
        case LightParameterKind::Position:
          EXPECT_EQ(vectorsAfter[v], 2.0f * vectorsBefore[v] + Vec3(2.0f, 0.0f, 0.0f));
          ++v;
          break;
        case LightParameterKind::Direction: EXPECT_EQ(vectorsAfter[v], 2.0f * vectorsBefore[v]); ++v; break;
        case LightParameterKind::Emission: EXPECT_EQ(vectorsAfter[v], vectorsBefore[v]); ++v; break;
        case LightParameterKind::Angle: EXPECT_EQ(numbersAfter[n], numbersBefore[n]); ++n; break;
        case LightParameterKind::Length: EXPECT_NEAR(numbersAfter[n], 2.0f * numbersBefore[n], 1e-6f); ++n; break;
      }
    }
  }
}

// The delta lights against their closed forms: a point light gives I/d² along the line to it,
// a spot the same inside its inner cone and nothing outside its outer one, a directional light
// its irradiance from −direction everywhere (the sun masks' direction and irradiance).
TEST(Lights, DeltaLightsGiveTheirClosedForms) {
  const Light point = createLight("point", {{"position", Vec3(0.0f, 2.0f, 0.0f)}, {"intensity", Rgb(8.0f)}}, "test");
  const std::optional<IncidentLight> p = sampleLight(point, Vec3(0.0f), Vec2(0.3f));
  ASSERT_TRUE(p);
  EXPECT_EQ(p->wi, Vec3(0.0f, 1.0f, 0.0f));
  EXPECT_EQ(p->incident, Rgb(2.0f));
  EXPECT_EQ(p->pdf, 1.0f);
  EXPECT_EQ(p->target, Vec3(0.0f, 2.0f, 0.0f));
  EXPECT_FALSE(sampleLight(point, Vec3(0.0f, 2.0f, 0.0f), Vec2(0.3f)));  // at the light
  EXPECT_TRUE(isDeltaLight(point));
  EXPECT_FALSE(isAtInfinity(point));
  EXPECT_FALSE(parallelLight(point));
  EXPECT_FLOAT_EQ(lightPower(point, 1.0f), 4.0f * kPi * 8.0f);

  const Light spot = createLight("spot",
                                 {{"position", Vec3(0.0f, 2.0f, 0.0f)},
                                  {"direction", Vec3(0.0f, -3.0f, 0.0f)},
                                  {"intensity", Rgb(8.0f)},
                                  {"inner_angle", 0.2f},
                                  {"outer_angle", 0.4f}},
                                 "test");
  EXPECT_EQ(sampleLight(spot, Vec3(0.0f), Vec2(0.5f))->incident, Rgb(2.0f));
  EXPECT_FALSE(sampleLight(spot, Vec3(2.0f * std::tan(0.41f), 0.0f, 0.0f), Vec2(0.5f)));
  const float half = sampleLight(spot, Vec3(2.0f * std::tan(0.3f), 0.0f, 0.0f), Vec2(0.5f))->incident.r;
  EXPECT_GT(half, 0.0f);
  EXPECT_LT(half, 2.0f);

  const Light sun = createLight("directional", {{"direction", Vec3(0.0f, -1.0f, 0.0f)}, {"irradiance", Rgb(3.0f)}}, "test");
  for (const Vec3& x : {Vec3(0.0f), Vec3(1e4f, -5.0f, 3.0f)}) {
    const std::optional<IncidentLight> s = sampleLight(sun, x, Vec2(0.5f));
    EXPECT_EQ(s->wi, Vec3(0.0f, 1.0f, 0.0f));
    EXPECT_EQ(s->incident, Rgb(3.0f));
    EXPECT_TRUE(std::isinf(s->distance));
  }
  EXPECT_TRUE(isAtInfinity(sun));
  EXPECT_EQ(parallelLight(sun)->towardsLight, Vec3(0.0f, 1.0f, 0.0f));
  EXPECT_EQ(parallelLight(sun)->irradiance, Rgb(3.0f));
  EXPECT_TRUE(shinesBehindPlane(sun, Vec3(0.0f, -1.0f, 0.0f), 0.0f));  // from above onto a plane facing down
  EXPECT_FALSE(shinesBehindPlane(sun, Vec3(0.0f, 1.0f, 0.0f), 0.0f));
  EXPECT_TRUE(shinesBehindPlane(point, Vec3(0.0f, -1.0f, 0.0f), 0.0f));
  EXPECT_FALSE(shinesBehindPlane(point, Vec3(0.0f, 1.0f, 0.0f), 0.0f));
}

// ---- The sphere light ---------------------------------------------------------------------

/// Σ incident·max(0, n·wi)/pdf over an n × n stratified grid of samples, divided by n²: the
/// sampler's estimate of the irradiance at x on a surface of normal `normal`.
double stratifiedIrradiance(const Light& light, const Vec3& x, const Vec3& normal, int n = 128) {
  double sum = 0.0;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const std::optional<IncidentLight> in = sampleLight(light, x, Vec2((i + 0.5f) / n, (j + 0.5f) / n));
      if (in) sum += double(in->incident.g) * std::max(0.0f, glm::dot(normal, in->wi)) / in->pdf;
    }
  return sum / (double(n) * n);
}

/// The same irradiance by quadrature over the sphere's surface: Σ L·cos θx·cos θy/ρ²·dA over
/// the points that face x (cos θy > 0), on an n × 2n grid in (cos θ, φ) (equal areas).
double surfaceIrradiance(const SphereLight& sphere, const Vec3& x, const Vec3& normal, int n = 1000) {
  const double radiance = double(sphere.intensity.g) / (kPiD * double(sphere.radius) * sphere.radius);
  const double dA = 4.0 * kPiD * double(sphere.radius) * sphere.radius / (2.0 * n * n);
  double sum = 0.0;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < 2 * n; ++i) {
      const double z = 1.0 - 2.0 * (j + 0.5) / n, r = std::sqrt(1.0 - z * z), phi = kPiD * (i + 0.5) / n;
      const DVec3 outward(r * std::cos(phi), r * std::sin(phi), z);
      const DVec3 toPoint = DVec3(sphere.position) + double(sphere.radius) * outward - DVec3(x);
      const double distance2 = glm::dot(toPoint, toPoint), distance = std::sqrt(distance2);
      const double cosY = -glm::dot(outward, toPoint) / distance, cosX = glm::dot(DVec3(normal), toPoint) / distance;
      if (cosY > 0.0 && cosX > 0.0) sum += radiance * cosX * cosY / distance2 * dA;
    }
  return sum;
}

// Lambert's (and Newton's) closed form: where the whole sphere is above the receiver's tangent
// plane, its irradiance is the point light's at its centre, I·cos θc/d², whatever the radius —
// near (d = 1.5 r), tilted, and a tiny sphere far away. The stratified cone samples integrate a
// smooth function over the cone: 128² of them come within 1e-4.
TEST(SphereLight, IrradianceIsThePointLightsAboveTheHorizon) {
  const float radius = 0.5f, intensity = 6.0f;
  const Vec3 centre(0.0f, 2.0f, 0.0f);
  const Light sphere = createLight("sphere", {{"position", centre}, {"radius", radius}, {"intensity", intensity}}, "test");
  const Light point = createLight("point", {{"position", Vec3(0.0f, 2.0f, 0.0f)}, {"intensity", intensity}}, "test");
  EXPECT_FALSE(isDeltaLight(sphere));
  EXPECT_FALSE(isAtInfinity(sphere));
  EXPECT_FALSE(parallelLight(sphere));
  EXPECT_EQ(lightPower(sphere, 1.0f), lightPower(point, 1.0f));
  struct Receiver {
    Vec3 x, normal;
  };
  for (const Receiver& r : {Receiver{{0.0f, 1.25f, 0.0f}, {0.0f, 1.0f, 0.0f}},               // d = 1.5 r
                            Receiver{{0.0f, 0.0f, 0.0f}, {0.0f, 1.0f, 0.0f}},                // d = 4 r
                            Receiver{{1.0f, 0.0f, 0.5f}, glm::normalize(Vec3(0.2f, 1.0f, 0.1f))},  // tilted
                            Receiver{{0.0f, 0.0f, 0.0f}, glm::normalize(Vec3(1.0f, 0.5f, 0.0f))}}) {
    const Vec3 toCentre = centre - r.x;
    const double d = glm::length(toCentre), cosCentre = glm::dot(r.normal, toCentre) / d;
    ASSERT_GE(d * cosCentre, radius);  // the whole sphere above the tangent plane
    const double expected = intensity * cosCentre / (d * d);
    EXPECT_NEAR(stratifiedIrradiance(sphere, r.x, r.normal), expected, 1e-4 * expected) << "x " << r.x.x << " " << r.x.y;
    EXPECT_NEAR(sampleLight(point, r.x, Vec2(0.5f))->incident.g * cosCentre, expected, 1e-5 * expected);
  }
  const Light tiny = createLight("sphere", {{"position", centre}, {"radius", 1e-3f}, {"intensity", intensity}}, "test");
  EXPECT_NEAR(stratifiedIrradiance(tiny, Vec3(0.0f), Vec3(0.0f, 1.0f, 0.0f), 16), intensity / 4.0, 1e-4 * intensity / 4.0);
}

// Where the sphere dips below the horizon, the cone samples agree with a quadrature over its
// surface (the two share nothing but the definition L = I/(π r²)).
TEST(SphereLight, IrradianceNearTheHorizonMatchesTheSurfaceIntegral) {
  const Light light =
      createLight("sphere", {{"position", Vec3(0.0f, 0.3f, 0.0f)}, {"radius", 0.5f}, {"intensity", 6.0f}}, "test");
  const SphereLight& sphere = std::get<SphereLight>(light);
  for (const Vec3& x : {Vec3(1.0f, 0.0f, 0.0f), Vec3(0.7f, 0.0f, 0.3f), Vec3(2.0f, 0.0f, 0.0f)}) {
    const Vec3 up(0.0f, 1.0f, 0.0f);
    const double expected = surfaceIrradiance(sphere, x, up);
    EXPECT_GT(expected, 0.0);
    EXPECT_NEAR(stratifiedIrradiance(light, x, up, 256), expected, 2e-3 * expected) << "x " << x.x << " " << x.z;
  }
  EXPECT_TRUE(shinesBehindPlane(light, Vec3(0.0f, 1.0f, 0.0f), 0.0f));  // it pokes 0.2 below y = 0
  EXPECT_FALSE(shinesBehindPlane(light, Vec3(0.0f, 1.0f, 0.0f), -0.3f));
}

// Every sample: its density is lightPdf's for its direction, the shadow ray's target is the
// near point where that direction meets the sphere, and the radiance is I/(π r²). Directions
// off the cone have density 0; a receiver inside the sphere gets nothing.
TEST(SphereLight, SamplesLandOnTheNearSideWithTheirDensity) {
  const Vec3 centre(0.5f, 3.0f, -1.0f);
  const float radius = 0.8f;
  const Light light =
      createLight("sphere", {{"position", centre}, {"radius", radius}, {"intensity", Rgb(2.0f, 4.0f, 8.0f)}}, "test");
  const Vec3 x(0.0f, 0.0f, 0.0f);
  for (int j = 0; j < 16; ++j)
    for (int i = 0; i < 16; ++i) {
      const std::optional<IncidentLight> in = sampleLight(light, x, Vec2((i + 0.5f) / 16, (j + 0.5f) / 16));
      ASSERT_TRUE(in);
      EXPECT_NEAR(glm::length(in->wi), 1.0f, 1e-6f);
      EXPECT_FLOAT_EQ(lightPdf(light, x, in->wi), in->pdf);
      EXPECT_NEAR(glm::length(in->target - centre), radius, 1e-5f);
      EXPECT_LE(glm::dot(in->target - centre, in->wi), 1e-5f);  // the side facing x
      EXPECT_NEAR(glm::length(in->target - x), in->distance, 1e-5f);
      EXPECT_EQ(in->incident, Rgb(2.0f, 4.0f, 8.0f) / (kPi * radius * radius));
    }
  EXPECT_EQ(lightPdf(light, x, glm::normalize(Vec3(1.0f, 0.0f, 0.0f))), 0.0f);
  EXPECT_FALSE(sampleLight(light, centre + Vec3(0.1f), Vec2(0.5f)));
  EXPECT_EQ(lightPdf(light, centre, Vec3(0.0f, 1.0f, 0.0f)), 0.0f);
}

// A sphere light needs a radius; the JSON scene format takes it like any other light.
class SphereLightJson : public test_support::TempDirTest {};
TEST_F(SphereLightJson, TheRadiusIsRequiredAndPositive) {
  std::ofstream(path("ok.json")) << R"({"include_cornell": true, "lights": [)"
                                  << R"({"type": "sphere", "position": [278, 400, 280], "radius": 20, "intensity": [1, 2, 3]}]})";
  const Scene scene = loadScene(path("ok.json"));
  ASSERT_EQ(scene.lights.size(), 1u);
  const SphereLight& sphere = std::get<SphereLight>(scene.lights[0]);
  EXPECT_EQ(sphere.radius, 20.0f);
  EXPECT_EQ(sphere.intensity, Rgb(1.0f, 2.0f, 3.0f));
  for (const char* radius : {"", ", \"radius\": 0", ", \"radius\": -1"}) {
    std::ofstream(path("bad.json")) << R"({"include_cornell": true, "lights": [{"type": "sphere", "position": [0, 1, 0])"
                                    << radius << "}]}";
    try {
      loadScene(path("bad.json"));
      ADD_FAILURE() << "accepted a sphere light with radius '" << radius << "'";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("bad.json: sphere light 0 needs a finite radius > 0"), std::string::npos)
          << e.what();
    }
  }
}

}  // namespace
}  // namespace pl
