// Resuming an interrupted bake: the visibility journal and the propagation checkpoint (resume.h).
#include "bake/resume.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <span>

#include <nlohmann/json.hpp>

#include "core/byte_writer.h"
#include "core/error.h"
#include "core/file_io.h"
#include "core/hash.h"
#include "lightfield/lightfield.h"
#include "plf/plf_file.h"

namespace pl {
namespace {

constexpr char kJournalMagic[8] = {'P', 'L', 'V', 'P', 'A', 'R', 'T', '\n'};
constexpr uint32_t kJournalVersion = 1;
constexpr size_t kJournalHeaderBytes = 48;
constexpr size_t kRecordHeaderBytes = 24;
/// Records are written in batches of about this many bytes (one `write` each): a killed bake
/// loses at most one batch besides the blocks in flight, and the tracing threads do not meet
/// in a system call per block.
constexpr size_t kJournalWriteBytes = size_t(1) << 20;

constexpr char kCheckpointMagic[8] = {'P', 'L', 'P', 'C', 'K', 'P', 'T', '\n'};
constexpr uint32_t kCheckpointVersion = 1;
constexpr size_t kCheckpointHeaderBytes = 8 + 4 + 4 + 8 + 4 + 4 + 4 * 8 + 3 * 8 + 2 * 8;

std::string errnoText() { return std::strerror(errno); }

template <typename T>
T getValue(std::span<const unsigned char> bytes, size_t at) {
  T value;
  std::memcpy(&value, bytes.data() + at, sizeof(T));
  return value;
}

/// Writes all of `bytes` to fd, or throws naming `path`.
void writeAll(int fd, std::span<const unsigned char> bytes, const std::string& path) {
  while (!bytes.empty()) {
    const ssize_t n = ::write(fd, bytes.data(), bytes.size());
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) fail("{}: cannot write the partial visibility field: {}", path, errnoText());
    bytes = bytes.subspan(size_t(n));
  }
}

std::vector<unsigned char> journalHeader(uint32_t gridSide, uint64_t hash, const std::vector<uint64_t>& blockTixels) {
  std::vector<unsigned char> h;
  appendBytes(h, kJournalMagic, 8);
  appendValue(h, kJournalVersion);
  appendValue(h, gridSide);
  appendValue(h, hash);
  appendValue(h, uint64_t(blockTixels.size()));
  appendValue(h, xxh64(blockTixels.data(), blockTixels.size() * sizeof(uint64_t)));
  appendValue(h, xxh64(h.data(), h.size()));
  return h;
}

/// One record's block restored from its content (the journal layout), checked like a .plv
/// block: false when it is not what the writer makes (then the record ends the valid prefix).
bool restoreBlock(std::span<const unsigned char> content, uint64_t tixels, uint64_t firstTixel, uint32_t n,
                  uint64_t targetTixels, EncodedRun& run, BlockExtras& extras) {
  if (content.size() < 8) return false;
  const uint64_t extraCount = getValue<uint64_t>(content, 0);
  constexpr size_t kExtraBytes = 8 + sizeof(VisibilityExtra);
  if (extraCount > tixels * n || content.size() < 8 + extraCount * kExtraBytes + tixels * sizeof(uint32_t)) return false;
  size_t at = 8;
  const uint64_t firstEntry = firstTixel * n, endEntry = (firstTixel + tixels) * n;
  extras.resize(extraCount);
  for (auto& [entry, extra] : extras) {
    entry = getValue<uint64_t>(content, at);
    extra = getValue<VisibilityExtra>(content, at + 8);
    at += kExtraBytes;
    if (entry < firstEntry || entry >= endEntry) return false;
  }
  run.tixelBytes.resize(tixels);
  std::memcpy(run.tixelBytes.data(), content.data() + at, tixels * sizeof(uint32_t));
  at += tixels * sizeof(uint32_t);
  run.bytes.assign(content.begin() + ptrdiff_t(at), content.end());
  // Every tixel decodes (checked), names tixels that exist, and has as many extra records as
  // flagged entries: the gather later decodes it unchecked.
  std::vector<VisibilityEntry> decoded(n);
  uint64_t used = 0, flagged = 0;
  for (uint64_t t = 0; t < tixels; ++t) {
    const uint32_t size = run.tixelBytes[t];
    if (size > run.bytes.size() - used ||
        decodeTixelEntries<true>(run.bytes.data() + used, size, n, decoded.data()) != size)
      return false;
    used += size;
    for (const VisibilityEntry& e : decoded) {
      if (!e.escaped() && e.tixel() >= targetTixels) return false;
      flagged += e.hasExtra() ? 1 : 0;
    }
  }
  return used == run.bytes.size() && flagged == extraCount;
}

}  // namespace

