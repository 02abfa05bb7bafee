// EXT_meshopt_compression and KHR_meshopt_compression through libmeshoptimizer
// (gltf_compression.h); the only file that includes it. Without PLENOPTIC_HAVE_MESHOPT
// (libmeshoptimizer-dev absent at configure time) the decoder refuses, naming the file and
// buffer view.
#include "core/error.h"
#include "scene/gltf_compression.h"

#if PLENOPTIC_HAVE_MESHOPT
#include <meshoptimizer.h>
#endif

namespace pl::detail {

#if PLENOPTIC_HAVE_MESHOPT

bool meshoptSupported() { return true; }

/// The library's version as people write it (MESHOPTIMIZER_VERSION 180 is 0.18).
const std::string kLibraryVersion = fmt::format("{}.{}", MESHOPTIMIZER_VERSION / 1000, MESHOPTIMIZER_VERSION % 1000 / 10);

std::vector<unsigned char> decodeMeshopt(std::span<const unsigned char> bytes, const MeshoptView& view,
                                         const std::string& label) {
  const std::string& ext = view.extension;
  const bool khr = ext == "KHR_meshopt_compression";
  // The extensions' limits: a vertex stride is a multiple of 4 up to 256, an index 2 or 4 bytes.
  const bool attributes = view.mode == "ATTRIBUTES", triangles = view.mode == "TRIANGLES",
             indices = view.mode == "INDICES";
  if (!attributes && !triangles && !indices) fail("{}: unknown {} mode '{}'", label, ext, view.mode);
  if (attributes ? (view.byteStride == 0 || view.byteStride % 4 != 0 || view.byteStride > 256)
                 : (view.byteStride != 2 && view.byteStride != 4))
    fail("{}: {} byteStride {} is invalid for mode {}", label, ext, view.byteStride, view.mode);
  if (triangles && view.count % 3 != 0) fail("{}: {} TRIANGLES count {} is not a multiple of 3", label, ext, view.count);
  const bool knownFilter = view.filter == "NONE" || view.filter.empty() || view.filter == "OCTAHEDRAL" ||
                           view.filter == "QUATERNION" || view.filter == "EXPONENTIAL" || (khr && view.filter == "COLOR");
  if (!knownFilter) fail("{}: unknown {} filter '{}'", label, ext, view.filter);
  const bool filtered = view.filter != "NONE" && !view.filter.empty();
  if (filtered && !attributes) fail("{}: {} filter {} needs mode ATTRIBUTES", label, ext, view.filter);
  if (view.filter == "COLOR") {
    if (view.byteStride != 4 && view.byteStride != 8) fail("{}: COLOR filter needs byteStride 4 or 8", label);
    if (MESHOPTIMIZER_VERSION < 250)
      fail("{}: {} filter COLOR is not supported: this build's meshoptimizer {} predates it (0.25 or newer decodes it)",
           label, ext, kLibraryVersion);
  }
  // Attribute data starts with its codec version: 0xa0 (version 0, both extensions) or, in
  // KHR_meshopt_compression only, 0xa1 (version 1, decoded by meshoptimizer 0.23 and newer).
  if (attributes && !bytes.empty()) {
    const unsigned header = bytes[0];
    if (header == 0xa1 && !khr) fail("{}: attribute codec version 1 (header 0xa1) is KHR_meshopt_compression's, not {}'s", label, ext);
    if (header == 0xa1 && MESHOPTIMIZER_VERSION < 230)
      fail("{}: {} attribute codec version 1 (header 0xa1) is not supported: this build's meshoptimizer {} decodes "
           "version 0 only (0.23 or newer decodes both)", label, ext, kLibraryVersion);
  }
  // Every element takes at least one encoded byte, which bounds the allocation by the input.
  if (view.count > bytes.size() * 64 + 64) fail("{}: {} count {} is larger than its data can hold", label, ext, view.count);
  std::vector<unsigned char> out(view.count * view.byteStride);
  const int status = attributes ? meshopt_decodeVertexBuffer(out.data(), view.count, view.byteStride, bytes.data(), bytes.size())
                     : triangles ? meshopt_decodeIndexBuffer(out.data(), view.count, view.byteStride, bytes.data(), bytes.size())
                                 : meshopt_decodeIndexSequence(out.data(), view.count, view.byteStride, bytes.data(), bytes.size());
  if (status != 0) fail("{}: the {} data does not decode (error {})", label, ext, status);
  if (view.filter == "OCTAHEDRAL") {
    if (view.byteStride != 4 && view.byteStride != 8) fail("{}: OCTAHEDRAL filter needs byteStride 4 or 8", label);
    meshopt_decodeFilterOct(out.data(), view.count, view.byteStride);
  } else if (view.filter == "QUATERNION") {
    if (view.byteStride != 8) fail("{}: QUATERNION filter needs byteStride 8", label);
    meshopt_decodeFilterQuat(out.data(), view.count, view.byteStride);
  } else if (view.filter == "EXPONENTIAL") {
    meshopt_decodeFilterExp(out.data(), view.count, view.byteStride);
  } else if (view.filter == "COLOR") {
#if MESHOPTIMIZER_VERSION >= 250
    meshopt_decodeFilterColor(out.data(), view.count, view.byteStride);
#endif
  }
  return out;
}

#else

bool meshoptSupported() { return false; }

std::vector<unsigned char> decodeMeshopt(std::span<const unsigned char>, const MeshoptView& view, const std::string& label) {
  fail("{}: {}: plenoptic was built without meshoptimizer support (install libmeshoptimizer-dev and "
       "reconfigure)", label, view.extension);
}

#endif

}  // namespace pl::detail
