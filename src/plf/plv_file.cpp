// The .plv visibility-field file (layout in plv_file.h).
#include "plf/plv_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <map>
#include <mutex>
#include <filesystem>
#include <fstream>
#include <span>

#include "core/error.h"
#include "core/file_io.h"
#include "core/hash.h"
#include "core/memory.h"
#include "core/parallel.h"
#include "core/progress.h"
#include "plf/codec_backends.h"

namespace pl {
namespace {

constexpr char kPlvMagic[8] = {'P', 'L', 'V', 'I', 'S', '\0', '\r', '\n'};
constexpr size_t kPlvHeaderSize = 8 + 4 + 4 + 8 * 5;

/// Entry blocks of the .plv: as many whole tixels as make about kBlockEntryBytes of entries.
constexpr uint64_t kBlockEntryBytes = uint64_t(1) << 19;
/// A reader refuses blocks larger than this (a writer never makes them): it bounds the
/// scratch buffer and what one frame may claim.
constexpr uint64_t kMaxBlockEntryBytes = uint64_t(1) << 24;
/// zstd level of the .plv frames. On Sponza's default field level 3 saves 1.5 % of the bytes
/// (3.41 instead of 3.46 per entry) for about 1.4× the time, level 9 5 % for 3×.
constexpr int kPlvZstdLevel = 1;
/// Blocks compressed in parallel between two writes (bounds the writer's buffers).
constexpr uint64_t kWriteBatchBlocks = 16;

uint64_t tixelsPerBlock(uint32_t directionsPerTixel) {
  return std::max<uint64_t>(1, kBlockEntryBytes / (uint64_t(directionsPerTixel) * sizeof(VisibilityEntry)));
}

// ---- Stored entry blocks ------------------------------------------------------------------
// A block's entries in byte streams, each its own zstd frame (layout in plv_file.h): the one
// place the entry blocks' frames are made and read.

enum PlvStream : uint32_t { kOpsStream, kNearStream, kFarLowStream, kFarHighStream, kTargetsStream, kFractionsStream };
static_assert(kFractionsStream + 1 == kPlvStreams);
constexpr uint8_t kOpEscape = 0, kOpNear = 1, kOpFar = 2, kOpGeneral = 3;
constexpr uint32_t kFlagBits = VisibilityEntry::kBackSide | VisibilityEntry::kHasExtra;
/// Bytes of a stored block's header: the bits byte, then the raw and stored sizes (u32 each).
constexpr uint64_t kBlockHeaderBytes = 1 + 2 * kPlvStreams * sizeof(uint32_t);
/// Zero bytes after each decompressed stream, so that the decoder may read a whole word.
constexpr uint64_t kStreamPadding = 8;

/// Bytes of an entry's fractions in the fractions stream at `bits` per fraction.
constexpr uint32_t storedFractionBytes(uint32_t bits) { return bits == kExactFractionBits ? 4 : (2 * bits + 7) / 8; }

/// The stored frame of `tixels` tixels' entries (n each, tixel-major) at `bits` per fraction.
std::vector<unsigned char> encodeEntryBlock(const VisibilityEntry* entries, uint64_t tixels, uint32_t n, uint32_t bits) {
  const uint64_t count = tixels * n;
  const bool exact = bits == kExactFractionBits;
  const uint32_t fractionBytes = storedFractionBytes(bits);
  std::array<std::vector<unsigned char>, kPlvStreams> streams;
  streams[kOpsStream].resize(count);
  streams[kNearStream].reserve(count);
  streams[kFractionsStream].reserve(count * fractionBytes);
  auto put = [](std::vector<unsigned char>& stream, uint64_t value, uint32_t bytes) {
    const size_t at = stream.size();
    stream.resize(at + bytes);
    std::memcpy(stream.data() + at, &value, bytes);  // little-endian, as the whole format
  };
  for (uint64_t t = 0; t < tixels; ++t) {
    int64_t previous = 0;  // index of the tixel's last entry that saw a tixel
    for (uint32_t k = 0; k < n; ++k) {
      const VisibilityEntry& e = entries[t * n + k];
      const uint64_t fractions = exact ? uint64_t(e.fu) | uint64_t(e.fv) << 16
                                       : quantiseFraction(e.fu, bits) | uint64_t(quantiseFraction(e.fv, bits)) << bits;
      uint8_t op = kOpEscape;
      if (e.target != VisibilityEntry::kEscape || fractions != 0) {
        const int64_t index = e.tixel(), delta = index - previous;
        const bool plain = (e.target & kFlagBits) == 0 && !e.escaped();
        if (plain && delta >= INT8_MIN && delta <= INT8_MAX) {
          op = kOpNear;
          streams[kNearStream].push_back(uint8_t(delta));
        } else if (plain && delta >= INT16_MIN && delta <= INT16_MAX) {
          op = kOpFar;
          streams[kFarLowStream].push_back(uint8_t(delta));
          streams[kFarHighStream].push_back(uint8_t(uint64_t(delta) >> 8));
        } else {
          op = kOpGeneral;
          put(streams[kTargetsStream], e.target, 4);
        }
        put(streams[kFractionsStream], fractions, fractionBytes);
        if (!e.escaped()) previous = index;
      }
      streams[kOpsStream][t * n + k] = op;
    }
  }
  std::array<std::vector<unsigned char>, kPlvStreams> frames;
  uint64_t total = kBlockHeaderBytes;
  for (uint32_t i = 0; i < kPlvStreams; ++i) {
    if (!streams[i].empty()) frames[i] = detail::zstdCompress(streams[i], kPlvZstdLevel);
    total += frames[i].size();
  }
  std::vector<unsigned char> stored(total);
  stored[0] = uint8_t(bits);
  unsigned char* at = stored.data() + 1;
  for (uint32_t i = 0; i < kPlvStreams; ++i, at += 4) {
    const uint32_t raw = uint32_t(streams[i].size());
    std::memcpy(at, &raw, 4);
  }
  for (uint32_t i = 0; i < kPlvStreams; ++i, at += 4) {
    const uint32_t size = uint32_t(frames[i].size());
    std::memcpy(at, &size, 4);
  }
  for (uint32_t i = 0; i < kPlvStreams; ++i) {
    if (!frames[i].empty()) std::memcpy(at, frames[i].data(), frames[i].size());
    at += frames[i].size();
  }
  return stored;
}

/// A stored entry block's header, checked against its tixels' entry count: the bits per
/// fraction, each stream's raw bytes and where its frame lies in the block. Fails naming
/// `context` on a block that cannot be one of `count` entries.
struct EntryBlockHeader {
  uint32_t bits = 0;
  std::array<uint64_t, kPlvStreams> rawSizes{}, frameOffset{}, frameSizes{};
};
EntryBlockHeader readEntryBlockHeader(std::span<const unsigned char> stored, uint64_t count, const std::string& context) {
  if (stored.size() < kBlockHeaderBytes) fail("{}: corrupt entry block: {} bytes, shorter than its header", context, stored.size());
  EntryBlockHeader h;
  h.bits = stored[0];
  if (!validFractionBits(h.bits)) fail("{}: corrupt entry block: {} bits per fraction (1 to 8, or 16)", context, h.bits);
  uint64_t offset = kBlockHeaderBytes;
  for (uint32_t i = 0; i < kPlvStreams; ++i) {
    uint32_t raw, size;
    std::memcpy(&raw, stored.data() + 1 + 4 * i, 4);
    std::memcpy(&size, stored.data() + 1 + 4 * (kPlvStreams + i), 4);
    // Each stream holds at most one item per entry: 1 byte (ops, deltas), 4 (targets, fractions).
    const uint64_t most = count * (i == kTargetsStream || i == kFractionsStream ? 4 : 1);
    if (raw > most || (i == kOpsStream && raw != count) || (raw == 0) != (size == 0) || size > stored.size() - offset)
      fail("{}: corrupt entry block: stream {} declares {} bytes in a frame of {} (the block holds {} entries in {} bytes)",
           context, i, raw, size, count, stored.size());
    h.rawSizes[i] = raw;
    h.frameOffset[i] = offset;
    h.frameSizes[i] = size;
    offset += size;
  }
  if (offset != stored.size()) fail("{}: corrupt entry block: {} bytes after its streams", context, stored.size() - offset);
  return h;
}

/// Checks a stored entry block of `count` entries without decoding it (its header and that each
/// stream's frame declares its size).
void checkEntryBlock(std::span<const unsigned char> stored, uint64_t count, const std::string& context) {
  const EntryBlockHeader h = readEntryBlockHeader(stored, count, context);
  for (uint32_t i = 0; i < kPlvStreams; ++i)
    if (h.frameSizes[i] > 0)
      detail::zstdCheckFrame(stored.subspan(h.frameOffset[i], h.frameSizes[i]), h.rawSizes[i],
                             fmt::format("{} stream {}", context, i));
}

/// Decodes a stored entry block of `tixels` tixels of n entries into out (tixels · n entries,
/// tixel-major), `scratch` holding its streams; returns its bits per fraction. Checked: fails
/// naming `context` on any block the writer cannot have made (stream sizes that disagree with
/// the ops, an op above 3, an index outside [0, kEscape), fraction bits the writer leaves 0).
uint32_t decodeEntryBlock(std::span<const unsigned char> stored, uint64_t tixels, uint32_t n,
                          std::vector<unsigned char>& scratch, VisibilityEntry* out, const std::string& context) {
  const uint64_t count = tixels * n;
  const EntryBlockHeader h = readEntryBlockHeader(stored, count, context);
  std::array<const unsigned char*, kPlvStreams> stream{};
  uint64_t scratchBytes = 0;
  for (uint32_t i = 0; i < kPlvStreams; ++i) scratchBytes += h.rawSizes[i] + kStreamPadding;
  scratch.resize(scratchBytes);
  for (uint64_t i = 0, at = 0; i < kPlvStreams; ++i) {
    unsigned char* into = scratch.data() + at;
    if (h.frameSizes[i] > 0)
      detail::zstdDecompressInto(stored.subspan(h.frameOffset[i], h.frameSizes[i]), {into, h.rawSizes[i]},
                                 fmt::format("{} stream {}", context, i));
    std::memset(into + h.rawSizes[i], 0, kStreamPadding);
    stream[i] = into;
    at += h.rawSizes[i] + kStreamPadding;
  }
  // The ops say how many items each other stream must hold: checked first, so that the loops
  // below read within the streams without a check per entry.
  const unsigned char* const op = stream[kOpsStream];
  uint64_t invalid = 0, nears = 0, fars = 0, generals = 0;
  for (uint64_t i = 0; i < count; ++i) {  // branch-free, so that it vectorises
    const uint8_t o = op[i];
    invalid += o > kOpGeneral;
    nears += o == kOpNear;
    fars += o == kOpFar;
    generals += o == kOpGeneral;
  }
  if (invalid > 0) {
    const uint64_t i = uint64_t(std::find_if(op, op + count, [](uint8_t o) { return o > kOpGeneral; }) - op);
    fail("{}: corrupt entry block: op {} of entry {}", context, op[i], i);
  }
  const uint32_t bits = h.bits, fractionBytes = storedFractionBytes(bits);
  if (h.rawSizes[kNearStream] != nears || h.rawSizes[kFarLowStream] != fars || h.rawSizes[kFarHighStream] != fars ||
      h.rawSizes[kTargetsStream] != 4 * generals || h.rawSizes[kFractionsStream] != uint64_t(fractionBytes) * (nears + fars + generals))
    fail("{}: corrupt entry block: its streams' sizes disagree with its ops", context);
  const unsigned char *near = stream[kNearStream], *farLow = stream[kFarLowStream], *farHigh = stream[kFarHighStream];
  const unsigned char *targets = stream[kTargetsStream], *fractions = stream[kFractionsStream];
  const bool exact = bits == kExactFractionBits;
  const uint64_t fractionMask = (uint64_t(1) << (8 * fractionBytes)) - 1;
  // Bits of the stored fractions the writer leaves 0 (none for exact ones).
  const uint64_t unusedBits = exact ? 0 : fractionMask & ~((uint64_t(1) << (2 * bits)) - 1);
  // Both fractions' 16-bit values (fu | fv << 16) per stored fractions byte, for F ≤ 4: one load.
  std::array<uint32_t, 256> pairs{};
  if (fractionBytes == 1)
    for (uint32_t q = 0; q < (1u << (2 * bits)); ++q) pairs[q] = detail::fractionPair(bits, q);
  auto levelsOf = [&](uint64_t f) -> uint64_t {  // fu | fv << 16
    if (fractionBytes == 1) return pairs[f & 0xff];
    return exact ? f : detail::fractionPair(bits, f);
  };
  for (uint64_t t = 0; t < tixels; ++t) {
    int64_t previous = 0;
    uint64_t bad = 0;
    for (uint64_t i = t * n; i < (t + 1) * n; ++i) {
      const uint8_t o = op[i];
      uint64_t f;
      std::memcpy(&f, fractions, 8);
      f &= fractionMask;
      if (o == kOpGeneral) [[unlikely]] {
        uint32_t target;
        std::memcpy(&target, targets, 4);
        targets += 4;
        fractions += fractionBytes;
        bad |= f & unusedBits;
        VisibilityEntry e;
        e.target = target;
        const uint64_t levels = levelsOf(f);
        e.fu = uint16_t(levels);
        e.fv = uint16_t(levels >> 16);
        if (!e.escaped()) previous = e.tixel();
        out[i] = e;
        continue;
      }
      // An escape, a near or a far hit, without branches (their mix is unpredictable): each
      // stream's cursor moves by the entry's share of it, a mask selects the delta.
      const uint64_t isNear = 0 - uint64_t(o == kOpNear), isFar = 0 - uint64_t(o == kOpFar), hit = isNear | isFar;
      const int64_t nearDelta = int8_t(*near), farDelta = int16_t(uint16_t(*farLow) | uint16_t(*farHigh) << 8);
      previous += int64_t((uint64_t(nearDelta) & isNear) | (uint64_t(farDelta) & isFar));
      near += isNear & 1;
      farLow += isFar & 1;
      farHigh += isFar & 1;
      fractions += fractionBytes & hit;
      bad |= hit & ((uint64_t(previous) >= uint64_t(VisibilityEntry::kEscape)) | (f & unusedBits));
      // The entry as one 8-byte word (target, then fu and fv: little-endian, one store).
      const uint64_t packed = ((uint64_t(uint32_t(previous)) | (levelsOf(f) << 32)) & hit) |
                              (uint64_t(VisibilityEntry::kEscape) & ~hit);
      std::memcpy(static_cast<void*>(&out[i]), &packed, 8);
    }
    if (bad != 0) fail("{}: corrupt entry block: the entries of its tixel {} do not decode", context, t);
  }
  return bits;
}

}  // namespace

uint64_t visibilityBlockTixels(uint32_t directionsPerTixel) { return tixelsPerBlock(directionsPerTixel); }

uint64_t visibilityWriteBufferBytes(uint32_t gridSide) {
  // Per block of a batch: its content (the sizes and the encoded entries, fewer than 8 bytes
  // per entry), counted three times as before the streams, and while it is framed its entries
  // decoded (8 bytes each) and its streams (at most 12 bytes per entry: an op, a delta's bytes,
  // a target and fractions) twice, raw and compressed.
  const uint32_t n = gridSide * gridSide;
  const uint64_t blockBytes = tixelsPerBlock(n) * (sizeof(uint32_t) + maxEncodedTixelBytes(n));
  const uint64_t blockEntries = tixelsPerBlock(n) * n;
  return kWriteBatchBlocks * (3 * blockBytes + blockEntries * (sizeof(VisibilityEntry) + 2 * 12));
}

struct VisibilityWriter::Impl {
  PendingFile file;
  std::ofstream out;
  Xxh64Stream payloadHash;
  mutable std::mutex mutex;
  uint64_t next = 0;       ///< the next block to write
  uint64_t offset = 0;     ///< of the next frame in the file
  uint64_t waiting = 0;    ///< bytes of the frames in `pending`
  std::map<uint64_t, std::pair<std::vector<unsigned char>, uint64_t>> pending;  ///< block → (frame, content bytes)

