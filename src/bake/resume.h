#pragma once
// Resuming an interrupted bake (docs/design.md, Resuming an interrupted bake). Two scratch
// files beside the visibility field X.plv keep a long bake's work while it runs:
//
//   X.plv.partial     the visibility field as it is traced: a journal of finished blocks, each
//                     its own checksummed record, appended as the blocks finish (a MiB of
//                     records per write), so that a bake killed while tracing loses only the
//                     blocks in flight and the last unwritten MiB (a torn or corrupt tail is
//                     detected by its checksum and dropped). Removed once the complete X.plv
//                     is written.
//   X.plv.checkpoint  the propagation's state after its last finished iteration (the first
//                     shot and the iterate), replaced atomically after every iteration, so a
//                     bake killed while propagating resumes at the next iteration. Removed
//                     once the bake has returned its light field.
//
// A bake resumes from them automatically when they match it (the field's hash; for the
// checkpoint also the scene's materials, lights and every bake setting), and says how much it
// reused; anything else in them — another scene, other settings, damage — is traced or
// propagated afresh with the reason logged, never an error: they are scratch data. The resumed
// light field is the uninterrupted bake's bit for bit: a block's entries depend only on its
// tixels, and an iteration only on the state the checkpoint holds.
//
// Journal layout (little-endian):
//   header   magic "PLVPART\n", u32 kJournalVersion, u32 gridSide, u64 field hash, u64 block
//            count, u64 XXH64 of the blocks' tixel counts, u64 XXH64 of the 40 bytes before it
//   records  until the end of the file, in the order the blocks finished: u64 block, u64
//            content bytes C, u64 XXH64 of the C bytes after it (seeded with the XXH64 of the
//            record's first 16 bytes); then the content, uncompressed (zstd would cost the
//            tracing threads more than the few bytes it saves; the .plv is compressed): u64
//            extra count X, X × (u64 field entry index, 24-byte VisibilityExtra), the block's
//            tixels' encoded sizes (u32 each), their encodings (plv_file.h "Compact entries").
// Checkpoint layout: magic "PLPCKPT\n", u32 version, u32 converged flag, u64 key, u32 iterations,
// u32 0, f64 × 4 (StoppingRule state: previous power, previous L1 change, ω; residual),
// u64 × 3 (shadow rays, caustic photons shot, landed), u64 value count V, u64 punctual count P,
// then V direct values, P punctual-glossy values, V current values (RGB f32), then u64 XXH64 of
// everything before it.
#include <cstdint>
#include <functional>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "core/math.h"
#include "plf/plv_file.h"

namespace pl {

struct BakeSettings;
struct Scene;

/// Where the scratch files of the bake whose visibility field is `plvPath` live.
std::string partialVisibilityPath(const std::string& plvPath);
std::string propagationCheckpointPath(const std::string& plvPath);

/// The extra records of one block of a field as tracing makes them: (field entry index, record).
using BlockExtras = std::vector<std::pair<uint64_t, VisibilityExtra>>;

/// The journal of a visibility field being traced (X.plv.partial; layout above).
class VisibilityJournal {
 public:
  /// `resume`: whether blocks that an interrupted bake saved at `path` may be reused (false:
  /// `bake --fresh`). `log` receives one-line notes (may be empty).
  VisibilityJournal(std::string path, bool resume, std::function<void(const std::string&)> log);
  ~VisibilityJournal();
  VisibilityJournal(const VisibilityJournal&) = delete;
  VisibilityJournal& operator=(const VisibilityJournal&) = delete;

  /// Starts the journal of a field (its hash and gather grid side) traced in blocks of
  /// blockTixels[b] tixels (in field order), whose entries may name tixels below targetTixels.
  /// The blocks a matching journal at the path holds are restored into runs[b] and extras[b]
  /// (returned flags: 1 = restored) and kept; a torn or corrupt tail is dropped; a journal of
  /// another field is discarded. Says which in a note. Throws pl::Error when the file cannot
  /// be written.
  std::vector<uint8_t> open(uint64_t hash, uint32_t gridSide, const std::vector<uint64_t>& blockTixels,
                            uint64_t targetTixels, std::vector<EncodedRun>& runs, std::vector<BlockExtras>& extras);
  /// Appends finished block b (thread-safe). Throws pl::Error when the write fails.
  void append(uint64_t block, const EncodedRun& run, const BlockExtras& extras);
  /// The field is complete and saved: closes and removes the journal.
  void finish();

  uint64_t restoredBlocks() const { return restoredBlocks_; }
  uint64_t restoredTixels() const { return restoredTixels_; }

 private:
  std::string path_;
  bool resume_;
  std::function<void(const std::string&)> log_;
  int fd_ = -1;
  std::mutex mutex_;
  std::vector<unsigned char> pending_;  ///< records not yet written (written a MiB at a time)
  uint64_t appended_ = 0, stopAfter_ = 0;  ///< stopAfter_: the test hook's K (0: none)
  uint64_t restoredBlocks_ = 0, restoredTixels_ = 0;
};

/// Where the propagation stands after `iterations` iterations: what a checkpoint holds besides its values.
struct PropagationProgress {
  uint64_t key = 0;  ///< propagationKey of the bake
  uint32_t iterations = 0;
  bool converged = false;  ///< the stopping rule was met after the last iteration
  double previousPower = 0.0, previousL1Change = 0.0;  ///< StoppingRule's state
  float omega = 0.0f;                                   ///< StoppingRule's ω for the next iteration
  double residual = 0.0;                                ///< of the last iteration
  uint64_t shadowRays = 0, causticPhotons = 0, causticPhotonsLanded = 0;  ///< the first shot's counts
};

/// A checkpoint as read back (layout above): the progress and the propagation's arrays
/// (TransportState's direct, punctualGlossy and current, in LightField::values layout).
struct PropagationCheckpoint {
  PropagationProgress progress;
  std::vector<Rgb> direct, punctualGlossy, current;
};

/// What the checkpoint of a bake must match: the visibility field's hash (fieldHash: geometry,
/// parameterisation, gather settings), everything a .plf stores of the scene (materials,
/// textures, lights, environment) and every bake setting.
uint64_t propagationKey(uint64_t fieldHash, const Scene& scene, const BakeSettings& settings);

/// Writes a checkpoint atomically (temp + rename), streaming the arrays (no copy of them is
/// made). Throws pl::Error naming the file on failure.
void writePropagationCheckpoint(const std::string& path, const PropagationProgress& progress,
                                const std::vector<Rgb>& direct, const std::vector<Rgb>& punctualGlossy,
                                const std::vector<Rgb>& current);
/// Reads the checkpoint at `path` when it is there, intact, of `key` and of valueCount values;
/// otherwise returns false and sets *why (absent, damaged or another bake's: not an error).
bool readPropagationCheckpoint(const std::string& path, uint64_t key, uint64_t valueCount,
                               PropagationCheckpoint& checkpoint, std::string* why);

/// The test hooks (docs/development.md): the process ends at once, as if killed, after
/// writing the Kth journal record (PLENOPTIC_TEST_STOP_AFTER_BLOCKS=K) or the Kth checkpoint
/// (PLENOPTIC_TEST_STOP_AFTER_ITERATIONS=K) of this run. 0 when unset.
uint64_t testStopAfter(const char* variable);

}  // namespace pl
