// Scene validation, queries and per-hit surface data. No third-party library here.
#include "scene/scene.h"

#include "core/error.h"

#include <algorithm>
#include <cmath>
#include <array>
#include <fmt/format.h>
#include <map>
#include <spdlog/spdlog.h>
#include <string>
#include <utility>

namespace pl {

namespace {

bool isFinite2(const Vec2& v) { return std::isfinite(v.x) && std::isfinite(v.y); }

/// A triangle is degenerate when its edge vectors are parallel to float precision:
/// |e1 × e2| = |e1|·|e2|·sin(angle) ≤ kDegenerateSine·|e1|·|e2|. With float's unit roundoff of
/// 6e-8, a sine below 1e-7 cannot be told from zero, so such a triangle has no usable normal.
constexpr float kDegenerateSine = 1e-7f;

bool isDegenerate(const Vec3& p0, const Vec3& p1, const Vec3& p2) {
  const Vec3 e1 = p1 - p0, e2 = p2 - p0;
  const float crossLength = glm::length(glm::cross(e1, e2));
  return !(crossLength > kDegenerateSine * glm::length(e1) * glm::length(e2));
}

std::string vecString(const Vec3& v) { return fmt::format("({}, {}, {})", v.x, v.y, v.z); }

void validateLights(const Scene& scene) {
  for (size_t i = 0; i < scene.lights.size(); ++i)
    if (const std::string problem = lightProblem(scene.lights[i]); !problem.empty())
      fail("{}: {} light {} {}", scene.sourcePath, lightTypeName(scene.lights[i]), i, problem);
}

}  // namespace

std::string mappingProblem(const Material& material) {
  const std::pair<const char*, const TextureMapping*> slots[] = {{"albedo", &material.albedoMapping},
                                                                 {"alpha", &material.alphaMapping},
                                                                 {"normal", &material.normalMapping},
                                                                 {"metallic-roughness", &material.metallicRoughness.mapping},
                                                                 {"emission", &material.emissionMapping}};
  auto mappingIssue = [](const char* slot, const TextureMapping& mapping) -> std::string {
    if (mapping.uvSet > 1) return fmt::format("the {} texture reads uv set {} (0 or 1)", slot, mapping.uvSet);
    if (!isFinite2(mapping.offset) || !isFinite2(mapping.linear[0]) || !isFinite2(mapping.linear[1]))
      return fmt::format("the {} texture's uv transform is not finite", slot);
    return "";
  };
  for (const auto& [slot, mapping] : slots)
    if (std::string issue = mappingIssue(slot, *mapping); !issue.empty()) return issue;
  for (int s = 0; s < PbrLayerMaps::kSlots; ++s)
    if (std::string issue = mappingIssue(PbrLayerMaps::kSlotNames[s], material.layers.mapping[size_t(s)]); !issue.empty())
      return issue;
  const bool ggxLike = std::holds_alternative<GgxBsdf>(material.bsdf) || std::holds_alternative<GltfPbrBsdf>(material.bsdf);
  const MetallicRoughnessMap& mr = material.metallicRoughness;
  if (mr.texture >= 0 && !(ggxLike && isFinite(mr.baseColor) && mr.metallic >= 0.0f && mr.metallic <= 1.0f &&
                           mr.roughness >= 0.0f && mr.roughness <= 1.0f))
    return "a metallic-roughness texture needs a GGX model and factors in [0, 1]";
  if (material.layers.any() && !std::holds_alternative<GltfPbrBsdf>(material.bsdf))
    return "glTF layer textures need the layered (gltf-pbr) model";
  return "";
}

void markVertexColoredMaterials(Scene& scene) {
  for (Material& material : scene.materials) material.vertexColored = material.vertexAlpha = false;
  for (const Mesh& mesh : scene.meshes)
    for (const uint32_t material : mesh.materials)
      if (material < scene.materials.size()) {
        scene.materials[material].vertexColored |= !mesh.colors.empty();
        scene.materials[material].vertexAlpha |= !mesh.alphas.empty();
      }
}

size_t openSubsurfaceEdges(const Scene& scene, const Mesh& mesh) {
  // Vertices welded by position, quantised to 1e-6 of the mesh's extent (a seam splits
  // vertices of equal position, and computed ones such as a sphere's pole differ in the last
  // bits), then every directed edge a → b of a subsurface triangle must be matched by exactly
  // one b → a. Edges that the weld collapses to a point are no edges.
  Vec3 lo(kInfinity), hi(-kInfinity);
  for (const Vec3& p : mesh.positions) lo = glm::min(lo, p), hi = glm::max(hi, p);
  const double step = std::max(1e-6 * double(maxComponent(hi - lo)), 1e-30);
  std::map<std::array<int64_t, 3>, uint32_t> weldedOf;
  std::vector<uint32_t> welded(mesh.positions.size());
  for (size_t v = 0; v < mesh.positions.size(); ++v) {
    const Vec3 p = mesh.positions[v] - lo;
    const std::array<int64_t, 3> key = {std::llround(p.x / step), std::llround(p.y / step), std::llround(p.z / step)};
    welded[v] = weldedOf.try_emplace(key, uint32_t(weldedOf.size())).first->second;
  }
  std::map<std::pair<uint32_t, uint32_t>, uint32_t> directed;
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    if (!subsurfaceMedium(scene.materials[mesh.materials[t]].bsdf)) continue;
    for (int e = 0; e < 3; ++e) {
      const uint32_t a = welded[mesh.triangles[t][e]], b = welded[mesh.triangles[t][(e + 1) % 3]];
      if (a != b) ++directed[{a, b}];
    }
  }
  size_t open = 0;
  for (const auto& [edge, count] : directed) {
    const auto back = directed.find({edge.second, edge.first});
    if (count != 1 || back == directed.end() || back->second != 1) ++open;
  }
  return open;
}