  explicit Impl(const std::string& path) : file(path) {}
  void put(const void* data, size_t size) { out.write(static_cast<const char*>(data), std::streamsize(size)); }
  void putPayload(const void* data, size_t size) {
    put(data, size);
    payloadHash.update(data, size);
  }
  void check() {
    if (!out) fail("{}: cannot write: write failed (disk full?)", file.target());
  }
};

VisibilityWriter::VisibilityWriter(const std::string& path, uint32_t gridSide, uint64_t hash, uint64_t tixelCount)
    : impl_(std::make_unique<Impl>(path)) {
  const uint32_t n = gridSide * gridSide;
  frames_.perBlock = tixelsPerBlock(n);
  frames_.tixelCount = tixelCount;
  frames_.directionsPerTixel = n;
  frames_.blocks = (tixelCount + frames_.perBlock - 1) / frames_.perBlock;
  frames_.frameOffset.assign(frames_.blocks + 1, 0);
  frames_.frameSizes.assign(frames_.blocks + 1, 0);
  frames_.contentSizes.assign(frames_.blocks + 1, 0);
  Impl& w = *impl_;
  w.out.open(w.file.temporaryPath(), std::ios::binary | std::ios::trunc);
  if (!w.out) fail("{}: cannot write: cannot create the temporary file {}", path, w.file.temporaryPath());
  const uint64_t entryCount = tixelCount * n, extraCountPlaceholder = 0, placeholder = 0;
  w.put(kPlvMagic, 8);
  w.put(&kPlvVersion, 4);
  w.put(&gridSide, 4);
  w.put(&hash, 8);
  w.put(&tixelCount, 8);
  w.put(&entryCount, 8);
  w.put(&extraCountPlaceholder, 8);  // the extra records' count and the payload hash, written last
  w.put(&placeholder, 8);
  w.putPayload(&frames_.perBlock, 8);
  w.offset = kPlvHeaderSize + 8;
  w.check();
}

VisibilityWriter::~VisibilityWriter() = default;

std::vector<unsigned char> VisibilityWriter::frameBlock(std::span<const uint32_t> tixelBytes,
                                                        std::span<const unsigned char> encoded, uint32_t directionsPerTixel,
                                                        uint64_t* contentBytes) {
  const uint64_t tixels = tixelBytes.size(), n = directionsPerTixel;
  // The tixels' entries, decoded (checked: they are this program's own encodings, so a failure
  // is a bug, not a damaged file), then stored in streams.
  std::vector<VisibilityEntry> entries(tixels * n);
  uint32_t bits = 0;
  uint64_t used = 0;
  for (uint64_t t = 0; t < tixels; ++t) {
    const uint32_t size = tixelBytes[t];
    if (size > encoded.size() - used || size == 0 ||
        decodeTixelEntries<true>(encoded.data() + used, size, uint32_t(n), entries.data() + t * n) != size)
      fail("visibility field: the encoding of tixel {} of a block does not decode", t);
    if (t > 0 && encoded[used] != bits) fail("visibility field: tixels of one block with {} and {} bits per fraction", bits, encoded[used]);
    bits = encoded[used];
    used += size;
  }
  if (used != encoded.size()) fail("visibility field: {} bytes after a block's tixels", encoded.size() - used);
  if (contentBytes) *contentBytes = tixels * sizeof(uint32_t) + encoded.size();
  return encodeEntryBlock(entries.data(), tixels, uint32_t(n), tixels > 0 ? bits : kCompactFractionBits);
}

void VisibilityWriter::put(uint64_t b, std::vector<unsigned char> frame, uint64_t contentBytes) {
  Impl& w = *impl_;
  const std::lock_guard lock(w.mutex);
  if (b >= frames_.blocks || b < w.next || w.pending.count(b))
    fail("{}: visibility block {} handed over twice or out of range", w.file.target(), b);
  w.waiting += frame.size();
  w.pending.emplace(b, std::make_pair(std::move(frame), contentBytes));
  // The blocks now contiguous with those written, in order.
  for (auto it = w.pending.begin(); it != w.pending.end() && it->first == w.next; it = w.pending.erase(it)) {
    const std::vector<unsigned char>& f = it->second.first;
    w.putPayload(f.data(), f.size());
    w.check();
    frames_.frameOffset[w.next] = w.offset;
    frames_.frameSizes[w.next] = f.size();
    frames_.contentSizes[w.next] = it->second.second;
    w.offset += f.size();
    w.waiting -= f.size();
    ++w.next;
  }
}

uint64_t VisibilityWriter::waitingBytes() const {
  const std::lock_guard lock(impl_->mutex);
  return impl_->waiting;
}

VisibilityFrames VisibilityWriter::finish(std::span<const uint64_t> extraOffset, std::span<const VisibilityExtra> extras) {
  Impl& w = *impl_;
  if (w.next != frames_.blocks) fail("{}: {} of {} visibility blocks written", w.file.target(), w.next, frames_.blocks);
  // The extra records' frame: offsets, then records.
  std::vector<unsigned char> tail(extraOffset.size() * sizeof(uint64_t) + extras.size() * sizeof(VisibilityExtra));
  if (!extraOffset.empty()) std::memcpy(tail.data(), extraOffset.data(), extraOffset.size() * sizeof(uint64_t));
  if (!extras.empty())
    std::memcpy(tail.data() + extraOffset.size() * sizeof(uint64_t), extras.data(), extras.size() * sizeof(VisibilityExtra));
  const std::vector<unsigned char> tailFrame = detail::zstdCompress(tail, kPlvZstdLevel);
  w.putPayload(tailFrame.data(), tailFrame.size());
  const uint64_t b = frames_.blocks;
  frames_.frameOffset[b] = w.offset;
  frames_.frameSizes[b] = tailFrame.size();
  frames_.contentSizes[b] = tail.size();
  w.putPayload(frames_.frameSizes.data(), frames_.frameSizes.size() * sizeof(uint64_t));
  w.putPayload(frames_.contentSizes.data(), frames_.contentSizes.size() * sizeof(uint64_t));
  const uint64_t digest = w.payloadHash.digest(), extraCount = extras.size();
  w.out.seekp(kPlvHeaderSize - 16);
  w.put(&extraCount, 8);
  w.put(&digest, 8);
  w.out.flush();
  w.check();
  w.out.close();
  w.check();
  w.file.commit();
  return frames_;
}

void writeVisibility(const std::string& path, const VisibilityField& field) {
  VisibilityWriter writer(path, field.gridSide, field.hash, field.tixelCount);
  const uint64_t perBlock = writer.perBlock(), blocks = writer.blocks();
  // Entry blocks framed a batch at a time in parallel, handed over in order: memory stays
  // bounded by one batch of frames whatever the field's size.
  const uint64_t batch = kWriteBatchBlocks;
  std::vector<std::vector<unsigned char>> frames(batch);
  std::vector<uint64_t> contentBytes(batch);
  Progress progress("visibility: writing", blocks);
  for (uint64_t b0 = 0; b0 < blocks; b0 += batch) {
    const uint64_t b1 = std::min(blocks, b0 + batch);
    parallelFor(b1 - b0, [&](uint64_t i) {
      const uint64_t t0 = (b0 + i) * perBlock, t1 = std::min(field.tixelCount, t0 + perBlock);
      std::vector<uint32_t> sizes(t1 - t0);
      for (uint64_t t = t0; t < t1; ++t) sizes[t - t0] = uint32_t(field.entryOffset[t + 1] - field.entryOffset[t]);
      frames[i] = VisibilityWriter::frameBlock(
          sizes, {field.entryBytes.data() + field.entryOffset[t0], field.entryOffset[t1] - field.entryOffset[t0]},
          field.directionsPerTixel(), &contentBytes[i]);
    });
    for (uint64_t i = 0; i < b1 - b0; ++i) writer.put(b0 + i, std::move(frames[i]), contentBytes[i]);
    progress.advance(b1 - b0);
  }
  writer.finish({field.extraOffset.data(), field.extraOffset.size()}, {field.extras.data(), field.extras.size()});
}

VisibilityBlockFile::VisibilityBlockFile(std::string path, VisibilityFrames frames)
    : path_(std::move(path)), frames_(std::move(frames)) {
  fd_ = ::open(path_.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd_ < 0) fail("{}: cannot open the visibility field: {}", path_, std::strerror(errno));
}

VisibilityBlockFile::~VisibilityBlockFile() {
  if (fd_ >= 0) ::close(fd_);
}

void VisibilityBlockFile::readEntries(uint64_t b, std::vector<unsigned char>& frame, std::vector<unsigned char>& stream,
                                      std::vector<VisibilityEntry>& entries) const {
  if (b >= frames_.blocks) fail("{}: visibility block {} of {}", path_, b, frames_.blocks);
  frame.resize(frames_.frameSizes[b]);
  for (uint64_t done = 0; done < frame.size();) {
    const ssize_t got = ::pread(fd_, frame.data() + done, frame.size() - done, off_t(frames_.frameOffset[b] + done));
    if (got < 0 && errno == EINTR) continue;
    if (got <= 0)
      fail("{}: cannot read visibility block {}: {}", path_, b, got < 0 ? std::strerror(errno) : "the file is truncated");
    done += uint64_t(got);
  }
  const uint64_t tixels = std::min(frames_.tixelCount - b * frames_.perBlock, frames_.perBlock);
  entries.resize(tixels * frames_.directionsPerTixel);
  decodeEntryBlock(frame, tixels, frames_.directionsPerTixel, stream, entries.data(),
                   fmt::format("{}: visibility block {}", path_, b));
}

namespace {

/// A .plv's header (plv_file.h).
struct PlvHeader {
  uint32_t version = 0, gridSide = 0;
  uint64_t hash = 0, tixelCount = 0, entryCount = 0, extraCount = 0, payloadHash = 0;
};

/// Reads the header of `bytes` (the file `path`); fails on a file that is not a .plv. The counts
/// are checked only for the current version (readPlvLayout).
PlvHeader readPlvHeader(const std::string& path, std::span<const unsigned char> bytes) {
  if (bytes.size() < kPlvHeaderSize)
    fail("{}: truncated visibility field ({} bytes, header needs {})", path, bytes.size(), kPlvHeaderSize);
  size_t at = 0;
  auto get = [&](void* data, size_t size) {
    std::memcpy(data, bytes.data() + at, size);
    at += size;
  };
  char magic[8];
  PlvHeader h;
  get(magic, 8);
  if (std::memcmp(magic, kPlvMagic, 8) != 0) fail("{}: not a plenoptic visibility field (bad magic)", path);
  get(&h.version, 4);
  if (h.version > kPlvVersion) fail("{}: visibility field version {} (this program reads version {})", path, h.version, kPlvVersion);
  get(&h.gridSide, 4);
  get(&h.hash, 8);
  get(&h.tixelCount, 8);
  get(&h.entryCount, 8);
  get(&h.extraCount, 8);
  get(&h.payloadHash, 8);
  return h;
}

/// The payload's layout, checked: the block size, the frame table, and where each block's
/// encoded entries start in the field's entry bytes (blockEntryStart[B]: their total).
struct PlvLayout {
  uint64_t perBlock = 0, blocks = 0;
  std::vector<uint64_t> frameSizes, contentSizes, frameOffset, blockEntryStart;
};

/// Checks the counts of a current-version header, the payload's checksum, its frame table and
/// every frame's declared size (before anything is allocated for the decoded field: a forged
/// header or table is refused, not obeyed). Fails naming `path` on anything corrupt.
PlvLayout readPlvLayout(const std::string& path, std::span<const unsigned char> bytes, const PlvHeader& h) {
  const uint64_t fileSize = bytes.size();
  const uint64_t tixelCount = h.tixelCount, extraCount = h.extraCount;
  if (h.gridSide == 0 || h.gridSide > kMaxGatherGridSide || tixelCount > VisibilityEntry::kIndexMask ||
      h.entryCount != tixelCount * uint64_t(h.gridSide) * h.gridSide || extraCount > h.entryCount)
    fail("{}: inconsistent counts in the header (grid {}, {} tixels, {} entries, {} extra records)", path, h.gridSide,
         tixelCount, h.entryCount, extraCount);
  const uint64_t n = uint64_t(h.gridSide) * h.gridSide;

  // The payload: its checksum first (a damaged file is "corrupt", whatever its damage happens
  // to break), then the frame table at its end, checked against the bytes present.
  const std::span<const unsigned char> payload = bytes.subspan(kPlvHeaderSize);
  if (xxh64(payload.data(), payload.size()) != h.payloadHash)
    fail("{}: corrupt or truncated visibility field (payload checksum mismatch)", path);
  if (payload.size() < 8) fail("{}: truncated visibility field (no block size)", path);
  PlvLayout l;
  std::memcpy(&l.perBlock, payload.data(), 8);
  if (l.perBlock == 0 || l.perBlock > kMaxBlockEntryBytes / (n * sizeof(VisibilityEntry)))
    fail("{}: corrupt visibility field: {} tixels per block of {} directions each", path, l.perBlock, n);
  const uint64_t perBlock = l.perBlock;
  const uint64_t blocks = l.blocks = (tixelCount + perBlock - 1) / perBlock;
  const uint64_t tableBytes = 2 * (blocks + 1) * sizeof(uint64_t);
  if (payload.size() < 8 + tableBytes)
    fail("{}: truncated visibility field: {} bytes cannot hold the table of {} frames", path, fileSize, blocks + 1);
  std::vector<uint64_t>& frameSizes = l.frameSizes;
  std::vector<uint64_t>& contentSizes = l.contentSizes;
  frameSizes.resize(blocks + 1);
  contentSizes.resize(blocks + 1);
  std::memcpy(frameSizes.data(), payload.data() + payload.size() - tableBytes, tableBytes / 2);
  std::memcpy(contentSizes.data(), payload.data() + payload.size() - tableBytes / 2, tableBytes / 2);
  const uint64_t framesBytes = payload.size() - 8 - tableBytes;
  uint64_t sum = 0;
  for (uint64_t size : frameSizes) {
    if (size > framesBytes - sum) fail("{}: corrupt visibility field: the frame sizes exceed the {} bytes present", path, framesBytes);
    sum += size;
  }
  if (sum != framesBytes)
    fail("{}: corrupt visibility field: {} bytes of frames present, the table describes {}", path, framesBytes, sum);

  // Every frame must declare the size the table gives it, and that size must lie within what
  // its tixels' encodings can take.
  l.blockEntryStart.assign(blocks + 1, 0);  // of each block in the field's entry bytes
  l.frameOffset.assign(blocks + 2, kPlvHeaderSize + 8);  // of each frame in the file
  for (uint64_t b = 0; b <= blocks; ++b) {
    const uint64_t tixels = b < blocks ? std::min(tixelCount - b * perBlock, perBlock) : 0;
    if (b < blocks) {
      const uint64_t least = tixels * (sizeof(uint32_t) + kTixelHeaderBytes(uint32_t(n)));
      const uint64_t most = tixels * (sizeof(uint32_t) + maxEncodedTixelBytes(uint32_t(n)));
      if (contentSizes[b] < least || contentSizes[b] > most)
        fail("{}: corrupt visibility field: block {} of {} tixels declares {} bytes (between {} and {})", path, b,
             tixels, contentSizes[b], least, most);
      l.blockEntryStart[b + 1] = l.blockEntryStart[b] + contentSizes[b] - tixels * sizeof(uint32_t);
    } else if (contentSizes[b] != (tixelCount + 1) * sizeof(uint64_t) + extraCount * sizeof(VisibilityExtra)) {
      fail("{}: corrupt visibility field: the extra records' frame declares {} bytes", path, contentSizes[b]);
    }
    if (b < blocks)
      checkEntryBlock(bytes.subspan(l.frameOffset[b], frameSizes[b]), tixels * n, fmt::format("{}: visibility block {}", path, b));
    else
      detail::zstdCheckFrame(bytes.subspan(l.frameOffset[b], frameSizes[b]), contentSizes[b],
                             fmt::format("{}: visibility extra records", path));
    l.frameOffset[b + 1] = l.frameOffset[b] + frameSizes[b];
  }
  return l;
}

/// Bytes a field of this header and entry-byte total holds in memory (VisibilityField::bytes).
uint64_t heldBytes(const PlvHeader& h, uint64_t entryBytes) {
  return entryBytes + kEntryBytesPadding + 2 * (h.tixelCount + 1) * sizeof(uint64_t) + h.extraCount * sizeof(VisibilityExtra);
}

}  // namespace

VisibilityFileInfo readVisibilityInfo(const std::string& path) {
  const MappedFile file(path);
  const std::span<const unsigned char> bytes = file.bytes();
  const PlvHeader h = readPlvHeader(path, bytes);
  VisibilityFileInfo info;
  info.version = h.version;
  info.gridSide = h.gridSide;
  info.hash = h.hash;
  info.tixelCount = h.tixelCount;
  info.entryCount = h.entryCount;
  info.extraCount = h.extraCount;
  info.fileBytes = bytes.size();
  if (h.version == kPlvVersion) {
    const PlvLayout l = readPlvLayout(path, bytes, h);
    info.entryBytes = l.blockEntryStart[l.blocks];
    info.heldBytes = heldBytes(h, info.entryBytes);
    if (l.blocks > 0) info.fractionBits = bytes[l.frameOffset[0]];  // the first block's (the bake writes one for all)
  }
  return info;
}

bool readVisibility(const std::string& path, uint64_t expectedHash, VisibilityField& field, std::string* why,
                    uint64_t targetTixels, std::vector<VisibilityEntry>* decodedOut, bool streamed) {
  auto reason = [&](std::string text) {
    if (why) *why = std::move(text);
    return false;
  };
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) return reason(fmt::format("{} does not exist", path));
  const auto file = std::make_shared<const MappedFile>(path);
  const std::span<const unsigned char> bytes = file->bytes();
  const PlvHeader h = readPlvHeader(path, bytes);
  // An older field is not an error: it is traced again, as a stale one is.
  if (h.version < kPlvVersion)
    return reason(fmt::format("{} has the older format version {} (this program writes version {})", path, h.version,
                              kPlvVersion));
  if (h.hash != expectedHash)
    return reason(fmt::format("{} was traced for different geometry, parameterisation or settings (hash {:016x}, expected {:016x})",
                              path, h.hash, expectedHash));
  const PlvLayout layout = readPlvLayout(path, bytes, h);
  const uint64_t tixelCount = h.tixelCount, extraCount = h.extraCount, blocks = layout.blocks, perBlock = layout.perBlock;
  const uint64_t n = uint64_t(h.gridSide) * h.gridSide;
  const std::vector<uint64_t>& frameSizes = layout.frameSizes;
  const std::vector<uint64_t>& contentSizes = layout.contentSizes;
  const std::vector<uint64_t>& frameOffset = layout.frameOffset;
  const std::vector<uint64_t>& blockEntryStart = layout.blockEntryStart;
  const uint64_t entryBytesTotal = blockEntryStart[blocks];
  // Streamed: the entries stay in the file; only the extra records and their offsets are held.
  const uint64_t keptEntryBytes = streamed ? 0 : entryBytesTotal;
  requireMemory(heldBytes(h, keptEntryBytes) - (streamed ? (tixelCount + 1) * sizeof(uint64_t) : 0),
                fmt::format("{}: the visibility field", path), "bake at a coarser --preset");

