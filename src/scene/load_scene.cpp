// loadScene(): picks the loader by name or file extension.
#include "core/error.h"
#include "core/file_io.h"
#include "scene/loaders.h"
#include "scene/scene.h"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <system_error>

namespace pl {

namespace detail {

std::string inputFileProblem(const std::filesystem::path& path) {
  std::error_code ec;
  if (std::filesystem::exists(path, ec)) return "";
  return ec ? ec.message() : "not found";
}

void appendScene(Scene& scene, Scene&& part) {
  const auto materialOffset = uint32_t(scene.materials.size());
  const auto textureOffset = int(scene.textures.size());
  for (Material& material : part.materials) {
    for (int* texture :
         {&material.albedoTexture, &material.alphaTexture, &material.normalTexture, &material.metallicRoughness.texture,
          &material.emissionTexture})
      if (*texture >= 0) *texture += textureOffset;
    for (int& texture : material.layers.texture)
      if (texture >= 0) texture += textureOffset;
    scene.materials.push_back(std::move(material));
  }
  for (Texture& texture : part.textures) scene.textures.push_back(std::move(texture));
  for (Mesh& mesh : part.meshes) {
    for (uint32_t& material : mesh.materials) material += materialOffset;
    scene.meshes.push_back(std::move(mesh));
  }
  for (Light& light : part.lights) scene.lights.push_back(light);
  for (CameraDesc& camera : part.cameras) scene.cameras.push_back(std::move(camera));
}

}  // namespace detail

Scene loadScene(const std::string& pathOrName) {
  if (pathOrName == "cornell") return makeCornellBox();

  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path path(pathOrName);
  if (!fs::exists(path, ec)) failFile(pathOrName, "{}: no such file", pathOrName);
  if (fs::is_directory(path, ec)) failFile(pathOrName, "{}: is a directory, not a scene file", pathOrName);
  requireRegularFile(pathOrName);

  std::string extension = path.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return char(std::tolower(c)); });
  if (extension == ".obj") return detail::loadObj(pathOrName);
  if (extension == ".gltf" || extension == ".glb") return detail::loadGltf(pathOrName);
  if (extension == ".json") return detail::loadJsonScene(pathOrName);
  fail("{}: unsupported scene format '{}' (supported: 'cornell', .obj, .gltf, .glb, .json)", pathOrName,
       extension.empty() ? std::string("no extension") : extension);
}

}  // namespace pl