std::string partialVisibilityPath(const std::string& plvPath) { return plvPath + ".partial"; }
std::string propagationCheckpointPath(const std::string& plvPath) { return plvPath + ".checkpoint"; }

uint64_t testStopAfter(const char* variable) {
  const char* value = std::getenv(variable);
  return value ? std::strtoull(value, nullptr, 10) : 0;
}

VisibilityJournal::VisibilityJournal(std::string path, bool resume, std::function<void(const std::string&)> log)
    : path_(std::move(path)), resume_(resume), log_(std::move(log)), stopAfter_(testStopAfter("PLENOPTIC_TEST_STOP_AFTER_BLOCKS")) {}

VisibilityJournal::~VisibilityJournal() {
  // Unwinding (an error, Ctrl-C in Python): what is pending is saved too, if it can be.
  if (fd_ >= 0) {
    try {
      writeAll(fd_, pending_, path_);
    } catch (const Error&) {
    }
    ::close(fd_);
  }
}

std::vector<uint8_t> VisibilityJournal::open(uint64_t hash, uint32_t gridSide, const std::vector<uint64_t>& blockTixels,
                                             uint64_t targetTixels, std::vector<EncodedRun>& runs,
                                             std::vector<BlockExtras>& extras) {
  auto note = [&](const std::string& text) {
    if (log_) log_(text);
  };
  const uint32_t n = gridSide * gridSide;
  const std::vector<unsigned char> header = journalHeader(gridSide, hash, blockTixels);
  std::vector<uint8_t> done(blockTixels.size(), 0);
  std::vector<uint64_t> firstTixel(blockTixels.size() + 1, 0);
  for (size_t b = 0; b < blockTixels.size(); ++b) firstTixel[b + 1] = firstTixel[b] + blockTixels[b];
  uint64_t validBytes = 0;  // of the existing journal that is kept (0: none, start afresh)
  std::error_code ec;
  if (std::filesystem::exists(path_, ec) && !resume_) {
    note(fmt::format("visibility: ignoring the partial field {} (--fresh)", path_));
  } else if (std::filesystem::exists(path_, ec)) {
    const MappedFile file(path_);
    const std::span<const unsigned char> bytes = file.bytes();
    if (bytes.size() < kJournalHeaderBytes || std::memcmp(bytes.data(), header.data(), 8) != 0 ||
        getValue<uint64_t>(bytes, 40) != xxh64(bytes.data(), 40)) {
      note(fmt::format("visibility: tracing afresh, because {} is not a partial visibility field (damaged header)", path_));
    } else if (std::memcmp(bytes.data(), header.data(), kJournalHeaderBytes) != 0) {
      note(fmt::format("visibility: tracing afresh, because {} was traced for different geometry, parameterisation "
                       "or settings (or by another program version)",
                       path_));
    } else {
      size_t at = kJournalHeaderBytes;
      while (bytes.size() - at >= kRecordHeaderBytes) {
        const uint64_t block = getValue<uint64_t>(bytes, at), contentBytes = getValue<uint64_t>(bytes, at + 8),
                       check = getValue<uint64_t>(bytes, at + 16);
        if (block >= blockTixels.size() || contentBytes > bytes.size() - at - kRecordHeaderBytes) break;
        const std::span<const unsigned char> content = bytes.subspan(at + kRecordHeaderBytes, contentBytes);
        if (xxh64(content.data(), content.size(), xxh64(bytes.data() + at, 16)) != check) break;
        if (!done[block]) {
          if (!restoreBlock(content, blockTixels[block], firstTixel[block], n, targetTixels, runs[block], extras[block]))
            break;
          done[block] = 1;
          ++restoredBlocks_;
          restoredTixels_ += blockTixels[block];
        }
        at += kRecordHeaderBytes + contentBytes;
      }
      validBytes = at;
      std::string dropped;
      if (at < bytes.size())
        dropped = fmt::format("; dropped {} bytes of a torn or damaged tail", bytes.size() - at);
      note(fmt::format("visibility: resuming the interrupted trace in {}: {} of {} tixels ({} of {} blocks) already "
                       "traced{}",
                       path_, restoredTixels_, firstTixel.back(), restoredBlocks_, blockTixels.size(), dropped));
    }
  }
  if (validBytes == 0) {
    // A new journal: the blocks restored (none) are forgotten.
    std::fill(done.begin(), done.end(), 0);
    fd_ = ::open(path_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd_ < 0) fail("{}: cannot create the partial visibility field: {}", path_, errnoText());
    writeAll(fd_, header, path_);
  } else {
    fd_ = ::open(path_.c_str(), O_WRONLY | O_CLOEXEC);
    if (fd_ < 0 || ::ftruncate(fd_, off_t(validBytes)) != 0 || ::lseek(fd_, off_t(validBytes), SEEK_SET) < 0)
      fail("{}: cannot continue the partial visibility field: {}", path_, errnoText());
  }
  return done;
}