  std::vector<unsigned char> entryBytes;
  std::vector<uint64_t> entryOffset;
  if (!streamed) {
    entryBytes.reserve(entryBytesTotal + kEntryBytesPadding);
    adviseHugePages(entryBytes.data(), entryBytesTotal + kEntryBytesPadding);
    entryBytes.resize(entryBytesTotal + kEntryBytesPadding);
    entryOffset.assign(tixelCount + 1, 0);
    entryOffset[tixelCount] = entryBytesTotal;
  }
  std::vector<uint64_t> flaggedPerTixel(tixelCount);
  const uint64_t targets = targetTixels > 0 ? targetTixels : tixelCount;
  if (decodedOut) decodedOut->resize(tixelCount * n);
  // Blocks decode independently, in parallel; every tixel's encoding is decoded once, checked,
  // so that the gather may decode it unchecked and index without bounds checks.
  parallelFor(blocks, [&](uint64_t b) {
    const uint64_t t0 = b * perBlock, t1 = std::min(tixelCount, t0 + perBlock);
    const std::string context = fmt::format("{}: visibility block {}", path, b);
    std::vector<unsigned char> streams;
    std::vector<VisibilityEntry> scratch(decodedOut ? 0 : (t1 - t0) * n);
    VisibilityEntry* const decoded = decodedOut ? decodedOut->data() + t0 * n : scratch.data();
    const uint32_t bits = decodeEntryBlock(bytes.subspan(frameOffset[b], frameSizes[b]), t1 - t0, uint32_t(n), streams,
                                           decoded, context);
    // Held: each tixel's compact encoding, into the block's part of the field's entry bytes,
    // whose size the table declares.
    const uint64_t encodedBytes = contentSizes[b] - (t1 - t0) * sizeof(uint32_t);
    std::vector<unsigned char> encoding(streamed ? 0 : maxEncodedTixelBytes(uint32_t(n)));
    uint64_t used = 0;
    for (uint64_t g = t0; g < t1; ++g) {
      const VisibilityEntry* const entries = decoded + (g - t0) * n;
      if (!streamed) {
        const size_t size = encodeTixelEntries(entries, uint32_t(n), bits, encoding.data());
        if (size > encodedBytes - used)
          fail("{}: corrupt visibility field: block {} holds more than the {} bytes its table declares", path, b, encodedBytes);
        std::memcpy(entryBytes.data() + blockEntryStart[b] + used, encoding.data(), size);
        entryOffset[g] = blockEntryStart[b] + used;
        used += size;
      }
      uint64_t flagged = 0;
      for (uint64_t k = 0; k < n; ++k) {
        const VisibilityEntry& e = entries[k];
        if (!e.escaped() && e.tixel() >= targets) fail("{}: an entry of tixel {} points outside the field", path, g);
        flagged += e.hasExtra() ? 1 : 0;
      }
      flaggedPerTixel[g] = flagged;
    }
    if (!streamed && used != encodedBytes)
      fail("{}: corrupt visibility field: block {} holds {} bytes, its table declares {}", path, b, used, encodedBytes);
  });
  std::vector<uint64_t> extraOffset(tixelCount + 1);
  std::vector<VisibilityExtra> extras(extraCount);
  std::vector<unsigned char> raw(contentSizes[blocks]);
  detail::zstdDecompressInto(bytes.subspan(frameOffset[blocks], frameSizes[blocks]), raw,
                             fmt::format("{}: visibility extra records", path));
  std::memcpy(extraOffset.data(), raw.data(), extraOffset.size() * sizeof(uint64_t));
  if (extraCount > 0)
    std::memcpy(extras.data(), raw.data() + extraOffset.size() * sizeof(uint64_t), extraCount * sizeof(VisibilityExtra));
  raw = {};
  if (extraOffset[0] != 0 || extraOffset[tixelCount] != extraCount) fail("{}: corrupt extra-record offsets", path);
  for (uint64_t g = 0; g < tixelCount; ++g)
    if (extraOffset[g + 1] < extraOffset[g] || extraOffset[g + 1] - extraOffset[g] != flaggedPerTixel[g])
      fail("{}: corrupt extra-record offsets at tixel {}", path, g);
  // The records' contents, as computeVisibility writes them: a throughput is a product of
  // mirror reflectances (each channel in [0, 1]); st is a paraboloid coordinate (unit disk) or
  // an octahedral one ([−1, 1]²), so both components lie in [−1, 1] (kStSlack: float rounding
  // of x / r and x / (1 + z)); viaMirror is 0 or 1. Anything else — NaN, 1e9 — would flow
  // unchecked into every propagated value.
  constexpr float kStSlack = 1e-4f;
  for (uint64_t i = 0; i < extraCount; ++i) {
    const VisibilityExtra& x = extras[i];
    for (int c = 0; c < 3; ++c)
      if (!(x.throughput[c] >= 0.0f && x.throughput[c] <= 1.0f))
        fail("{}: extra record {} has throughput {} outside [0, 1]", path, i, x.throughput[c]);
    for (int c = 0; c < 2; ++c)
      if (!(std::abs(x.st[c]) <= 1.0f + kStSlack))
        fail("{}: extra record {} has direction coordinate {} outside [-1, 1]", path, i, x.st[c]);
    if (x.viaMirror > 1) fail("{}: extra record {} has a mirror flag of {} (0 or 1)", path, i, x.viaMirror);
  }

  VisibilityField f;
  f.gridSide = h.gridSide;
  f.tixelCount = tixelCount;
  f.hash = h.hash;
  if (streamed) {
    VisibilityFrames frames{perBlock,     blocks,     {frameOffset.begin(), frameOffset.begin() + int64_t(blocks) + 1},
                            frameSizes,   contentSizes, tixelCount, uint32_t(n)};
    f.stream = std::make_shared<const VisibilityBlockFile>(path, std::move(frames));
  } else {
    f.entryBytes = FieldArray<unsigned char>(std::move(entryBytes));
    f.entryOffset = FieldArray<uint64_t>(std::move(entryOffset));
  }
  f.extraOffset = FieldArray<uint64_t>(std::move(extraOffset));
  f.extras = FieldArray<VisibilityExtra>(std::move(extras));
  field = std::move(f);
  return true;
}

}  // namespace pl
