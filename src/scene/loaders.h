#pragma once
// Private to the scene module: one loader per file format, each behind its own .cpp with its
// third-party library. Each returns a finalized Scene or throws pl::Error naming the file.
#include "scene/scene.h"

#include <filesystem>
#include <string>

namespace pl::detail {

/// Wavefront OBJ + MTL (tinyobjloader). See obj_loader.cpp for the material mapping.
Scene loadObj(const std::string& path);
/// glTF 2.0, .gltf or .glb (tinygltf). See gltf_loader.cpp for the material mapping.
Scene loadGltf(const std::string& path);
/// The JSON scene description (nlohmann-json). See json_scene.cpp for the schema.
Scene loadJsonScene(const std::string& path);

/// Why `path` cannot be opened as an input file referenced by a scene (texture, material
/// library): "" when it exists, else "not found" or the system's reason (e.g. "File name too
/// long" for a component longer than the OS allows). Never throws.
std::string inputFileProblem(const std::filesystem::path& path);

/// Appends `part` to `scene`, re-indexing its materials and textures (used by the JSON scene
/// to combine files). Lights and cameras are appended too.
void appendScene(Scene& scene, Scene&& part);

}  // namespace pl::detail
