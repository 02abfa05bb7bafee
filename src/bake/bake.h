#pragma once
// The light-field bake: parameterisation → visibility field → propagation → LightField
// (DESIGN.md "Light-field pipeline"). The .plf file is written by plf_file.h.
//
// Presets (densities are relative to the scene's largest extent, so a scene in millimetres and
// one in metres get the same grids):
//   preset   tixels across   max per side   gather dirs   glossy map ≤   area-light rays   tolerance
//   draft          32              32        144 (12²)         8              16             5e-3
//   default        64              64        256 (16²)        16              32             1e-3
//   high           96             128        576 (24²)        24              64             2e-4
// "tolerance" is the relative change of total outgoing power at which iteration stops, once
// the remaining error estimated from the rate of convergence is below it too (propagation.h).
#include "lightfield/lightfield.h"

#include <functional>
#include <string>
#include <vector>

namespace pl {

/// The settings of a named preset; throws pl::Error listing the names for an unknown one.
BakeSettings bakePreset(const std::string& name);
std::vector<std::string> bakePresetNames();

struct BakeOptions {
  /// Where the visibility field is saved (and looked for with reuseVisibility); empty = not saved.
  std::string visibilityPath;
  /// Reuse visibilityPath when it exists and its hash matches this scene and settings.
  bool reuseVisibility = false;
  /// Receives one-line notes for the user (reuse decisions, rates). May be empty.
  std::function<void(const std::string&)> log;
  /// Called once the parameterisation is known, before the visibility field and the values
  /// are allocated, with bakeMemoryEstimate() of this bake; may throw to refuse it (the
  /// command line calls requireMemory, core/memory.h). May be empty.
  std::function<void(uint64_t bytes)> checkMemory;
};

/// Bytes of the bake's large arrays for this parameterisation and these settings: the
/// visibility field (an 8-byte entry per tixel and gather direction, plus a 64-bit offset per
/// tixel) with the .plv writer's buffers (visibilityWriteBufferBytes) and, during propagation,
/// three arrays of RGB values (current, first shot, previous iteration) and a 64-byte
/// transport quad plus a 4-byte change per tixel. What the bake allocates after the check: the
/// scene and the BVH, already resident then, are not in it (nor the field's rare extra
/// records: mirror chains, glossy targets).
uint64_t bakeMemoryEstimate(uint64_t tixels, uint64_t values, const BakeSettings& settings);

/// Bakes `scene` (moved into the result). Throws pl::Error on failures.
LightField bake(Scene scene, const BakeSettings& settings, const BakeOptions& options = {});

}  // namespace pl
