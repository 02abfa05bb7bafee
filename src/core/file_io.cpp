#include "core/file_io.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#if defined(__linux__)
#include <sys/mman.h>
#endif

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>

#include "core/cancel.h"
#include "core/error.h"
#include "core/interrupt.h"

namespace pl {
namespace {

/// A unique hidden name in the target's directory, so that the final rename is atomic (same
/// file system). Pid + counter keep concurrent writers (threads, processes) apart.
std::string temporaryPathBeside(const std::string& target) {
  static std::atomic<uint64_t> counter{0};
  const std::filesystem::path p(target);
  const std::string name = fmt::format(".{}.tmp-{}-{}", p.filename().string(), long(::getpid()), counter++);
  return (p.parent_path() / name).string();
}

/// fsync of an existing file or directory (opened read-only, which suffices on Linux and
/// BSD). Returns 0 or the errno of the failure.
int syncPath(const std::string& path, bool directory) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | (directory ? O_DIRECTORY : 0));
  if (fd < 0) return errno;
  const int result = ::fsync(fd) == 0 ? 0 : errno;
  ::close(fd);
  return result;
}

}  // namespace

std::string fileExtensionLower(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return ext;
}

void checkOutputPath(const std::string& path, std::span<const std::string_view> extensions, std::string_view option) {
  namespace fs = std::filesystem;
  const std::string ext = fileExtensionLower(path);
  if (!extensions.empty() && std::find(extensions.begin(), extensions.end(), ext) == extensions.end())
    failUsage("{} {}: expected a {} file name, not '{}'", option, path, alternatives(extensions),
              ext.empty() ? "no extension" : ext);
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (fs::is_directory(status)) failFile(path, "{} {}: is a directory", option, path);
  if (fs::exists(status) && !fs::is_regular_file(status)) failFile(path, "{} {}: exists and is not a regular file", option, path);
  const fs::path parentPath = fs::path(path).parent_path();
  const std::string parent = parentPath.empty() ? std::string(".") : parentPath.string();
  const fs::file_status parentStatus = fs::status(parent, ec);
  if (!fs::exists(parentStatus)) failFile(path, "{} {}: directory '{}' does not exist", option, path, parent);
  if (!fs::is_directory(parentStatus)) failFile(path, "{} {}: '{}' is not a directory", option, path, parent);
  // access(2) also reports a read-only file system (EROFS), which permission bits do not show.
  if (::access(parent.c_str(), W_OK | X_OK) != 0)
    failFile(path, "{} {}: cannot write in directory '{}': {}", option, path, parent, std::strerror(errno));
}

void checkDistinctOutputs(std::initializer_list<OutputFlag> outputs) {
  auto resolved = [](const std::string& path) {
    std::error_code ec;
    const std::filesystem::path p = std::filesystem::weakly_canonical(path, ec);
    return ec ? std::filesystem::path(path).lexically_normal() : p;
  };
  for (auto a = outputs.begin(); a != outputs.end(); ++a)
    for (auto b = a + 1; b != outputs.end(); ++b)
      if (!a->path.empty() && !b->path.empty() && resolved(a->path) == resolved(b->path))
        failUsage("{} {} and {} {} are the same file: one output would overwrite the other", a->option, a->path,
                  b->option, b->path);
}

void requireRegularFile(const std::string& path) {
  struct stat info {};
  if (::stat(path.c_str(), &info) != 0 || S_ISREG(info.st_mode)) return;
  const char* kind = S_ISDIR(info.st_mode)    ? "a directory"
                     : S_ISFIFO(info.st_mode) ? "a FIFO"
                     : S_ISCHR(info.st_mode)  ? "a character device"
                     : S_ISBLK(info.st_mode)  ? "a block device"
                     : S_ISSOCK(info.st_mode) ? "a socket"
                                              : "not a file";
  failFile(path, "{}: not a regular file ({})", path, kind);
}

PendingFile::PendingFile(std::string target) : target_(std::move(target)) {
  const std::filesystem::path parent = std::filesystem::path(target_).parent_path();
  std::error_code ec;
  if (!parent.empty() && !std::filesystem::is_directory(parent, ec))
    failFile(target_, "{}: cannot write: directory '{}' does not exist", target_, parent.string());
  if (std::filesystem::is_directory(target_, ec)) failFile(target_, "{}: cannot write: is a directory", target_);
  temporary_ = temporaryPathBeside(target_);
  interruptSlot_ = registerTemporaryFile(temporary_.c_str());
}

