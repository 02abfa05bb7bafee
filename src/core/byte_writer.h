#pragma once
// Writing a binary format's fields into a byte buffer, as the host stores them (the formats
// are little-endian, and so is every host plenoptic targets) — the counterpart of
// core/byte_reader.h. The one writer of the .plf sections (plf/plf_file.cpp), the .plt tixel
// setup (plf/plt_file.cpp) and the resume journal and checkpoint (bake/resume.cpp).
#include <cstddef>
#include <cstdint>
#include <string>
#include <type_traits>
#include <vector>

namespace pl {

/// Appends `size` bytes at `data` to `out`.
inline void appendBytes(std::vector<unsigned char>& out, const void* data, size_t size) {
  const auto* bytes = static_cast<const unsigned char*>(data);
  out.insert(out.end(), bytes, bytes + size);
}

/// Appends one field of a trivially copyable type to `out`.
template <typename T>
void appendValue(std::vector<unsigned char>& out, const T& value) {
  static_assert(std::is_trivially_copyable_v<T>);
  appendBytes(out, &value, sizeof(T));
}

/// A byte buffer with the .plf's compound fields: strings and arrays prefixed by their length.
class ByteWriter {
 public:
  template <typename T>
  void put(const T& value) {
    appendValue(bytes_, value);
  }
  /// Its u32 length, then its bytes (ByteReader::getString reads it).
  void putString(const std::string& s) {
    put(uint32_t(s.size()));
    appendBytes(bytes_, s.data(), s.size());
  }
  /// Its u64 element count, then its elements.
  template <typename T>
  void putArray(const std::vector<T>& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    put(uint64_t(v.size()));
    appendBytes(bytes_, v.data(), v.size() * sizeof(T));
  }
  std::vector<unsigned char>& bytes() { return bytes_; }

 private:
  std::vector<unsigned char> bytes_;
};

}  // namespace pl
