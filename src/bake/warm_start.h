#pragma once
// A re-bake warm-started from the previous light field (docs/design.md, Relighting; `bake
// --reuse-visibility`, docs/user-guide.md). When the scene to bake differs from the one of a
// previous light field only in what relighting serves (relight.h: a light's colour, intensity
// or placement, an emission, the environment, a Lambertian albedo), and that light field's
// visibility field is the one this bake would reuse, the previous light field is relit
// through the Relighter — its first shot by source, then the bake's iteration from the
// previous solution to the bake's tolerance — instead of propagated from zero.
//
// What the result promises: a solution of the same transport with the same stopping rule, so
// within the bake's tolerance of a fresh bake of the scene, not bit for bit (it starts
// elsewhere and stops after other iterations). A caller that needs the bit-identical light
// field bakes cold (bake() with reuseVisibility).
//
// Anything else — no previous light field, a damaged one or one of another scene, other
// settings, a change the Relighter refuses, a distributed bake, a caller that keeps the
// parameterisation and visibility field — is declined with the reason, and the caller bakes
// cold. Only cancellation (pl::Cancelled) propagates.
#include <optional>
#include <string>

#include "bake/bake.h"
#include "bake/relight.h"
#include "lightfield/lightfield.h"

namespace pl {

/// What warmStartBake did.
struct WarmStartOutcome {
  bool used = false;        ///< the light field is the relit previous one
  std::string reason;       ///< when not used: why (one clause, for a log line and `--stats`)
  RelightStats relight;     ///< when used: the relighting's stages
  double setupSeconds = 0;  ///< when used: reading the previous light field, its visibility field and tixel setup, first shot by source
};

/// Relights the light field at `previousPath` (a .plf) for `scene` with `settings`, reading the
/// visibility field at options.visibilityPath (and its .plt). On success returns the light
/// field (with `scene` moved into it, its stats those of this bake: reused visibility, the
/// relighting's iterations and residual) and rewrites the .plt beside the .plv for the new
/// scene; a material whose albedo changed gets a key no scene has there, so that a later cold
/// reuse fills its charts again exactly (parameterisation.h writeTixelSetup). Otherwise returns
/// nothing, leaves `scene` as it was and says why in outcome.reason. options.log gets one line
/// either way; options.checkMemory is asked about a conservative estimate (a refusal declines).
std::optional<LightField> warmStartBake(Scene& scene, const BakeSettings& settings, const std::string& previousPath,
                                        const BakeOptions& options, WarmStartOutcome& outcome);

}  // namespace pl
