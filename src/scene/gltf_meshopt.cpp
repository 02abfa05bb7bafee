// EXT_meshopt_compression through libmeshoptimizer (gltf_compression.h); the only file that
// includes it. Without PLENOPTIC_HAVE_MESHOPT (libmeshoptimizer-dev absent at configure time)
// the decoder refuses, naming the file and buffer view.
#include "core/error.h"
#include "scene/gltf_compression.h"

#if PLENOPTIC_HAVE_MESHOPT
#include <meshoptimizer.h>
#endif

namespace pl::detail {

#if PLENOPTIC_HAVE_MESHOPT

bool meshoptSupported() { return true; }

std::vector<unsigned char> decodeMeshopt(std::span<const unsigned char> bytes, const MeshoptView& view,
                                         const std::string& label) {
  // The extension's limits: a vertex stride is a multiple of 4 up to 256, an index 2 or 4 bytes.
  const bool attributes = view.mode == "ATTRIBUTES", triangles = view.mode == "TRIANGLES",
             indices = view.mode == "INDICES";
  if (!attributes && !triangles && !indices) fail("{}: unknown EXT_meshopt_compression mode '{}'", label, view.mode);
  if (attributes ? (view.byteStride == 0 || view.byteStride % 4 != 0 || view.byteStride > 256)
                 : (view.byteStride != 2 && view.byteStride != 4))
    fail("{}: EXT_meshopt_compression byteStride {} is invalid for mode {}", label, view.byteStride, view.mode);
  if (triangles && view.count % 3 != 0) fail("{}: EXT_meshopt_compression TRIANGLES count {} is not a multiple of 3", label, view.count);
  // Every element takes at least one encoded byte, which bounds the allocation by the input.
  if (view.count > bytes.size() * 64 + 64) fail("{}: EXT_meshopt_compression count {} is larger than its data can hold", label, view.count);
  std::vector<unsigned char> out(view.count * view.byteStride);
  const int status = attributes ? meshopt_decodeVertexBuffer(out.data(), view.count, view.byteStride, bytes.data(), bytes.size())
                     : triangles ? meshopt_decodeIndexBuffer(out.data(), view.count, view.byteStride, bytes.data(), bytes.size())
                                 : meshopt_decodeIndexSequence(out.data(), view.count, view.byteStride, bytes.data(), bytes.size());
  if (status != 0) fail("{}: the EXT_meshopt_compression data does not decode (error {})", label, status);
  if (view.filter == "OCTAHEDRAL" || view.filter == "QUATERNION" || view.filter == "EXPONENTIAL") {
    if (!attributes) fail("{}: EXT_meshopt_compression filter {} needs mode ATTRIBUTES", label, view.filter);
    if (view.filter == "OCTAHEDRAL") {
      if (view.byteStride != 4 && view.byteStride != 8) fail("{}: OCTAHEDRAL filter needs byteStride 4 or 8", label);
      meshopt_decodeFilterOct(out.data(), view.count, view.byteStride);
    } else if (view.filter == "QUATERNION") {
      if (view.byteStride != 8) fail("{}: QUATERNION filter needs byteStride 8", label);
      meshopt_decodeFilterQuat(out.data(), view.count, view.byteStride);
    } else {
      meshopt_decodeFilterExp(out.data(), view.count, view.byteStride);
    }
  } else if (view.filter != "NONE" && !view.filter.empty()) {
    fail("{}: unknown EXT_meshopt_compression filter '{}'", label, view.filter);
  }
  return out;
}

#else

bool meshoptSupported() { return false; }

std::vector<unsigned char> decodeMeshopt(std::span<const unsigned char>, const MeshoptView&, const std::string& label) {
  fail("{}: EXT_meshopt_compression: plenoptic was built without meshoptimizer support (install "
       "libmeshoptimizer-dev and reconfigure)", label);
}

#endif

}  // namespace pl::detail
