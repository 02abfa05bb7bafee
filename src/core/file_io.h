#pragma once
// Writing output files without ever leaving a half-written one behind, and checking output
// paths before any work is done. The one implementation every writer of the project uses
// (images, .plf/.plv, --stats JSON, camera paths, videos).
//
// Atomic write: the bytes go to a temporary file in the target's directory (same file
// system, so the final std::filesystem::rename is atomic), which replaces the target only
// once it is complete. On any failure the temporary is removed, the target is untouched
// and pl::Error names the target and the problem.
#include <cstddef>
#include <functional>
#include <initializer_list>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace pl {

/// How hard a finished file is pushed to the disk before it counts as written.
enum class FileSync {
  none,     ///< rename only: atomic against crashes of this process (images, JSON)
  durable,  ///< fsync the file before the rename and its directory after it: also survives a power loss (.plf)
};

/// "name.EXR" → ".exr": the extension of `path`'s file name, lower-case ("" when it has none).
std::string fileExtensionLower(const std::string& path);

/// The one check of an output path, done by every command before any work starts. Fails
/// with a message starting "OPTION PATH: " (`option` is the flag the path came from, e.g.
/// "-o" or "--stats"):
///   * pl::UsageError unless the extension is one of `extensions` (lower-case with the dot,
///     e.g. {".plf"}; an empty list accepts any name);
///   * pl::Error when the path is a directory or another non-regular file (FIFO, device),
///     or its directory does not exist, is not a directory or is not writable.
/// The target itself may exist: it is replaced by renaming a temporary over it.
void checkOutputPath(const std::string& path, std::span<const std::string_view> extensions, std::string_view option);
inline void checkOutputPath(const std::string& path, std::initializer_list<std::string_view> extensions,
                            std::string_view option) {
  checkOutputPath(path, std::span<const std::string_view>(extensions.begin(), extensions.size()), option);
}

/// An output path and the flag it came from.
struct OutputFlag {
  std::string_view option;
  std::string path;  ///< empty = not given
};
/// pl::UsageError when two of the given outputs are the same file (compared after resolving
/// ".", ".." and symbolic links), e.g. --visibility equal to -o, which would overwrite one
/// output with the other.
void checkDistinctOutputs(std::initializer_list<OutputFlag> outputs);

/// Fails with "PATH: not a regular file (a FIFO)" (directory, device, socket) when `path`
/// exists and is not a regular file (symbolic links are followed). Every reader calls it
/// before opening its input: opening a FIFO would block until something writes to it, and a
/// directory or device has no content to parse. A missing file passes (the reader's own
/// open reports it).
void requireRegularFile(const std::string& path);

/// A temporary file beside `target` that becomes `target` on commit(); if it is never
/// committed (error, exception), the destructor removes it, and if the program is
/// interrupted (SIGINT, SIGTERM), the interruption handler does (core/interrupt.h). For
/// writers whose output is produced over a longer time or by another process (e.g. ffmpeg);
/// the simple cases use writeFileAtomically below.
class PendingFile {
 public:
  /// Checks that target's directory exists and that target is not a directory (pl::Error
  /// naming target otherwise) and picks a unique temporary name (nothing is created yet).
  explicit PendingFile(std::string target);
  ~PendingFile();
  PendingFile(const PendingFile&) = delete;
  PendingFile& operator=(const PendingFile&) = delete;

  const std::string& target() const { return target_; }
  /// Where to write: ".NAME.tmp-PID-N" in the target's directory (hidden, unique per process and call).
  const std::string& temporaryPath() const { return temporary_; }

  /// Renames the temporary over the target (after an fsync if `sync` is durable). On failure
  /// the temporary is removed and pl::Error names the target.
  void commit(FileSync sync = FileSync::none);
  /// Removes the temporary now (idempotent); the target is untouched.
  void discard() noexcept;

 private:
  std::string target_;
  std::string temporary_;
  size_t interruptSlot_;  ///< temporary_'s registration for removal on Ctrl-C (core/interrupt.h)
  bool open_ = true;  ///< not yet committed or discarded
};

/// Runs write(temporaryPath), which must create and fill that file, then moves it over
/// `path`. Any exception from `write` (or the rename) removes the temporary and becomes
/// pl::Error("PATH: cannot write: <what>"), so `write` may report problems without naming a file.
void writeFileAtomically(const std::string& path, const std::function<void(const std::string& temporaryPath)>& write,
                         FileSync sync = FileSync::none);

/// Creates (or truncates) `path` and writes the bytes to it, checking every step (open,
/// write, flush, close). NOT atomic: meant for the temporary inside a writeFileAtomically
/// callback, so pl::Error gives the system's reason (disk full, permission) and no path.
void writeFileBytes(const std::string& path, const void* data, size_t size);

/// Writes `bytes` as the whole content of `path`, atomically (see above).
void writeFileAtomically(const std::string& path, std::string_view bytes, FileSync sync = FileSync::none);

/// A whole file's bytes, read-only: memory-mapped where the system can (Linux: the page
/// cache's pages themselves, pre-faulted, so opening a large file costs neither a copy nor
/// zeroed memory), else read into memory. For large binary inputs read once per run (.plv).
/// Files are replaced by renaming a complete new file over them (writeFileAtomically), which
/// leaves a mapping of the old one intact; truncating a file in place while it is mapped
/// would fault, as for any mapped file.
class MappedFile {
 public:
  /// Opens and maps (or reads) `path`; pl::Error naming the path and the system's reason on
  /// failure. An empty file gives an empty span.
  explicit MappedFile(const std::string& path);
  ~MappedFile();
  MappedFile(const MappedFile&) = delete;
  MappedFile& operator=(const MappedFile&) = delete;

  std::span<const unsigned char> bytes() const { return {data_, size_}; }

 private:
  const unsigned char* data_ = nullptr;
  size_t size_ = 0;
  bool mapped_ = false;
  std::vector<unsigned char> copy_;  ///< when not mapped
};

}  // namespace pl
