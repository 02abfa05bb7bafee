// The JSON schema of the bake's settings and statistics (lightfield.h toJson / fromJson).
#include "lightfield/lightfield.h"

#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>

#include "bake/bake.h"

namespace pl {
namespace {

// The bake's settings and statistics have one JSON schema (lightfield.h toJson/fromJson): what
// the .plf's META, `info --json` and `bake --stats` write, read back field for field.
TEST(BakeJsonSchema, SettingsAndStatsRoundTripAndOldFilesMeanNoSunMasksOrHighlights) {
  BakeSettings settings = bakePreset("high");
  settings.tixelsPerUnit = 3.5f;
  settings.seed = 77;
  settings.sunMasks = true;
  settings.punctualHighlights = true;
  const nlohmann::json json = toJson(settings);
  EXPECT_EQ(json.at("gather_directions"), 576);
  EXPECT_EQ(json.at("tixels_per_unit"), 3.5f);
  EXPECT_EQ(json.at("caustic_photons"), uint64_t(1) << 24);
  BakeSettings back;
  fromJson(json, back);
  EXPECT_EQ(toJson(back), json);
  EXPECT_EQ(back.seed, 77u);

  // A writer from before sun masks and punctual highlights: both off; keys it lacks keep their values.
  nlohmann::json old = json;
  old.erase("sun_masks");
  old.erase("punctual_highlights");
  old.erase("caustic_photons");
  old.erase("exact_visibility");
  old.erase("seed");
  old["a_key_from_a_newer_writer"] = 1;
  BakeSettings fromOld;
  fromOld.seed = 5;
  fromJson(old, fromOld);
  EXPECT_FALSE(fromOld.sunMasks);
  EXPECT_FALSE(fromOld.punctualHighlights);
  EXPECT_EQ(fromOld.causticPhotons, 0u);  // caustics gathered
  EXPECT_TRUE(fromOld.exactVisibility);    // fractions kept whole
  EXPECT_EQ(fromOld.seed, 5u);

  BakeStats stats;
  stats.seconds = 1.25;
  stats.iterations = 7;
  stats.visibilityRays = uint64_t(1) << 40;
  stats.reusedVisibility = true;
  stats.causticPhotons = 1000;
  stats.causticPhotonsLanded = 300;
  stats.causticSeconds = 0.5;
  BakeStats statsBack;
  fromJson(toJson(stats), statsBack);
  EXPECT_EQ(toJson(statsBack), toJson(stats));
  EXPECT_EQ(statsBack.visibilityRays, uint64_t(1) << 40);
  EXPECT_EQ(statsBack.causticPhotonsLanded, 300u);
  EXPECT_THROW(fromJson(nlohmann::json{{"iterations", "seven"}}, statsBack), nlohmann::json::exception);
}

}  // namespace
}  // namespace pl

namespace pl {
namespace {

// Normal-mapped diffuse charts (lightfield.h): the tilt constants are 45° and 120° apart, and
// the model E(n') ≈ tiltWeights(n')·(E, E_0, E_1, E_2) is exact where the header says it is —
// light from one direction above every tilted horizon, and uniform light over the hemisphere
// (E(n') = E·(1 + n'·n)/2, each E_k = E·(1 + cos β)/2).
TEST(TiltedIrradiance, ConstantsAndTheModelsExactCases) {
  const float beta = glm::radians(kNormalTiltDegrees);
  EXPECT_NEAR(kNormalTiltCosine, std::cos(beta), 1e-7f);
  EXPECT_NEAR(kNormalTiltSine, std::sin(beta), 1e-7f);
  for (uint32_t k = 0; k < kTiltedNormals; ++k) {
    const float phi = glm::radians(120.0f * float(k));
    EXPECT_NEAR(kTiltAcross[k][0], std::cos(phi), 1e-7f);
    EXPECT_NEAR(kTiltAcross[k][1], std::sin(phi), 1e-7f);
    EXPECT_NEAR(glm::length(tiltedNormal(k)), 1.0f, 1e-6f);
  }
  auto model = [](const Vec3& n, float e, const float (&tilted)[kTiltedNormals]) {
    const TiltWeights w = tiltWeights(n);
    float sum = w.irradiance * e;
    for (uint32_t k = 0; k < kTiltedNormals; ++k) sum += w.tilted[k] * tilted[k];
    return sum;
  };
  const Vec3 normals[] = {Vec3(0, 0, 1), glm::normalize(Vec3(0.3f, -0.2f, 1.0f)), glm::normalize(Vec3(-0.6f, 0.4f, 0.7f))};
  // One direction ω, 30° from the normal (within 90° of every b_k): E_k = ω·b_k (all positive), E(n') = ω·n'.
  const Vec3 omega = glm::normalize(Vec3(std::sin(glm::radians(30.0f)) * Vec3(0.6f, 0.8f, 0.0f)) +
                                    Vec3(0.0f, 0.0f, std::cos(glm::radians(30.0f))));
  float directional[kTiltedNormals];
  for (uint32_t k = 0; k < kTiltedNormals; ++k) directional[k] = glm::dot(omega, tiltedNormal(k));
  for (const Vec3& n : normals) EXPECT_NEAR(model(n, omega.z, directional), glm::dot(omega, n), 1e-5f);
  // Uniform radiance L = 1/π over the hemisphere: E = 1.
  const float uniform[kTiltedNormals] = {0.5f * (1.0f + kNormalTiltCosine), 0.5f * (1.0f + kNormalTiltCosine),
                                         0.5f * (1.0f + kNormalTiltCosine)};
  for (const Vec3& n : normals) EXPECT_NEAR(model(n, 1.0f, uniform), 0.5f * (1.0f + n.z), 1e-5f);
}

}  // namespace
}  // namespace pl
