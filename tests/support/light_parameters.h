#pragma once
// Test support (header-only; include as "support/light_parameters.h"): lights of every type
// (light/lights.h) with parameters of their own, and their parameters as plain numbers, for
// tests that run over the whole Light variant.
#include "light/lights.h"

#include <type_traits>
#include <vector>

namespace pl::test_support {

/// A light of variant index `index` whose parameters all differ: positive and increasing in
/// the order of its parameters() hook (a Vec3 as three numbers), so that a spot's inner angle
/// stays below its outer one and every type's values are in range.
inline Light lightWithDistinctParameters(size_t index) {
  Light light = *lightOfIndex(index);
  float next = 0.1f;
  visitLightParameters(light, [&](const char*, LightParameterKind, auto& field) {
    if constexpr (std::is_same_v<std::decay_t<decltype(field)>, Vec3>) {
      field = Vec3(next, next + 0.1f, next + 0.2f);
      next += 0.3f;
    } else {
      field = next;
      next += 0.1f;
    }
  });
  return light;
}

/// Every parameter of a light as floats, in hook order (a Vec3 as three).
inline std::vector<float> lightParameterFloats(const Light& light) {
  std::vector<float> values;
  visitLightParameters(light, [&](const char*, LightParameterKind, const auto& field) {
    if constexpr (std::is_same_v<std::decay_t<decltype(field)>, Vec3>)
      values.insert(values.end(), {field.x, field.y, field.z});
    else
      values.push_back(field);
  });
  return values;
}

}  // namespace pl::test_support