void warnAboutOpenSubsurfaceMeshes(const Scene& scene) {
  for (size_t index = 0; index < scene.meshes.size(); ++index) {
    const Mesh& mesh = scene.meshes[index];
    const auto first = std::find_if(mesh.materials.begin(), mesh.materials.end(), [&](uint32_t m) {
      return subsurfaceMedium(scene.materials[m].bsdf).has_value();
    });
    if (first == mesh.materials.end()) continue;
    if (const size_t open = openSubsurfaceEdges(scene, mesh); open > 0)
      spdlog::warn("{}: mesh {}: its subsurface triangles (material '{}') do not enclose a volume ({} open, "
                   "non-manifold or inconsistently wound edge(s)): random walks inside leak out through the gaps",
                   scene.sourcePath, mesh.name.empty() ? fmt::format("#{} (unnamed)", index) : "'" + mesh.name + "'",
                   scene.materials[*first].name, open);
  }
}

/// The model's own validation (bsdf.h bsdfProblem), prefixed with the file and material.
void validateMaterial(const Material& material, const std::string& sourcePath) {
  if (const std::string problem = bsdfProblem(material.bsdf); !problem.empty())
    fail("{}: material '{}': {}", sourcePath, material.name, problem);
}


void checkScene(const Scene& scene) {
  const std::string& src = scene.sourcePath;
  if (scene.materials.empty()) fail("{}: the scene has no materials", src);

  for (const Material& material : scene.materials) {
    if (!isFinite(material.emission) || material.emission.r < 0.0f || material.emission.g < 0.0f ||
        material.emission.b < 0.0f)
      fail("{}: material '{}' has an invalid emission {}", src, material.name, vecString(material.emission));
    // Radiance sums (irradiance = π·L over many tixels, pixel sums over many samples) are
    // 32-bit floats: an emission near FLT_MAX (3.4e38) overflows them into infinities and
    // NaN. 1e12 W·sr⁻¹·m⁻² is 5·10⁴ times the sun's disc (2·10⁷) and leaves 26 orders of
    // magnitude of headroom.
    constexpr float kMaxEmission = 1e12f;
    if (maxComponent(material.emission) > kMaxEmission)
      fail("{}: material '{}' has an emission {} above {:g} W/(sr m^2), too large to compute with", src,
           material.name, vecString(material.emission), kMaxEmission);
    validateMaterial(material, src);
    std::vector<int> textures = {material.albedoTexture, material.alphaTexture, material.normalTexture,
                                 material.metallicRoughness.texture, material.emissionTexture};
    textures.insert(textures.end(), material.layers.texture.begin(), material.layers.texture.end());
    for (const int texture : textures)
      if (texture < -1 || texture >= int64_t(scene.textures.size()))
        fail("{}: material '{}' refers to texture {} but the scene has {}", src, material.name, texture,
             scene.textures.size());
    if (const std::string problem = mappingProblem(material); !problem.empty())
      fail("{}: material '{}': {}", src, material.name, problem);
    if (!(material.alphaFactor >= 0.0f && material.alphaFactor <= 1.0f) ||
        !(material.alphaCutoff >= 0.0f && material.alphaCutoff <= 1.0f))
      fail("{}: material '{}' has alpha {} and alpha cutoff {}; both must be in [0, 1]", src, material.name,
           material.alphaFactor, material.alphaCutoff);
    if (!std::isfinite(material.normalScale))
      fail("{}: material '{}' has a non-finite normal-map scale", src, material.name);
  }

  size_t triangles = 0;
  for (const Mesh& mesh : scene.meshes) {
    const size_t vertexCount = mesh.positions.size();
    if (!mesh.normals.empty() && mesh.normals.size() != vertexCount)
      fail("{}: mesh '{}' has {} normals for {} vertices", src, mesh.name, mesh.normals.size(), vertexCount);
    if (!mesh.uvs.empty() && mesh.uvs.size() != vertexCount)
      fail("{}: mesh '{}' has {} texture coordinates for {} vertices", src, mesh.name, mesh.uvs.size(),
           vertexCount);
    if (!mesh.uvs1.empty() && mesh.uvs1.size() != vertexCount)
      fail("{}: mesh '{}' has {} second texture coordinates for {} vertices", src, mesh.name, mesh.uvs1.size(),
           vertexCount);
    if (!mesh.colors.empty() && mesh.colors.size() != vertexCount)
      fail("{}: mesh '{}' has {} vertex colours for {} vertices", src, mesh.name, mesh.colors.size(), vertexCount);
    for (size_t v = 0; v < mesh.uvs1.size(); ++v)
      if (!isFinite2(mesh.uvs1[v])) fail("{}: mesh '{}': second texture coordinate {} is not finite", src, mesh.name, v);
    for (size_t v = 0; v < mesh.colors.size(); ++v)
      if (!isFinite(mesh.colors[v]) || glm::any(glm::lessThan(mesh.colors[v], Rgb(0.0f))) ||
          maxComponent(mesh.colors[v]) > 1.0f)
        fail("{}: mesh '{}': vertex colour {} is {}, outside [0, 1]", src, mesh.name, v, vecString(mesh.colors[v]));
    if (!mesh.alphas.empty() && mesh.alphas.size() != vertexCount)
      fail("{}: mesh '{}' has {} vertex alphas for {} vertices", src, mesh.name, mesh.alphas.size(), vertexCount);
    for (size_t v = 0; v < mesh.alphas.size(); ++v)
      if (!(mesh.alphas[v] >= 0.0f && mesh.alphas[v] <= 1.0f))
        fail("{}: mesh '{}': vertex alpha {} is {}, outside [0, 1]", src, mesh.name, v, mesh.alphas[v]);
    if (mesh.materials.size() != mesh.triangles.size())
      fail("{}: mesh '{}' has {} material indices for {} triangles", src, mesh.name, mesh.materials.size(),
           mesh.triangles.size());
    for (size_t v = 0; v < vertexCount; ++v)
      if (!isFinite(mesh.positions[v]))
        fail("{}: mesh '{}': vertex {} is not finite {}", src, mesh.name, v, vecString(mesh.positions[v]));
    for (size_t v = 0; v < mesh.normals.size(); ++v)
      if (!isFinite(mesh.normals[v]))
        fail("{}: mesh '{}': normal {} is not finite {}", src, mesh.name, v, vecString(mesh.normals[v]));
    for (size_t v = 0; v < mesh.uvs.size(); ++v)
      if (!isFinite2(mesh.uvs[v]))
        fail("{}: mesh '{}': texture coordinate {} is not finite", src, mesh.name, v);
    for (size_t t = 0; t < mesh.triangles.size(); ++t) {
      const UVec3 tri = mesh.triangles[t];
      for (int k = 0; k < 3; ++k)
        if (tri[k] >= vertexCount)
          fail("{}: mesh '{}': triangle {} refers to vertex {} but the mesh has {} vertices", src, mesh.name, t,
               tri[k], vertexCount);
      if (mesh.materials[t] >= scene.materials.size())
        fail("{}: mesh '{}': triangle {} uses material {} but the scene has {}", src, mesh.name, t,
             mesh.materials[t], scene.materials.size());
    }
    triangles += mesh.triangles.size();
  }
  if (triangles == 0) fail("{}: the scene has no triangles", src);

  validateLights(scene);
  for (const CameraDesc& camera : scene.cameras) {
    if (!isFinite(camera.eye) || !isFinite(camera.target) || !isFinite(camera.up))
      fail("{}: camera '{}' has non-finite eye, target or up", src, camera.name);
    if (camera.eye == camera.target) fail("{}: camera '{}' has eye == target", src, camera.name);
    if (glm::length(glm::cross(camera.target - camera.eye, camera.up)) == 0.0f)
      fail("{}: camera '{}' has an up vector parallel to its view direction", src, camera.name);
    if (!(camera.fovYDegrees > 0.0f && camera.fovYDegrees < 180.0f))
      fail("{}: camera '{}' has a vertical field of view of {} degrees (needs 0 < fov < 180)", src,
           camera.name, camera.fovYDegrees);
    if (!(camera.fNumber >= 0.0f) || !(camera.focusDistance >= 0.0f))
      fail("{}: camera '{}' has a negative f-number or focus distance", src, camera.name);
    if (camera.aspectRatio && !(*camera.aspectRatio > 0.0f && std::isfinite(*camera.aspectRatio)))
      fail("{}: camera '{}' has an invalid aspect ratio", src, camera.name);
  }
  const SceneSettings& settings = scene.settings;
  if ((settings.width && *settings.width <= 0) || (settings.height && *settings.height <= 0) ||
      (settings.spp && *settings.spp <= 0))
    fail("{}: settings: width, height and spp must be positive", src);
  if (settings.camera) (void)scene.camera(*settings.camera);  // throws, listing the cameras, if unknown
  const Environment& environment = scene.environment;
  if (!isFinite(environment.constant) || environment.constant.r < 0.0f || environment.constant.g < 0.0f ||
      environment.constant.b < 0.0f)
    fail("{}: the environment colour {} is invalid", src, vecString(environment.constant));
}

