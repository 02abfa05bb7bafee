#pragma once
// Ctrl-C (SIGINT), SIGTERM and SIGHUP: remove the temporary files of atomic writes in
// progress (core/file_io.h's PendingFile registers them here), print "plenoptic: interrupted"
// and exit with status 128 + signal (130 for SIGINT, 143 for SIGTERM), as shells report a
// program stopped by that signal. Outputs are only ever replaced by renaming a complete
// temporary over them, so after the cleanup no half-written file remains, hidden or not.
//
// Why a handler that cleans up and exits at once, rather than a flag polled by the long
// loops plus cleanup during unwinding: the work runs inside TBB tasks, Embree and codecs
// that would each need a cancellation point, and a poll that is missed (a 260 MB .plv being
// written, an ffmpeg pipe) would leave the user waiting. The handler does only
// async-signal-safe things: it reads a fixed table of lock-free atomic pointers to the
// registered paths (no allocation, no locks), calls unlink(2), write(2) and _exit(2).
// PendingFile registers its temporary's name before creating the file and unregisters it
// in its destructor, after the rename or removal; unlinking a name that is already gone is
// harmless, and the names are unique per process and call, so no other file is touched.
#include <cstddef>

namespace pl {

/// Installs the handler for SIGINT, SIGTERM and SIGHUP. Called once by main() before any work.
void installInterruptHandlers();

/// Registers `path` (a NUL-terminated string that stays alive and unchanged until
/// unregisterTemporaryFile) to be unlinked if the process is interrupted. Returns a slot to
/// pass to unregisterTemporaryFile, or kNoTemporarySlot when the table is full (the file is
/// then not cleaned up on interruption; the table holds far more than are ever open at once).
size_t registerTemporaryFile(const char* path) noexcept;
/// Forgets a registration (before the path's string is freed). kNoTemporarySlot is ignored.
void unregisterTemporaryFile(size_t slot) noexcept;

inline constexpr size_t kNoTemporarySlot = ~size_t(0);

}  // namespace pl
