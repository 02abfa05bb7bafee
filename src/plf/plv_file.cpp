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

/// The stored frame of an entry block's content, and back: the one place the entry blocks'
/// frames are made and read.
std::vector<unsigned char> compressEntryBlock(std::span<const unsigned char> content) {
  return detail::zstdCompress(content, kPlvZstdLevel);
}
void decompressEntryBlock(std::span<const unsigned char> frame, std::span<unsigned char> content, const std::string& context) {
  detail::zstdDecompressInto(frame, content, context);
}

}  // namespace

uint64_t visibilityBlockTixels(uint32_t directionsPerTixel) { return tixelsPerBlock(directionsPerTixel); }

uint64_t visibilityWriteBufferBytes(uint32_t gridSide) {
  // Per block of a batch: its compressed frame (at most the content plus zstd's small bound,
  // counted as the content twice) while a worker also holds the content; the content is at most
  // the sizes and the encoded entries, which take fewer than 8 bytes per entry.
  const uint32_t n = gridSide * gridSide;
  const uint64_t blockBytes = tixelsPerBlock(n) * (sizeof(uint32_t) + maxEncodedTixelBytes(n));
  return kWriteBatchBlocks * 3 * blockBytes;
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
                                                        std::span<const unsigned char> encoded, uint64_t* contentBytes) {
  std::vector<unsigned char> content(tixelBytes.size() * sizeof(uint32_t) + encoded.size());
  if (!tixelBytes.empty()) std::memcpy(content.data(), tixelBytes.data(), tixelBytes.size() * sizeof(uint32_t));
  if (!encoded.empty()) std::memcpy(content.data() + tixelBytes.size() * sizeof(uint32_t), encoded.data(), encoded.size());
  if (contentBytes) *contentBytes = content.size();
  return compressEntryBlock(content);
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
          &contentBytes[i]);
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

void VisibilityBlockFile::read(uint64_t b, std::vector<unsigned char>& frame, std::vector<unsigned char>& content) const {
  if (b >= frames_.blocks) fail("{}: visibility block {} of {}", path_, b, frames_.blocks);
  frame.resize(frames_.frameSizes[b]);
  for (uint64_t done = 0; done < frame.size();) {
    const ssize_t got = ::pread(fd_, frame.data() + done, frame.size() - done, off_t(frames_.frameOffset[b] + done));
    if (got < 0 && errno == EINTR) continue;
    if (got <= 0)
      fail("{}: cannot read visibility block {}: {}", path_, b, got < 0 ? std::strerror(errno) : "the file is truncated");
    done += uint64_t(got);
  }
  const uint64_t size = frames_.contentSizes[b];
  content.resize(size + kEntryBytesPadding);
  std::memset(content.data() + size, 0, kEntryBytesPadding);
  decompressEntryBlock(frame, {content.data(), size}, fmt::format("{}: visibility block {}", path_, b));
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
    detail::zstdCheckFrame(bytes.subspan(l.frameOffset[b], frameSizes[b]), contentSizes[b],
                           fmt::format("{}: visibility frame {}", path, b));
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
    if (l.blocks > 0) {  // the first tixel's precision, from the first block (the bake writes one for all)
      std::vector<unsigned char> raw(l.contentSizes[0]);
      decompressEntryBlock(bytes.subspan(l.frameOffset[0], l.frameSizes[0]), raw, fmt::format("{}: visibility block 0", path));
      info.fractionBits = raw[std::min(h.tixelCount, l.perBlock) * sizeof(uint32_t)];
    }
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
    std::vector<unsigned char> raw(contentSizes[b]);
    decompressEntryBlock(bytes.subspan(frameOffset[b], frameSizes[b]), raw, fmt::format("{}: visibility block {}", path, b));
    const unsigned char* encoded = raw.data() + (t1 - t0) * sizeof(uint32_t);
    const uint64_t encodedBytes = raw.size() - (t1 - t0) * sizeof(uint32_t);
    if (!streamed) std::memcpy(entryBytes.data() + blockEntryStart[b], encoded, encodedBytes);
    std::vector<VisibilityEntry> scratch(decodedOut ? 0 : n);
    uint64_t used = 0;
    for (uint64_t g = t0; g < t1; ++g) {
      uint32_t size;
      std::memcpy(&size, raw.data() + (g - t0) * sizeof(uint32_t), sizeof(uint32_t));
      const std::span<VisibilityEntry> decoded(decodedOut ? decodedOut->data() + g * n : scratch.data(), n);
      if (size > encodedBytes - used ||
          decodeTixelEntries<true>(encoded + used, size, uint32_t(n), decoded.data()) != size)
        fail("{}: corrupt visibility field: the entries of tixel {} do not decode", path, g);
      if (!streamed) entryOffset[g] = blockEntryStart[b] + used;
      used += size;
      uint64_t flagged = 0;
      for (const VisibilityEntry& e : decoded) {
        if (!e.escaped() && e.tixel() >= targets) fail("{}: an entry of tixel {} points outside the field", path, g);
        flagged += e.hasExtra() ? 1 : 0;
      }
      flaggedPerTixel[g] = flagged;
    }
    if (used != encodedBytes)
      fail("{}: corrupt visibility field: block {} holds {} bytes past its tixels", path, b, encodedBytes - used);
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
    VisibilityFrames frames{perBlock, blocks, {frameOffset.begin(), frameOffset.begin() + int64_t(blocks) + 1}, frameSizes,
                            contentSizes};
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