void Scene::finalize() {
  const std::string& src = sourcePath;
  checkScene(*this);
  for (Texture& texture : textures) texture.finish(src);

  size_t totalBefore = 0, dropped = 0;
  for (Mesh& mesh : meshes) {
    // Zero normals stay zero: surfaceAt() falls back to the geometric normal there.
    for (Vec3& n : mesh.normals) {
      const float length = glm::length(n);
      if (length > 0.0f) n /= length;
    }
    totalBefore += mesh.triangles.size();
    size_t kept = 0;
    for (size_t t = 0; t < mesh.triangles.size(); ++t) {
      const UVec3 tri = mesh.triangles[t];
      if (isDegenerate(mesh.positions[tri.x], mesh.positions[tri.y], mesh.positions[tri.z])) continue;
      mesh.triangles[kept] = tri;
      mesh.materials[kept] = mesh.materials[t];
      ++kept;
    }
    dropped += mesh.triangles.size() - kept;
    mesh.triangles.resize(kept);
    mesh.materials.resize(kept);
  }
  std::erase_if(meshes, [](const Mesh& mesh) { return mesh.triangles.empty(); });
  if (meshes.empty()) fail("{}: all {} triangles are degenerate (zero area)", src, totalBefore);
  markVertexColoredMaterials(*this);
  if (dropped > 0)
    spdlog::warn("{}: dropped {} degenerate (zero-area) triangle(s) of {}", src, dropped, totalBefore);

  // Embree reads vertex buffers with 16-byte loads, so the last Vec3 needs 4 readable bytes
  // past it: one element of spare capacity (a copy of the Scene does not keep it, so the
  // renderers build their Accel from the Scene object that was finalized or moved).
  for (Mesh& mesh : meshes) mesh.positions.reserve(mesh.positions.size() + 1);

  for (Light& light : lights) normaliseLightDirections(light);
  warnAboutOpenSubsurfaceMeshes(*this);
}

