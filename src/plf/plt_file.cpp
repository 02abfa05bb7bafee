// The tixel-setup file (see plt_file.h).
#include "plf/plt_file.h"

#include <algorithm>
#include <cstring>
#include <limits>
#include <filesystem>
#include <string_view>

#include "core/byte_writer.h"
#include "core/error.h"
#include "core/file_io.h"
#include "core/hash.h"
#include "core/memory.h"
#include "core/parallel.h"
#include "plf/codec_backends.h"

namespace pl {

namespace {

constexpr char kPltMagic[8] = {'P', 'L', 'T', 'I', 'X', '\0', '\r', '\n'};
constexpr size_t kPltHeaderBytes = 48, kPltEntryBytes = 32;
/// zstd level of the arrays: float arrays gain little from higher levels.
constexpr int kPltZstdLevel = 3;

template <typename T>
T load(const unsigned char* at) {
  T value;
  std::memcpy(&value, at, sizeof(T));
  return value;
}

std::string tagName(const std::array<char, 4>& tag) {
  std::string name;
  for (char c : tag) name += (c >= 0x20 && c < 0x7f) ? c : '?';
  return name;
}

}  // namespace

void writeTixelSetupFile(const std::string& path, uint64_t hash, uint64_t tixelCount,
                         std::span<const TixelSetupView> arrays, std::span<const uint64_t> keys) {
  if (keys.size() > kMaxTixelSetupKeys) fail("{}: {} tixel-setup keys (at most {})", path, keys.size(), kMaxTixelSetupKeys);
  if (arrays.size() > kMaxTixelSetupArrays) fail("{}: {} tixel-setup arrays (at most {})", path, arrays.size(), kMaxTixelSetupArrays);
  for (const TixelSetupView& a : arrays)
    if ((a.count != 0 && a.count != tixelCount) || a.elementBytes == 0 || a.elementBytes > kMaxTixelSetupElementBytes)
      fail("{}: tixel-setup array {} has {} elements of {} bytes (expected 0 or {} of 1 to {} bytes)", path,
           tagName(a.tag), a.count, a.elementBytes, tixelCount, kMaxTixelSetupElementBytes);
  std::vector<std::vector<unsigned char>> frames(arrays.size());
  parallelFor(arrays.size(), [&](uint64_t i) {
    const TixelSetupView& a = arrays[i];
    if (a.count > 0)
      frames[i] = detail::zstdCompress({static_cast<const unsigned char*>(a.data), a.count * a.elementBytes}, kPltZstdLevel);
  });
  std::vector<unsigned char> payload;
  for (size_t i = 0; i < arrays.size(); ++i) {
    appendBytes(payload, arrays[i].tag.data(), 4);
    appendValue(payload, arrays[i].elementBytes);
    appendValue(payload, arrays[i].count);
    appendValue(payload, uint64_t(frames[i].size()));
    appendValue(payload, uint64_t(0));
  }
  for (uint64_t key : keys) appendValue(payload, key);
  for (std::vector<unsigned char>& frame : frames) {
    appendBytes(payload, frame.data(), frame.size());
    std::vector<unsigned char>().swap(frame);
  }
  std::vector<unsigned char> file;
  file.reserve(kPltHeaderBytes + payload.size());
  appendBytes(file, kPltMagic, 8);
  appendValue(file, kPltVersion);
  appendValue(file, uint32_t(arrays.size()));
  appendValue(file, hash);
  appendValue(file, tixelCount);
  appendValue(file, xxh64(payload.data(), payload.size()));
  appendValue(file, uint64_t(keys.size()));
  appendBytes(file, payload.data(), payload.size());
  writeFileAtomically(path, std::string_view(reinterpret_cast<const char*>(file.data()), file.size()));
}

bool readTixelSetupFile(const std::string& path, uint64_t expectedHash, TixelSetupFile& out, std::string* why) {
  auto reason = [&](std::string text) {
    if (why) *why = std::move(text);
    return false;
  };
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) return reason(fmt::format("{} does not exist", path));
  requireRegularFile(path);
  const MappedFile file(path);
  const std::span<const unsigned char> bytes = file.bytes();
  if (bytes.size() < kPltHeaderBytes)
    fail("{}: truncated tixel-setup file ({} bytes, the header needs {})", path, bytes.size(), kPltHeaderBytes);
  if (std::memcmp(bytes.data(), kPltMagic, 8) != 0) fail("{}: not a plenoptic tixel-setup file (bad magic)", path);
  const uint32_t version = load<uint32_t>(bytes.data() + 8);
  if (version < kPltOldestVersion || version > kPltVersion)
    return reason(fmt::format("{} has format version {} (this program reads versions {} to {})", path, version,
                              kPltOldestVersion, kPltVersion));
  const uint32_t arrayCount = load<uint32_t>(bytes.data() + 12);
  const uint64_t hash = load<uint64_t>(bytes.data() + 16), tixelCount = load<uint64_t>(bytes.data() + 24);
  if (hash != expectedHash)
    return reason(fmt::format("{} belongs to another bake (hash {:016x}, expected {:016x})", path, hash, expectedHash));
  const std::span<const unsigned char> payload = bytes.subspan(kPltHeaderBytes);
  if (xxh64(payload.data(), payload.size()) != load<uint64_t>(bytes.data() + 32))
    fail("{}: corrupt tixel-setup file: the payload checksum does not match", path);
  if (arrayCount > kMaxTixelSetupArrays || uint64_t(arrayCount) * kPltEntryBytes > payload.size())
    fail("{}: corrupt tixel-setup file: {} arrays declared, at most {} fit", path, arrayCount,
         std::min<uint64_t>(kMaxTixelSetupArrays, payload.size() / kPltEntryBytes));
  const uint64_t keyCount = load<uint64_t>(bytes.data() + 40);
  const uint64_t tableBytes = uint64_t(arrayCount) * kPltEntryBytes;
  if (keyCount > kMaxTixelSetupKeys || keyCount * sizeof(uint64_t) > payload.size() - tableBytes)
    fail("{}: corrupt tixel-setup file: {} keys declared, at most {} fit", path, keyCount,
         std::min<uint64_t>(kMaxTixelSetupKeys, (payload.size() - tableBytes) / sizeof(uint64_t)));
  // The table, every count and frame size checked before anything is allocated.
  TixelSetupFile result;
  result.hash = hash;
  result.tixelCount = tixelCount;
  result.arrays.resize(arrayCount);
  result.keys.resize(keyCount);
  if (keyCount > 0) std::memcpy(result.keys.data(), payload.data() + tableBytes, keyCount * sizeof(uint64_t));
  std::vector<uint64_t> frameOffset(arrayCount + 1, tableBytes + keyCount * sizeof(uint64_t)), frameSize(arrayCount);
  uint64_t decodedBytes = 0;
  for (uint32_t i = 0; i < arrayCount; ++i) {
    const unsigned char* entry = payload.data() + uint64_t(i) * kPltEntryBytes;
    TixelSetupArray& a = result.arrays[i];
    std::memcpy(a.tag.data(), entry, 4);
    a.elementBytes = load<uint32_t>(entry + 4);
    a.count = load<uint64_t>(entry + 8);
    frameSize[i] = load<uint64_t>(entry + 16);
    const std::string name = tagName(a.tag);
    if (a.elementBytes == 0 || a.elementBytes > kMaxTixelSetupElementBytes)
      fail("{}: corrupt tixel-setup file: array {} has elements of {} bytes (1 to {})", path, name, a.elementBytes,
           kMaxTixelSetupElementBytes);
    if (a.count != 0 && a.count != tixelCount)
      fail("{}: corrupt tixel-setup file: array {} has {} elements, not 0 or the {} tixels", path, name, a.count, tixelCount);
    if ((a.count == 0) != (frameSize[i] == 0) || load<uint64_t>(entry + 24) != 0)
      fail("{}: corrupt tixel-setup file: array {}'s table entry is inconsistent", path, name);
    if (frameSize[i] > payload.size() - frameOffset[i])
      fail("{}: corrupt tixel-setup file: array {}'s frame of {} bytes runs past the end of the file", path, name,
           frameSize[i]);
    frameOffset[i + 1] = frameOffset[i] + frameSize[i];
    if (a.count > std::numeric_limits<uint64_t>::max() / 2 / a.elementBytes)
      fail("{}: corrupt tixel-setup file: array {} is too large", path, name);
    decodedBytes += a.count * a.elementBytes;
    if (a.count > 0)
      detail::zstdCheckFrame(payload.subspan(frameOffset[i], frameSize[i]), a.count * a.elementBytes,
                             fmt::format("{}: corrupt tixel-setup file: array {}", path, name));
  }
  if (frameOffset[arrayCount] != payload.size())
    fail("{}: corrupt tixel-setup file: {} unexpected bytes after the last array", path,
         payload.size() - frameOffset[arrayCount]);
  requireMemory(decodedBytes, fmt::format("{}: the tixel setup", path), "bake at a coarser --preset");
  for (TixelSetupArray& a : result.arrays) a.bytes.resize(a.count * a.elementBytes);
  parallelFor(arrayCount, [&](uint64_t i) {
    TixelSetupArray& a = result.arrays[i];
    if (a.count > 0)
      detail::zstdDecompressInto(payload.subspan(frameOffset[i], frameSize[i]), a.bytes,
                                 fmt::format("{}: corrupt tixel-setup file: array {}", path, tagName(a.tag)));
  });
  out = std::move(result);
  return true;
}

}  // namespace pl
