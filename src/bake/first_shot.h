#pragma once
// The first shot by source, stored beside the visibility field (docs/design.md, "A
// warm-started re-bake"; the format: docs/file-formats.md, "The .pls format"). Relighting keeps
// the first shot split by source (relight.h): D_l per scene light at unit emission (and its
// punctual highlights on glossy charts), D_e of the emissive surfaces, the environment and the
// caustics. Recomputing them is most of what a warm-started re-bake pays beyond reading its
// files, so a bake, which shoots its first shot in this split (propagation.h
// combineFirstShot), writes them as X.pls beside X.plv when they fit its memory, and a
// warm-started re-bake writes the ones of the scene it relit for — so the next re-bake reads
// them instead of shooting again.
//
// A file is used only for the light field it was written for: its key (firstShotKey) hashes
// the visibility field's hash, the value count, the bake settings, the tixel setup's keys
// (meshes, textures, every material's model and parameters, the sun-masked lights'
// placement), every light's parameters, every material's emission and albedo and the
// environment. Anything else — no file, another key, another version, a damaged file — is
// read as no file, with the reason: the caller shoots again (a cache, never an error).
#include <cstdint>
#include <string>
#include <vector>

#include "bake/parameterisation.h"
#include "core/math.h"
#include "lightfield/lightfield.h"
#include "scene/scene.h"

namespace pl {

/// The first shot by source, each array in LightField::values layout (param.valueCount).
struct FirstShotBySource {
  std::vector<std::vector<Rgb>> lightDirect;    ///< D_l per scene light, at unit emission
  std::vector<std::vector<Rgb>> lightPunctual;  ///< per light, its punctual glossy part; empty when the bake keeps none
  std::vector<Rgb> emitterDirect;               ///< D_e
};

/// Where the first shot by source of the visibility field at `visibilityPath` is kept: X.plv → X.pls.
std::string firstShotPathFor(const std::string& visibilityPath);

/// The key of the first shot of `scene` baked with `settings` over `param`, whose visibility
/// field has hash `visibilityHash` (see above for what it covers).
uint64_t firstShotKey(const Scene& scene, const Parameterisation& param, const BakeSettings& settings,
                      uint64_t visibilityHash);

/// Writes `shot` to `path` (through a temporary file renamed over it). Throws pl::Error when
/// it cannot be written or the arrays do not agree in size.
void writeFirstShot(const std::string& path, uint64_t visibilityHash, uint64_t key, const FirstShotBySource& shot);

/// Reads the first shot at `path` into `shot` when it was written for `visibilityHash` and
/// `key`, with `lightCount` lights, `valueCount` values per array and punctual arrays exactly
/// when `punctual`. Otherwise returns false, `shot` unchanged, and says why in `why` (one
/// clause: missing, stale, or damaged — every size is checked before allocating, and the
/// payload against its XXH64).
bool readFirstShot(const std::string& path, uint64_t visibilityHash, uint64_t key, uint32_t lightCount,
                   uint64_t valueCount, bool punctual, FirstShotBySource& shot, std::string* why = nullptr);

}  // namespace pl