bool Scene::hasThinGlass() const {
  return std::any_of(materials.begin(), materials.end(), [](const Material& m) {
    const auto* glass = std::get_if<DielectricBsdf>(&m.bsdf);
    return glass && glass->thin;
  });
}

size_t Scene::triangleCount() const {
  size_t count = 0;
  for (const Mesh& mesh : meshes) count += mesh.triangles.size();
  return count;
}

void Scene::bounds(Vec3& lo, Vec3& hi) const {
  lo = Vec3(kInfinity);
  hi = Vec3(-kInfinity);
  for (const Mesh& mesh : meshes)
    for (const Vec3& p : mesh.positions) {
      lo = glm::min(lo, p);
      hi = glm::max(hi, p);
    }
}

const CameraDesc& Scene::camera(const std::string& name) const {
  for (const CameraDesc& camera : cameras)
    if (camera.name == name) return camera;
  std::string available;
  for (const CameraDesc& camera : cameras) available += (available.empty() ? "" : ", ") + ("'" + camera.name + "'");
  fail("{}: no camera named '{}' (available: {})", sourcePath, name, available.empty() ? "none" : available);
}

CameraDesc Scene::automaticCamera() const {
  Vec3 lo, hi;
  bounds(lo, hi);
  CameraDesc camera;
  camera.name = "automatic";
  camera.fovYDegrees = 40.0f;
  if (!isFinite(lo) || !isFinite(hi)) return camera;  // no vertices: the default camera
  const Vec3 centre = 0.5f * (lo + hi);
  // The bounding sphere (radius = half the box diagonal) fits the vertical field of view when
  // seen from distance d = r / sin(fov/2): the tangent cone from the eye then has half-angle
  // fov/2. (Any aspect ratio >= 1 then fits horizontally too.)
  const float radius = std::max(0.5f * glm::length(hi - lo), 1e-6f);
  const float halfFov = 0.5f * glm::radians(camera.fovYDegrees);
  const float distance = radius / std::sin(halfFov);
  camera.target = centre;
  camera.eye = centre + Vec3(0.0f, 0.0f, distance);  // looks along −z
  camera.up = Vec3(0.0f, 1.0f, 0.0f);
  camera.focusDistance = distance;
  return camera;
}

