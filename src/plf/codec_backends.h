#pragma once
// Private to the light-field module: the two third-party codecs used by compression.cpp (and
// zstd by the .plv file, plv_file.cpp), each behind one .cpp file (codec_zstd.cpp: libzstd; codec_bc1.cpp: libsquish).
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace pl::detail {

/// One zstd frame of `input` at `level`, with its content size and the frame's XXH64-based
/// content checksum (so a corrupted payload is detected by zstd itself, not only by the
/// section checksum of the .plf file).
std::vector<unsigned char> zstdCompress(std::span<const unsigned char> input, int level);

/// Decodes `frame`, which must be exactly one complete zstd frame whose content is
/// `expectedSize` bytes; anything else (a frame error, a checksum mismatch, a different
/// size, trailing bytes) throws pl::Error starting with `context`.
std::vector<unsigned char> zstdDecompress(std::span<const unsigned char> frame, uint64_t expectedSize,
                                          const std::string& context);
/// Checks, without decoding, that `frame` is exactly one zstd frame declaring `expectedSize`
/// content bytes (so a reader can refuse a lying layout before allocating for it).
void zstdCheckFrame(std::span<const unsigned char> frame, uint64_t expectedSize, const std::string& context);
/// The same into `output`, whose size is the expected content size (no allocation).
void zstdDecompressInto(std::span<const unsigned char> frame, std::span<unsigned char> output,
                        const std::string& context);

/// BC1 (S3TC DXT1) of one 4×4 block of 8-bit RGB texels, row-major (texel x + 4·y);
/// texels whose bit (x + 4·y) is clear in `validMask` are padding and do not influence
/// the endpoints. Writes 8 bytes. Uses libsquish's iterative cluster fit with a uniform
/// colour metric (every channel counts equally, as in an RGB PSNR).
void bc1EncodeBlock(const unsigned char (&rgb)[16][3], int validMask, unsigned char* block);

/// Decodes 8 BC1 bytes into 16 RGB texels (row-major).
void bc1DecodeBlock(const unsigned char* block, unsigned char (&rgb)[16][3]);

}  // namespace pl::detail
