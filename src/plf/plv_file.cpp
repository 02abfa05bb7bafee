// The .plv visibility-field file (layout in plv_file.h).
#include "plf/plv_file.h"

#include <algorithm>
#include <cstring>
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

/// An entry block's frame content (see the layout in plv_file.h): the block's tixels' encoded
/// sizes (u32 each), then their encodings. Its bytes, for tixels [t0, t1).
uint64_t blockContentBytes(const VisibilityField& field, uint64_t t0, uint64_t t1) {
  return (t1 - t0) * sizeof(uint32_t) + field.entryOffset[t1] - field.entryOffset[t0];
}

}  // namespace

uint64_t visibilityWriteBufferBytes(uint32_t gridSide) {
  // Per block of a batch: its compressed frame (at most the content plus zstd's small bound,
  // counted as the content twice) while a worker also holds the content; the content is at most
  // the sizes and the encoded entries, which take fewer than 8 bytes per entry.
  const uint32_t n = gridSide * gridSide;
  const uint64_t blockBytes = tixelsPerBlock(n) * (sizeof(uint32_t) + maxEncodedTixelBytes(n));
  return kWriteBatchBlocks * 3 * blockBytes;
}

void writeVisibility(const std::string& path, const VisibilityField& field) {
  const uint64_t n = field.directionsPerTixel();
  const uint64_t perBlock = tixelsPerBlock(uint32_t(n));
  const uint64_t blocks = (field.tixelCount + perBlock - 1) / perBlock;
  const uint64_t entryCount = field.entryCount(), extraCount = field.extras.size();

  writeFileAtomically(path, [&](const std::string& temp) {
    std::ofstream out(temp, std::ios::binary | std::ios::trunc);
    if (!out) fail("cannot create the temporary file {}", temp);
    Xxh64Stream payloadHash;
    auto put = [&](const void* data, size_t size) { out.write(static_cast<const char*>(data), std::streamsize(size)); };
    auto putPayload = [&](const void* data, size_t size) {
      put(data, size);
      payloadHash.update(data, size);
    };
    const uint64_t placeholder = 0;
    put(kPlvMagic, 8);
    put(&kPlvVersion, 4);
    put(&field.gridSide, 4);
    put(&field.hash, 8);
    put(&field.tixelCount, 8);
    put(&entryCount, 8);
    put(&extraCount, 8);
    put(&placeholder, 8);  // the payload hash, written last
    putPayload(&perBlock, 8);

    // Entry blocks compressed a batch at a time in parallel, written in order: memory stays
    // bounded by one batch of frames whatever the field's size.
    std::vector<uint64_t> frameSizes, contentSizes;
    frameSizes.reserve(blocks + 1);
    contentSizes.reserve(blocks + 1);
    const uint64_t batch = kWriteBatchBlocks;
    std::vector<std::vector<unsigned char>> frames(batch);
    Progress progress("visibility: writing", blocks);
    for (uint64_t b0 = 0; b0 < blocks; b0 += batch) {
      const uint64_t b1 = std::min(blocks, b0 + batch);
      parallelFor(b1 - b0, [&](uint64_t i) {
        const uint64_t t0 = (b0 + i) * perBlock, t1 = std::min(field.tixelCount, t0 + perBlock);
        std::vector<unsigned char> raw(blockContentBytes(field, t0, t1));
        for (uint64_t t = t0; t < t1; ++t) {
          const uint32_t size = uint32_t(field.entryOffset[t + 1] - field.entryOffset[t]);
          std::memcpy(raw.data() + (t - t0) * sizeof(uint32_t), &size, sizeof(uint32_t));
        }
        std::memcpy(raw.data() + (t1 - t0) * sizeof(uint32_t), field.entryBytes.data() + field.entryOffset[t0],
                    field.entryOffset[t1] - field.entryOffset[t0]);
        frames[i] = detail::zstdCompress(raw, kPlvZstdLevel);
      });
      for (uint64_t i = 0; i < b1 - b0; ++i) {
        const uint64_t t0 = (b0 + i) * perBlock, t1 = std::min(field.tixelCount, t0 + perBlock);
        putPayload(frames[i].data(), frames[i].size());
        frameSizes.push_back(frames[i].size());
        contentSizes.push_back(blockContentBytes(field, t0, t1));
      }
      progress.advance(b1 - b0);
    }
    // The extra records' frame: offsets, then records.
    std::vector<unsigned char> tail(field.extraOffset.size() * sizeof(uint64_t) + extraCount * sizeof(VisibilityExtra));
    if (!field.extraOffset.empty()) std::memcpy(tail.data(), field.extraOffset.data(), field.extraOffset.size() * sizeof(uint64_t));
    if (extraCount > 0)
      std::memcpy(tail.data() + field.extraOffset.size() * sizeof(uint64_t), field.extras.data(),
                  extraCount * sizeof(VisibilityExtra));
    const std::vector<unsigned char> tailFrame = detail::zstdCompress(tail, kPlvZstdLevel);
    putPayload(tailFrame.data(), tailFrame.size());
    frameSizes.push_back(tailFrame.size());
    contentSizes.push_back(tail.size());
    putPayload(frameSizes.data(), frameSizes.size() * sizeof(uint64_t));
    putPayload(contentSizes.data(), contentSizes.size() * sizeof(uint64_t));
    const uint64_t digest = payloadHash.digest();
    out.seekp(kPlvHeaderSize - 8);
    put(&digest, 8);
    out.flush();
    if (!out) fail("write failed (disk full?)");
  });
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
      detail::zstdDecompressInto(bytes.subspan(l.frameOffset[0], l.frameSizes[0]), raw, fmt::format("{}: visibility block 0", path));
      info.fractionBits = raw[std::min(h.tixelCount, l.perBlock) * sizeof(uint32_t)];
    }
  }
  return info;
}