Vec3 interpolatedNormal(const Mesh& mesh, uint32_t triangle, Vec2 barycentrics, const Vec3& geometricNormal) {
  if (mesh.normals.empty()) return geometricNormal;
  const UVec3 tri = mesh.triangles[triangle];
  const float b1 = barycentrics.x, b2 = barycentrics.y, b0 = 1.0f - b1 - b2;
  const Vec3 n = b0 * mesh.normals[tri.x] + b1 * mesh.normals[tri.y] + b2 * mesh.normals[tri.z];
  const float length = glm::length(n);
  // Opposing vertex normals can cancel; then the geometric normal is the only sensible one.
  if (!(length > 1e-6f && std::isfinite(length))) return geometricNormal;
  const Vec3 shading = n / length;
  return glm::dot(shading, geometricNormal) < 0.0f ? -shading : shading;
}

SurfaceHit surfaceAt(const Scene& scene, uint32_t meshIndex, uint32_t triangle, Vec2 barycentrics) {
  const Mesh& mesh = scene.meshes[meshIndex];
  const UVec3 tri = mesh.triangles[triangle];
  const Vec3 &p0 = mesh.positions[tri.x], &p1 = mesh.positions[tri.y], &p2 = mesh.positions[tri.z];

  SurfaceHit hit;
  hit.mesh = meshIndex;
  hit.triangle = triangle;
  hit.barycentrics = barycentrics;
  hit.material = mesh.materials[triangle];
  hit.position = positionAt(mesh, triangle, barycentrics);
  // Counter-clockwise winding (p0, p1, p2) seen from the front ⇒ (p1−p0)×(p2−p0) points out
  // of the front side.
  hit.geometricNormal = glm::normalize(glm::cross(p1 - p0, p2 - p0));
  hit.shadingNormal = interpolatedNormal(mesh, triangle, barycentrics, hit.geometricNormal);
  // Without texture coordinates uv are the barycentrics, so a texture still maps somewhere.
  hit.uv = uvAt(mesh, triangle, barycentrics);
  const Material& material = scene.materials[hit.material];
  const TextureMapping& normalMapping = material.normalMapping;
  const std::vector<Vec2>& normalUvs = normalMapping.uvSet == 1 ? mesh.uvs1 : mesh.uvs;
  if (material.normalTexture >= 0 && !normalUvs.empty()) {
    const Vec3 p[3] = {p0, p1, p2};
    // The frame from the uvs the map is read with (an affine transform keeps the derivation).
    const Vec2 uv[3] = {normalMapping.apply(normalUvs[tri.x]), normalMapping.apply(normalUvs[tri.y]),
                        normalMapping.apply(normalUvs[tri.z])};
    const Vec2 at = normalMapping.isDefault() ? hit.uv : uvAt(mesh, triangle, barycentrics, normalMapping);
    hit.shadingNormal = normalMapped(hit.shadingNormal, hit.geometricNormal, p, uv,
                                     scene.textures[size_t(material.normalTexture)].sample(at), material.normalScale);
  }
  return hit;
}

