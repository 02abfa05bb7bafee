#pragma once
// Flags shared by every command that turns radiance into pictures (trace, render, view):
// image size, camera choice, exposure, vignetting and tone mapping. Declared once here so
// the commands agree on names, ranges and defaults, and bound straight to the fields of a
// ViewSettings (jobs/jobs.h), which says what they mean: a command binds them to its job's
// options.
#include <CLI/CLI.hpp>

#include "jobs/jobs.h"

namespace pl {

// Each adds its flags to `command`, bound to `view`, which must outlive the parse.

/// --width/--height and the camera flags.
void addCameraOptions(CLI::App& command, ViewSettings& view);
/// The exposure, vignetting and tone-mapping flags (addExposureOptions + --vignetting +
/// addToneMapOptions).
void addImageOptions(CLI::App& command, ViewSettings& view);
/// --exposure, --fstop, --shutter, --iso (checked all-or-none when parsing completes).
void addExposureOptions(CLI::App& command, ViewSettings& view);
/// --tonemap, --key, --white.
void addToneMapOptions(CLI::App& command, ViewSettings& view);

/// The light-field renderers' flags (render, view), bound to `render`: --spp (also accepted
/// as --samples), --mirror-depth and --texture-lod on|off.
void addRenderSettingsOptions(CLI::App& command, RenderSettings& render);

}  // namespace pl