bool readVisibility(const std::string& path, uint64_t expectedHash, VisibilityField& field, std::string* why,
                    uint64_t targetTixels, std::vector<VisibilityEntry>* decodedOut) {
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
  requireMemory(heldBytes(h, entryBytesTotal), fmt::format("{}: the visibility field", path), "bake at a coarser --preset");

  std::vector<unsigned char> entryBytes;
  entryBytes.reserve(entryBytesTotal + kEntryBytesPadding);
  adviseHugePages(entryBytes.data(), entryBytesTotal + kEntryBytesPadding);
  entryBytes.resize(entryBytesTotal + kEntryBytesPadding);
  std::vector<uint64_t> entryOffset(tixelCount + 1, 0);
  entryOffset[tixelCount] = entryBytesTotal;
  std::vector<uint64_t> flaggedPerTixel(tixelCount);
  const uint64_t targets = targetTixels > 0 ? targetTixels : tixelCount;
  if (decodedOut) decodedOut->resize(tixelCount * n);
  // Blocks decode independently, in parallel; every tixel's encoding is decoded once, checked,
  // so that the gather may decode it unchecked and index without bounds checks.
  parallelFor(blocks, [&](uint64_t b) {
    const uint64_t t0 = b * perBlock, t1 = std::min(tixelCount, t0 + perBlock);
    std::vector<unsigned char> raw(contentSizes[b]);
    detail::zstdDecompressInto(bytes.subspan(frameOffset[b], frameSizes[b]), raw,
                               fmt::format("{}: visibility block {}", path, b));
    const unsigned char* encoded = raw.data() + (t1 - t0) * sizeof(uint32_t);
    const uint64_t encodedBytes = raw.size() - (t1 - t0) * sizeof(uint32_t);
    std::memcpy(entryBytes.data() + blockEntryStart[b], encoded, encodedBytes);
    std::vector<VisibilityEntry> scratch(decodedOut ? 0 : n);
    uint64_t used = 0;
    for (uint64_t g = t0; g < t1; ++g) {
      uint32_t size;
      std::memcpy(&size, raw.data() + (g - t0) * sizeof(uint32_t), sizeof(uint32_t));
      const std::span<VisibilityEntry> decoded(decodedOut ? decodedOut->data() + g * n : scratch.data(), n);
      if (size > encodedBytes - used ||
          decodeTixelEntries<true>(encoded + used, size, uint32_t(n), decoded.data()) != size)
        fail("{}: corrupt visibility field: the entries of tixel {} do not decode", path, g);
      entryOffset[g] = blockEntryStart[b] + used;
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
  f.entryBytes = FieldArray<unsigned char>(std::move(entryBytes));
  f.entryOffset = FieldArray<uint64_t>(std::move(entryOffset));
  f.extraOffset = FieldArray<uint64_t>(std::move(extraOffset));
  f.extras = FieldArray<VisibilityExtra>(std::move(extras));
  field = std::move(f);
  return true;
}

}  // namespace pl