Vec3 normalMapped(const Vec3& n, const Vec3& geometricNormal, const Vec3 (&p)[3], const Vec2 (&uv)[3], Rgb texel,
                  float scale) {
  // p − p0 = dp/du·(u − u0) + dp/dv·(v − v0) on the triangle; solve the 2×2 system of its
  // two edges for dp/du and dp/dv.
  const Vec3 e1 = p[1] - p[0], e2 = p[2] - p[0];
  const Vec2 d1 = uv[1] - uv[0], d2 = uv[2] - uv[0];
  const float det = d1.x * d2.y - d1.y * d2.x;
  if (!(std::abs(det) > 1e-12f)) return n;
  const Vec3 dpdu = (e1 * d2.y - e2 * d1.y) / det;
  const Vec3 dpdv = (e2 * d1.x - e1 * d2.x) / det;
  Vec3 t = dpdu - n * glm::dot(n, dpdu);
  const float tLength = glm::length(t);
  if (!(tLength > 0.0f) || !std::isfinite(tLength)) return n;
  t /= tLength;
  const Vec3 b = glm::dot(glm::cross(n, t), dpdv) < 0.0f ? -glm::cross(n, t) : glm::cross(n, t);
  const Vec3 m(scale * (2.0f * texel.r - 1.0f), scale * (2.0f * texel.g - 1.0f), 2.0f * texel.b - 1.0f);
  const Vec3 mapped = m.x * t + m.y * b + m.z * n;
  const float length = glm::length(mapped);
  if (!(length > 0.0f) || !std::isfinite(length)) return n;
  const Vec3 result = mapped / length;
  return glm::dot(result, geometricNormal) > 0.01f ? result : n;
}

