#pragma once
// Compressed glTF meshes, each codec behind its own file with its library: Draco
// (KHR_draco_mesh_compression, gltf_draco.cpp, libdraco) and meshoptimizer
// (EXT_meshopt_compression and KHR_meshopt_compression, gltf_meshopt.cpp, libmeshoptimizer).
// Both libraries are optional at configure time; a build without one refuses such files with "built without … support".
// Internal to the scene module (gltf_loader.cpp is the only caller).
#include <cstddef>
#include <cstdint>
#include <map>
#include <span>
#include <string>
#include <vector>

namespace pl::detail {

/// Whether this build decodes Draco / meshopt compression (glTF extensions it then reads).
bool dracoSupported();
bool meshoptSupported();

/// A decoded Draco primitive: per requested glTF attribute its values as floats (integer
/// attributes converted as Draco's ConvertValue does: normalised ones to [0, 1] or [−1, 1]),
/// `components` per vertex, and the triangle list.
struct DracoPrimitive {
  std::map<std::string, std::vector<float>> attributes;  ///< glTF attribute name → values
  std::vector<uint32_t> indices;                         ///< three per triangle
  size_t vertexCount = 0;
};

/// Decodes a Draco mesh from `bytes`, reading for each entry of `attributes` (glTF name → the
/// Draco attribute's unique id, as the extension gives it) `components[name]` floats per
/// vertex. Throws pl::Error starting with `label` (file and mesh) when the bytes do not decode,
/// are not a triangle mesh, or lack an attribute; or, in a build without Draco, saying so.
DracoPrimitive decodeDraco(std::span<const unsigned char> bytes, const std::map<std::string, int>& attributes,
                           const std::map<std::string, int>& components, const std::string& label);

/// The parameters of one buffer view compressed by EXT_meshopt_compression or its ratified
/// successor KHR_meshopt_compression (`extension` names which, for messages). The KHR one adds
/// the attribute codec's version 1 (header byte 0xa1) and the COLOR filter (YCoCg); a build
/// whose meshoptimizer predates them (0.23 and 0.25) refuses them by name.
struct MeshoptView {
  std::string extension;  ///< "EXT_meshopt_compression" or "KHR_meshopt_compression"
  size_t count = 0, byteStride = 0;
  std::string mode;    ///< "ATTRIBUTES", "TRIANGLES" or "INDICES"
  std::string filter;  ///< "NONE", "OCTAHEDRAL", "QUATERNION", "EXPONENTIAL" or (KHR) "COLOR"
};

/// Decodes one compressed buffer view into count × byteStride bytes. Throws pl::Error starting
/// with `label` when the parameters are invalid or the data does not decode; or, in a build
/// without meshoptimizer, saying so.
std::vector<unsigned char> decodeMeshopt(std::span<const unsigned char> bytes, const MeshoptView& view,
                                         const std::string& label);

}  // namespace pl::detail
