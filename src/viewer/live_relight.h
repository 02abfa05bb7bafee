#pragma once
// Live relighting in the viewer (viewer.h, "Relighting" keys): lighting edits go to a
// Relighter (bake/relight.h) that re-propagates on a background thread from the visibility
// field, warm-started from the current solution; the view switches to each iteration's light
// field as it completes, and the HUD says the iteration and residual.
//
// What the keys edit: a selected source — each scene light, then "emitters" (every emissive
// material at once) — and a selected Lambertian material:
//   Tab            select the next source          O   switch it off / on
//   [ / ]          its emission × 0.8 / × 1.25     C   cycle its colour (white, warm, cool, red, green, blue)
//   J / L          the sun (selected directional light, else the first) 5° of azimuth left / right
//   I / K          the sun 5° higher / lower (elevation within ±89°)
//   M              select the next Lambertian material;  , / .  its albedo × 0.9 / × 1.1 (at most 1)
//
// Cores: the propagation (and the relighter's set-up) runs on one thread of its own, in a
// one-thread task arena (core/parallel.h runWithThreads), at the priority of its RelightShare
// (core_share.h: normal under Split, the viewer's, which gives the renderer the pool's
// threads − 1 meanwhile; busy() tells the viewer when that applies).
//
// Double buffering: two copies of the light field (made once; the scene's geometry and
// textures are shared by neither, so each is a full copy); the worker writes the one not on
// screen and builds its renderer, under a lock the viewer only tries (a frame never waits).
#include <atomic>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "lightfield/lightfield.h"
#include "realtime/realtime.h"
#include "viewer/core_share.h"

namespace pl {

class Accel;
class Relighter;

enum class RelightKey {
  NextSource, ToggleSource, Dimmer, Brighter, NextColour,
  SunLeft, SunRight, SunUp, SunDown,
  NextMaterial, Darker, Lighter,
};

/// The relighting state the HUD shows.
struct RelightStatus {
  bool ready = false;       ///< the Relighter is built (until then the keys are queued)
  bool running = false;     ///< propagating
  uint32_t iteration = 0;   ///< of the relight in progress or last finished
  double residual = 0.0;
  bool converged = true;
  double firstFrameSeconds = 0.0, seconds = 0.0;  ///< of the last relight (first frame, converged)
  double sunMaskSeconds = 0.0, firstShotSeconds = 0.0;  ///< of firstFrameSeconds (RelightStats)
  std::string message;      ///< the last refusal or error
};

class LiveRelight {
 public:
  /// Starts the background thread, which builds the Relighter from `lightField` and the .plv
  /// at visibilityPath (its errors go to status().message). lightField and accel must outlive it.
  LiveRelight(const LightField& lightField, const Accel& accel, const std::string& visibilityPath,
              RelightShare share = RelightShare::Split);
  ~LiveRelight();  ///< stops the worker (cancelling its set-up or iteration: core/cancel.h) and joins it
  LiveRelight(const LiveRelight&) = delete;
  LiveRelight& operator=(const LiveRelight&) = delete;

  /// Applies a key's edit to the wanted lighting and restarts the propagation with it.
  void press(RelightKey key);
  /// Once per frame: takes the newest finished iteration onto the screen; whether it did (the
  /// view then needs rendering again). Never blocks.
  bool update();
  /// The renderer of the light field on screen; null until the first relit iteration.
  const FastRenderer* renderer() const;
  /// The light field on screen (the original until the first relit iteration).
  const LightField& lightField() const;
  RelightStatus status() const;
  /// Whether the worker is setting up or relighting (a relight asked for counts at once), i.e.
  /// uses its core: not after it converged, stopped, or was refused, nor when the set-up failed.
  bool busy() const;
  /// Whether the screen shows the newest relit light field (one was published and taken).
  bool showsNewest() const;
  /// HUD lines: the selected source and material, and the propagation's state.
  std::vector<std::string> hudLines() const;
  /// Waits until the worker is idle with nothing pending (tests; headless runs).
  void waitIdle();

 private:
  void work();
  /// The wanted lighting's description of the selected source.
  std::string sourceLine() const;

  const LightField& original_;
  const Accel& accel_;
  const std::string visibilityPath_;
  const RelightShare share_;
  // The wanted lighting (main thread writes, worker copies under mutex_).
  std::vector<Light> lights_;
  std::vector<Rgb> emission_;      ///< per material
  std::vector<Rgb> albedo_;        ///< per material (Lambertian ones; others unused)
  std::vector<Rgb> savedLight_;    ///< per light: its emission before O switched it off
  std::vector<Rgb> baseLight_;     ///< per light: the colour C cycles from
  std::vector<Rgb> baseEmission_;  ///< per material, as baked
  std::vector<uint32_t> lightColour_;  ///< per light: its index in the colours C cycles
  float emitterScale_ = 1.0f;
  uint32_t emitterColour_ = 0;
  bool emittersOn_ = true;
  size_t source_ = 0;                    ///< 0 … lights − 1, then lights = the emitters
  std::vector<uint32_t> lambertian_;     ///< selectable materials
  size_t material_ = 0;
  // Shared with the worker.
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  bool pending_ = false, quit_ = false, idle_ = false;
  std::condition_variable idleChanged_;
  RelightStatus status_;
  // Screen buffers: the worker writes buffer 1 − shown_, the main thread switches shown_.
  LightField buffers_[2];
  std::optional<FastRenderer> renderers_[2];
  int shown_ = -1, ready_ = -1;
  std::atomic<bool> restart_{false};
  std::unique_ptr<Relighter> relighter_;
  std::thread thread_;
};

}  // namespace pl