PendingFile::~PendingFile() {
  discard();
  unregisterTemporaryFile(interruptSlot_);
}

void PendingFile::discard() noexcept {
  if (!open_) return;
  open_ = false;
  std::error_code ignored;
  std::filesystem::remove(temporary_, ignored);
}

void PendingFile::commit(FileSync sync) {
  if (!open_) fail("{}: cannot write: the temporary file was already committed or discarded", target_);
  try {
    if (sync == FileSync::durable) {
      if (const int error = syncPath(temporary_, false)) fail("fsync failed: {}", std::strerror(error));
    }
    std::filesystem::rename(temporary_, target_);
  } catch (const std::exception& e) {
    discard();
    failFile(target_, "{}: cannot write: {}", target_, e.what());
  }
  open_ = false;
  if (sync == FileSync::durable) {
    // Make the rename itself durable. The file is complete and in place at this point, so a
    // failure here is not reported (there is nothing the caller could undo).
    const std::filesystem::path parent = std::filesystem::path(target_).parent_path();
    syncPath(parent.empty() ? std::string(".") : parent.string(), true);
  }
}

void writeFileAtomically(const std::string& path, const std::function<void(const std::string&)>& write,
                         FileSync sync) {
  PendingFile file(path);
  try {
    write(file.temporaryPath());
  } catch (const Cancelled&) {
    throw;  // stays a cancellation (core/cancel.h); the PendingFile removes the temporary
  } catch (const std::exception& e) {
    file.discard();
    failFile(path, "{}: cannot write: {}", path, e.what());
  }
  file.commit(sync);
}

void writeFileBytes(const std::string& path, const void* data, size_t size) {
  std::FILE* file = std::fopen(path.c_str(), "wb");
  if (!file) fail("cannot create file: {}", std::strerror(errno));
  // (fwrite's buffer may not be null even for 0 bytes: an empty file writes nothing.)
  const bool written = (size == 0 || std::fwrite(data, 1, size, file) == size) && std::fflush(file) == 0;
  const int writeErrno = errno;
  const bool closed = std::fclose(file) == 0;
  if (!written || !closed) fail("write failed: {}", std::strerror(written ? errno : writeErrno));
}

void writeFileAtomically(const std::string& path, std::string_view bytes, FileSync sync) {
  writeFileAtomically(
      path, [&](const std::string& temporaryPath) { writeFileBytes(temporaryPath, bytes.data(), bytes.size()); },
      sync);
}

MappedFile::MappedFile(const std::string& path) {
  requireRegularFile(path);
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) failFile(path, "{}: cannot open for reading: {}", path, std::strerror(errno));
  struct stat info {};
  if (::fstat(fd, &info) != 0) {
    const int error = errno;
    ::close(fd);
    fail("{}: cannot determine its size: {}", path, std::strerror(error));
  }
  size_ = size_t(info.st_size);
#if defined(__linux__)
  if (size_ > 0) {
    void* mapping = ::mmap(nullptr, size_, PROT_READ, MAP_PRIVATE | MAP_POPULATE, fd, 0);
    if (mapping != MAP_FAILED) {
      ::madvise(mapping, size_, MADV_SEQUENTIAL);
      data_ = static_cast<const unsigned char*>(mapping);
      mapped_ = true;
    }
  }
#endif
  if (!mapped_ && size_ > 0) {
    // No mmap (or it failed, e.g. on a special file system): read the bytes instead.
    copy_.resize(size_);
    size_t done = 0;
    while (done < size_) {
      const ssize_t got = ::read(fd, copy_.data() + done, size_ - done);
      if (got < 0 && errno == EINTR) continue;
      if (got <= 0) {
        const int error = got < 0 ? errno : 0;
        ::close(fd);
        fail("{}: read failed after {} of {} bytes{}{}", path, done, size_, error ? ": " : " (file shrank)",
             error ? std::strerror(error) : "");
      }
      done += size_t(got);
    }
    data_ = copy_.data();
  }
  ::close(fd);  // a mapping stays valid without its descriptor
}

MappedFile::~MappedFile() {
#if defined(__linux__)
  if (mapped_) ::munmap(const_cast<unsigned char*>(data_), size_);
#endif
}

}  // namespace pl