float coverageAt(const Scene& scene, uint32_t meshIndex, uint32_t triangle, Vec2 barycentrics) {
  const Mesh& mesh = scene.meshes[meshIndex];
  const Material& material = scene.materials[mesh.materials[triangle]];
  float coverage = material.alphaFactor;
  if (!mesh.alphas.empty()) {
    const float b1 = barycentrics.x, b2 = barycentrics.y, b0 = 1.0f - b1 - b2;
    const UVec3 tri = mesh.triangles[triangle];
    coverage *= b0 * mesh.alphas[tri.x] + b1 * mesh.alphas[tri.y] + b2 * mesh.alphas[tri.z];
  }
  // Only uv is needed (this runs per candidate hit inside Embree's traversal).
  if (material.alphaTexture >= 0)
    coverage *= scene.textures[size_t(material.alphaTexture)].sample(uvAt(mesh, triangle, barycentrics, material.alphaMapping)).r;
  return coverage;
}

AlbedoPoint albedoPointAt(const Scene& scene, uint32_t meshIndex, uint32_t triangle, Vec2 barycentrics) {
  const Mesh& mesh = scene.meshes[meshIndex];
  const Material& material = scene.materials[mesh.materials[triangle]];
  AlbedoPoint p;
  p.uv = uvAt(mesh, triangle, barycentrics, material.albedoMapping);
  p.vertexColor = vertexColorAt(mesh, triangle, barycentrics);
  if (material.metallicRoughness.texture >= 0)
    p.metallicRoughnessUv = uvAt(mesh, triangle, barycentrics, material.metallicRoughness.mapping);
  if (material.emissionTexture >= 0) p.emission = emissionModulation(scene, material, meshIndex, triangle, barycentrics);
  return p;
}

Rgb albedoModulation(const Scene& scene, const Material& material, const AlbedoPoint& p) {
  if (material.albedoTexture < 0) return p.vertexColor;
  return scene.textures[size_t(material.albedoTexture)].sampleLod(p.uv, p.lod) * p.vertexColor;
}

namespace {

/// The layered model of a glTF layered material (PbrLayerMaps) at albedo point p: the layer
/// textures read at `hit`, or their means without one.
GltfPbrBsdf layeredModelAt(const Scene& scene, const Material& material, const AlbedoPoint& p, const SurfaceHit* hit) {
  const PbrLayerMaps& layers = material.layers;
  GltfPbrInputs in = layers.factors;
  in.baseColor *= albedoModulation(scene, material, p);
  if (material.metallicRoughness.texture >= 0) {
    const Rgb texel = scene.textures[size_t(material.metallicRoughness.texture)].sample(p.metallicRoughnessUv);
    in.metallic *= texel.b;
    in.roughness *= texel.g;
  }
  std::array<Rgb, PbrLayerMaps::kSlots> texel = layers.meanTexel;
  for (size_t s = 0; s < texel.size() && hit; ++s)
    if (const int t = layers.texture[s]; t >= 0) {
      const TextureMapping& mapping = layers.mapping[s];
      texel[s] = scene.textures[size_t(t)].sample(uvAt(scene.meshes[hit->mesh], hit->triangle, hit->barycentrics, mapping));
    }
  // Channels as glTF gives them: clearcoat R and clearcoat roughness G (raw values), the
  // colours sRGB-decoded, the specular and sheen-roughness A (decoded as coverage: alpha in R).
  in.specular *= texel[PbrLayerMaps::kSpecular].r;
  in.specularColor *= texel[PbrLayerMaps::kSpecularColor];
  in.clearcoat *= texel[PbrLayerMaps::kClearcoat].r;
  in.clearcoatRoughness *= texel[PbrLayerMaps::kClearcoatRoughness].g;
  in.sheenColor *= texel[PbrLayerMaps::kSheenColor];
  in.sheenRoughness *= texel[PbrLayerMaps::kSheenRoughness].r;
  return gltfPbrFromInputs(in);
}

}  // namespace