void VisibilityJournal::append(uint64_t block, const EncodedRun& run, const BlockExtras& extras) {
  // The record: its header (the checksum patched in last), then the block's content.
  std::vector<unsigned char> record;
  record.reserve(kRecordHeaderBytes + 8 + extras.size() * (8 + sizeof(VisibilityExtra)) + run.tixelBytes.size() * 4 +
                 run.bytes.size());
  appendValue(record, block);
  appendValue(record, uint64_t(0));  // the content's size, below
  appendValue(record, uint64_t(0));  // the checksum, below
  appendValue(record, uint64_t(extras.size()));
  for (const auto& [entry, extra] : extras) {
    appendValue(record, entry);
    appendValue(record, extra);
  }
  appendBytes(record, run.tixelBytes.data(), run.tixelBytes.size() * sizeof(uint32_t));
  appendBytes(record, run.bytes.data(), run.bytes.size());
  const uint64_t contentBytes = record.size() - kRecordHeaderBytes;
  std::memcpy(record.data() + 8, &contentBytes, 8);
  const uint64_t check = xxh64(record.data() + kRecordHeaderBytes, contentBytes, xxh64(record.data(), 16));
  std::memcpy(record.data() + 16, &check, 8);
  const std::lock_guard lock(mutex_);
  pending_.insert(pending_.end(), record.begin(), record.end());
  const bool stop = stopAfter_ > 0 && ++appended_ == stopAfter_;
  if (pending_.size() >= kJournalWriteBytes || stop) {
    writeAll(fd_, pending_, path_);
    pending_.clear();
  }
  if (stop) std::_Exit(kExitFailure);  // the test hook: "killed" here, with K blocks saved
}

void VisibilityJournal::finish() {
  pending_.clear();
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
  std::error_code ec;
  std::filesystem::remove(path_, ec);
}

uint64_t propagationKey(uint64_t fieldHash, const Scene& scene, const BakeSettings& settings) {
  const std::vector<unsigned char> sceneBytes = encodeSceneSection(scene);
  const std::string settingsText = toJson(settings).dump();
  uint64_t key = xxh64(sceneBytes.data(), sceneBytes.size(), fieldHash);
  key = xxh64(settingsText.data(), settingsText.size(), key);
  return xxh64(&kCheckpointVersion, sizeof kCheckpointVersion, key);
}

