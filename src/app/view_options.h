#pragma once
// Flags shared by every command that turns radiance into pictures (trace, render, view):
// image size, camera choice, exposure, vignetting and tone mapping. Declared once here so
// the commands agree on names, ranges and defaults; what they mean lives in ViewSettings
// (jobs/jobs.h).
#include <CLI/CLI.hpp>

#include "jobs/jobs.h"

namespace pl {

/// The view settings (jobs/jobs.h) with the flags that set them.
struct ViewOptions : ViewSettings {
  /// Adds --width/--height and the camera flags.
  void addCameraOptions(CLI::App& command);
  /// Adds the exposure, vignetting and tone-mapping flags (addExposureOptions +
  /// --vignetting + addToneMapOptions).
  void addImageOptions(CLI::App& command);
  /// --exposure, --fstop, --shutter, --iso (checked all-or-none when parsing completes).
  void addExposureOptions(CLI::App& command);
  /// --tonemap, --key, --white.
  void addToneMapOptions(CLI::App& command);
};

/// --texture-lod on|off for the light-field renderers (render, view): RenderSettings::textureLod.
void addTextureLodOption(CLI::App& command, bool& textureLod);

}  // namespace pl