Rgb emissionModulation(const Scene& scene, const Material& material, uint32_t mesh, uint32_t triangle,
                       Vec2 barycentrics) {
  if (material.emissionTexture < 0) return Rgb(1.0f);
  return scene.textures[size_t(material.emissionTexture)].sample(
      uvAt(scene.meshes[mesh], triangle, barycentrics, material.emissionMapping));
}

Bsdf materialModelAt(const Scene& scene, const Material& material, const AlbedoPoint& p) {
  const MetallicRoughnessMap& mr = material.metallicRoughness;
  if (!material.modelVaries()) return material.bsdf;
  if (material.layers.layered) return layeredModelAt(scene, material, p, nullptr);
  const Rgb modulation = albedoModulation(scene, material, p);
  if (mr.texture >= 0) {
    const Rgb texel = scene.textures[size_t(mr.texture)].sample(p.metallicRoughnessUv);
    return gltfMetallicRoughnessModel(mr.baseColor * modulation, mr.metallic * texel.b, mr.roughness * texel.g);
  }
  return withDiffuseAlbedo(material.bsdf, diffuseAlbedo(material.bsdf) * modulation);
}

Bsdf bsdfAt(const Scene& scene, const SurfaceHit& hit) {
  const Material& material = scene.materials[hit.material];
  if (material.layers.layered && (material.layers.any() || material.modelVaries()))
    return layeredModelAt(scene, material, albedoPointAt(scene, hit.mesh, hit.triangle, hit.barycentrics), &hit);
  if (!material.modelVaries()) return material.bsdf;
  return materialModelAt(scene, material, albedoPointAt(scene, hit.mesh, hit.triangle, hit.barycentrics));
}

ScatteringFrame scatteringFrame(const SurfaceHit& surface, const Vec3& wo, const Bsdf& bsdf) {
  const bool turn = glm::dot(surface.geometricNormal, wo) < 0.0f && !hasTransmission(bsdf);
  ScatteringFrame f;
  f.geometricNormal = turn ? -surface.geometricNormal : surface.geometricNormal;
  f.frame = Frame::fromNormal(turn ? -surface.shadingNormal : surface.shadingNormal);
  f.woLocal = f.frame.toLocal(wo);
  return f;
}

bool usableSide(const Vec3& w, const Vec3& wLocal, const Vec3& geometricNormal, const Bsdf& bsdf) {
  const float cosGeometric = glm::dot(w, geometricNormal);
  if (!hasTransmission(bsdf)) return cosGeometric > 0.0f;
  return cosGeometric * wLocal.z > 0.0f;
}

std::optional<Scattered> scatter(const ScatteringFrame& f, const Bsdf& bsdf, Vec2 u) {
  const std::optional<BsdfSample> s = sample(bsdf, f.woLocal, u);
  if (!s) return std::nullopt;
  const Vec3 wi = f.frame.toWorld(s->wi);
  if (!usableSide(wi, s->wi, f.geometricNormal, bsdf)) return std::nullopt;  // grazing / wrong side
  return Scattered{*s, wi};
}

}  // namespace pl
