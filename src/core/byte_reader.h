#pragma once
// Reading a binary format's fields from bytes in memory, every size checked against the bytes
// that remain, so that a corrupt count or a truncated file is reported (pl::Error naming the
// file, what is being read and the byte offset) instead of allocating absurd amounts or reading
// past the end. The one reader of the .plf sections (plf/plf_file.cpp) and of Radiance HDR
// files (image/stb_io.cpp). Fields are copied as the host stores them (the formats that use it
// are little-endian, and so is every host plenoptic targets).
#include <cstdint>
#include <cstring>
#include <span>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "core/error.h"

namespace pl {

class ByteReader {
 public:
  /// `path` names the file and `what` the bytes in error messages: "<path>: corrupt <what> at
  /// byte <offset>: <problem>" (e.g. what = "scene section", "Radiance HDR file").
  ByteReader(std::span<const unsigned char> bytes, std::string path, std::string what)
      : bytes_(bytes), path_(std::move(path)), what_(std::move(what)) {}

  /// One field of a trivially copyable type.
  template <typename T>
  T get() {
    static_assert(std::is_trivially_copyable_v<T>);
    need(sizeof(T), "a field");
    T value;
    std::memcpy(&value, bytes_.data() + pos_, sizeof(T));
    pos_ += sizeof(T);
    return value;
  }
  /// Longest string getString accepts by default (names and paths): longer is corrupt.
  static constexpr uint32_t kMaxStringBytes = 1u << 20;

  /// A string stored as its u32 length and its bytes; longer than maxBytes is corrupt.
  std::string getString(uint32_t maxBytes = kMaxStringBytes) {
    const uint32_t length = get<uint32_t>();
    if (length > maxBytes) corrupt(fmt::format("a string of {} bytes", length));
    need(length, "a string");
    std::string s(reinterpret_cast<const char*>(bytes_.data() + pos_), length);
    pos_ += length;
    return s;
  }
  /// A u64 element count whose elements (elementBytes each) must fit in what remains.
  uint64_t getCount(uint64_t elementBytes, const char* what) {
    const uint64_t count = get<uint64_t>();
    if (elementBytes > 0 && count > remaining() / elementBytes)
      corrupt(fmt::format("{} {} of {} bytes each, but only {} bytes remain", count, what, elementBytes, remaining()));
    return count;
  }
  /// A u64 count (getCount) followed by that many elements.
  template <typename T>
  std::vector<T> getArray(const char* what) {
    const uint64_t count = getCount(sizeof(T), what);
    std::vector<T> v(count);
    if (count > 0) std::memcpy(v.data(), bytes_.data() + pos_, count * sizeof(T));  // (an empty v's data() may be null)
    pos_ += count * sizeof(T);
    return v;
  }
  /// A text line: the bytes up to the next '\n', without it; longer than maxBytes is corrupt.
  std::string getLine(size_t maxBytes) {
    std::string s;
    while (true) {
      const unsigned char c = get<unsigned char>();
      if (c == '\n') return s;
      if (s.size() >= maxBytes) corrupt(fmt::format("a line longer than {} bytes", maxBytes));
      s.push_back(char(c));
    }
  }

  uint64_t offset() const { return pos_; }
  uint64_t remaining() const { return bytes_.size() - pos_; }
  /// Corrupt unless every byte was read.
  void expectEnd() {
    if (pos_ != bytes_.size()) corrupt(fmt::format("{} unexpected bytes after the last field", remaining()));
  }
  [[noreturn]] void corrupt(const std::string& problem) const {
    fail("{}: corrupt {} at byte {}: {}", path_, what_, pos_, problem);
  }

 private:
  void need(uint64_t bytes, const char* what) {
    if (bytes > remaining()) corrupt(fmt::format("{} of {} bytes, but only {} bytes remain", what, bytes, remaining()));
  }

  std::span<const unsigned char> bytes_;
  std::string path_, what_;
  uint64_t pos_ = 0;
};

}  // namespace pl
