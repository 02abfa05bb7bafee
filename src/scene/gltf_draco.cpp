// KHR_draco_mesh_compression through libdraco (gltf_compression.h); the only file that
// includes it. Without PLENOPTIC_HAVE_DRACO (libdraco-dev absent at configure time) the
// decoder refuses, naming the file and mesh.
#include "core/error.h"
#include "scene/gltf_compression.h"

#if PLENOPTIC_HAVE_DRACO
#include <draco/compression/decode.h>
#include <draco/core/decoder_buffer.h>
#endif

namespace pl::detail {

#if PLENOPTIC_HAVE_DRACO

bool dracoSupported() { return true; }

DracoPrimitive decodeDraco(std::span<const unsigned char> bytes, const std::map<std::string, int>& attributes,
                           const std::map<std::string, int>& components, const std::string& label) {
  draco::DecoderBuffer buffer;
  buffer.Init(reinterpret_cast<const char*>(bytes.data()), bytes.size());
  const auto type = draco::Decoder::GetEncodedGeometryType(&buffer);
  if (!type.ok() || type.value() != draco::TRIANGULAR_MESH)
    fail("{}: the Draco buffer does not hold a triangle mesh{}", label,
         type.ok() ? "" : fmt::format(" ({})", type.status().error_msg_string()));
  draco::Decoder decoder;
  auto decoded = decoder.DecodeMeshFromBuffer(&buffer);
  if (!decoded.ok()) fail("{}: the Draco buffer does not decode: {}", label, decoded.status().error_msg_string());
  const draco::Mesh& mesh = *decoded.value();
  DracoPrimitive result;
  result.vertexCount = mesh.num_points();
  result.indices.reserve(size_t(mesh.num_faces()) * 3);
  for (draco::FaceIndex f(0); f < mesh.num_faces(); ++f)
    for (int k = 0; k < 3; ++k) result.indices.push_back(mesh.face(f)[k].value());
  for (const auto& [name, id] : attributes) {
    const draco::PointAttribute* attribute = mesh.GetAttributeByUniqueId(uint32_t(id));
    if (!attribute) fail("{}: the Draco buffer has no attribute {} ({})", label, id, name);
    const auto it = components.find(name);
    const int n = it == components.end() ? attribute->num_components() : it->second;
    if (n < 1 || n > 4 || attribute->num_components() < n)
      fail("{}: Draco attribute {} ({}) has {} components, expected {}", label, id, name, attribute->num_components(), n);
    std::vector<float>& values = result.attributes[name];
    values.resize(result.vertexCount * size_t(n));
    float value[4];
    for (draco::PointIndex p(0); p < mesh.num_points(); ++p) {
      if (!attribute->ConvertValue<float>(attribute->mapped_index(p), int8_t(n), value))
        fail("{}: Draco attribute {} ({}) does not convert to numbers", label, id, name);
      for (int c = 0; c < n; ++c) values[size_t(p.value()) * size_t(n) + size_t(c)] = value[c];
    }
  }
  return result;
}

#else

bool dracoSupported() { return false; }

DracoPrimitive decodeDraco(std::span<const unsigned char>, const std::map<std::string, int>&,
                           const std::map<std::string, int>&, const std::string& label) {
  fail("{}: KHR_draco_mesh_compression: plenoptic was built without Draco support (install libdraco-dev and "
       "reconfigure)", label);
}

#endif

}  // namespace pl::detail
