// libzstd behind one file (see codec_backends.h).
#include <zstd.h>

#include <memory>

#include "core/error.h"
#include "plf/codec_backends.h"

namespace pl::detail {

namespace {
// One compression and one decompression context per thread, kept: creating one takes longer
// than compressing or decompressing a small frame (the .plv's entry blocks are six frames of a
// few KiB to 64 KiB each).
ZSTD_CCtx* threadCompressionContext() {
  thread_local const std::unique_ptr<ZSTD_CCtx, size_t (*)(ZSTD_CCtx*)> context(ZSTD_createCCtx(), ZSTD_freeCCtx);
  if (!context) fail("zstd: cannot create a compression context (out of memory)");
  return context.get();
}
ZSTD_DCtx* threadDecompressionContext() {
  thread_local const std::unique_ptr<ZSTD_DCtx, size_t (*)(ZSTD_DCtx*)> context(ZSTD_createDCtx(), ZSTD_freeDCtx);
  if (!context) fail("zstd: cannot create a decompression context (out of memory)");
  return context.get();
}
}  // namespace

std::vector<unsigned char> zstdCompress(std::span<const unsigned char> input, int level) {
  ZSTD_CCtx* const context = threadCompressionContext();
  auto check = [](size_t code) {
    if (ZSTD_isError(code)) fail("zstd compression failed: {}", ZSTD_getErrorName(code));
    return code;
  };
  check(ZSTD_CCtx_reset(context, ZSTD_reset_session_and_parameters));
  check(ZSTD_CCtx_setParameter(context, ZSTD_c_compressionLevel, level));
  check(ZSTD_CCtx_setParameter(context, ZSTD_c_checksumFlag, 1));
  check(ZSTD_CCtx_setParameter(context, ZSTD_c_contentSizeFlag, 1));
  std::vector<unsigned char> frame(ZSTD_compressBound(input.size()));
  const size_t size = check(ZSTD_compress2(context, frame.data(), frame.size(), input.data(), input.size()));
  frame.resize(size);
  return frame;
}

void zstdCheckFrame(std::span<const unsigned char> frame, uint64_t expectedSize, const std::string& context) {
  const size_t frameSize = ZSTD_findFrameCompressedSize(frame.data(), frame.size());
  if (ZSTD_isError(frameSize))
    fail("{}: corrupt zstd frame: {}", context, ZSTD_getErrorName(frameSize));
  if (frameSize != frame.size())
    fail("{}: {} unexpected bytes after the zstd frame", context, frame.size() - frameSize);
  const unsigned long long contentSize = ZSTD_getFrameContentSize(frame.data(), frame.size());
  if (contentSize == ZSTD_CONTENTSIZE_ERROR || contentSize == ZSTD_CONTENTSIZE_UNKNOWN)
    fail("{}: corrupt zstd frame: no valid content size", context);
  if (contentSize != expectedSize)
    fail("{}: the zstd frame holds {} bytes but the layout needs {}", context, contentSize, expectedSize);
}

namespace {
void decompressChecked(std::span<const unsigned char> frame, std::span<unsigned char> output,
                       const std::string& context) {
  const size_t size = ZSTD_decompressDCtx(threadDecompressionContext(), output.data(), output.size(), frame.data(), frame.size());
  if (ZSTD_isError(size)) fail("{}: corrupt zstd frame: {}", context, ZSTD_getErrorName(size));
  if (size != output.size())
    fail("{}: the zstd frame decoded to {} bytes but the layout needs {}", context, size, output.size());
}
}  // namespace

void zstdDecompressInto(std::span<const unsigned char> frame, std::span<unsigned char> output,
                        const std::string& context) {
  zstdCheckFrame(frame, output.size(), context);
  decompressChecked(frame, output, context);
}

std::vector<unsigned char> zstdDecompress(std::span<const unsigned char> frame, uint64_t expectedSize,
                                          const std::string& context) {
  zstdCheckFrame(frame, expectedSize, context);
  std::vector<unsigned char> output(expectedSize);
  decompressChecked(frame, output, context);
  return output;
}

}  // namespace pl::detail