void writePropagationCheckpoint(const std::string& path, const PropagationProgress& p, const std::vector<Rgb>& direct,
                                const std::vector<Rgb>& punctualGlossy, const std::vector<Rgb>& current) {
  std::vector<unsigned char> header;
  appendBytes(header, kCheckpointMagic, 8);
  appendValue(header, kCheckpointVersion);
  appendValue(header, uint32_t(p.converged ? 1 : 0));
  appendValue(header, p.key);
  appendValue(header, p.iterations);
  appendValue(header, uint32_t(0));
  appendValue(header, p.previousPower);
  appendValue(header, p.previousL1Change);
  appendValue(header, double(p.omega));
  appendValue(header, p.residual);
  appendValue(header, p.shadowRays);
  appendValue(header, p.causticPhotons);
  appendValue(header, p.causticPhotonsLanded);
  appendValue(header, uint64_t(current.size()));
  appendValue(header, uint64_t(punctualGlossy.size()));
  writeFileAtomically(path, [&](const std::string& temp) {
    std::ofstream out(temp, std::ios::binary | std::ios::trunc);
    if (!out) fail("cannot create the temporary file {}", temp);
    Xxh64Stream hash;
    auto write = [&](const void* data, size_t size) {
      out.write(static_cast<const char*>(data), std::streamsize(size));
      hash.update(data, size);
    };
    write(header.data(), header.size());
    for (const std::vector<Rgb>* values : {&direct, &punctualGlossy, &current})
      write(values->data(), values->size() * sizeof(Rgb));
    const uint64_t digest = hash.digest();
    out.write(reinterpret_cast<const char*>(&digest), 8);
    out.flush();
    if (!out) fail("write failed (disk full?)");
  });
}

bool readPropagationCheckpoint(const std::string& path, uint64_t key, uint64_t valueCount, PropagationCheckpoint& checkpoint,
                               std::string* why) {
  PropagationProgress& c = checkpoint.progress;
  auto reason = [&](std::string text) {
    if (why) *why = std::move(text);
    return false;
  };
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) return reason(fmt::format("{} does not exist", path));
  const MappedFile file(path);
  const std::span<const unsigned char> bytes = file.bytes();
  if (bytes.size() < kCheckpointHeaderBytes + 8 || std::memcmp(bytes.data(), kCheckpointMagic, 8) != 0 ||
      getValue<uint64_t>(bytes, bytes.size() - 8) != xxh64(bytes.data(), bytes.size() - 8))
    return reason(fmt::format("{} is damaged (checksum mismatch)", path));
  if (getValue<uint32_t>(bytes, 8) != kCheckpointVersion || getValue<uint64_t>(bytes, 16) != key)
    return reason(fmt::format("{} was saved by a bake of another scene, other settings or another program version", path));
  const uint64_t values = getValue<uint64_t>(bytes, 88), punctual = getValue<uint64_t>(bytes, 96);
  if (values != valueCount || punctual > values ||
      bytes.size() != kCheckpointHeaderBytes + (2 * values + punctual) * sizeof(Rgb) + 8)
    return reason(fmt::format("{} holds {} values, this bake {}", path, values, valueCount));
  c.converged = getValue<uint32_t>(bytes, 12) != 0;
  c.key = key;
  c.iterations = getValue<uint32_t>(bytes, 24);
  c.previousPower = getValue<double>(bytes, 32);
  c.previousL1Change = getValue<double>(bytes, 40);
  c.omega = float(getValue<double>(bytes, 48));
  c.residual = getValue<double>(bytes, 56);
  c.shadowRays = getValue<uint64_t>(bytes, 64);
  c.causticPhotons = getValue<uint64_t>(bytes, 72);
  c.causticPhotonsLanded = getValue<uint64_t>(bytes, 80);
  auto take = [&](std::vector<Rgb>& out, uint64_t count, size_t at) {
    out.resize(count);
    std::memcpy(static_cast<void*>(out.data()), bytes.data() + at, count * sizeof(Rgb));
    return at + count * sizeof(Rgb);
  };
  size_t at = kCheckpointHeaderBytes;
  at = take(checkpoint.direct, values, at);
  at = take(checkpoint.punctualGlossy, punctual, at);
  take(checkpoint.current, values, at);
  return true;
}

}  // namespace pl
