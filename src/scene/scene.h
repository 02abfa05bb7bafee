#pragma once
// The scene: triangle meshes, materials, emitters, cameras and the environment, in the
// scene file's own world units. Loaded once, then read-only; every renderer (path tracer,
// light-field bake, light-field renderer) uses the same Scene.
#include "bsdf/bsdf.h"
#include "core/math.h"
#include "env/env.h"
#include "image/image.h"
#include "light/lights.h"
#include "scene/texture.h"

#include <algorithm>
#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <variant>
#include <vector>

namespace pl {

/// How a material slot maps a surface point to its texture: which of the mesh's uv sets it
/// reads (0 = Mesh::uvs, 1 = Mesh::uvs1; glTF `texCoord`) and an affine transform applied
/// to it (glTF KHR_texture_transform), uv' = linear · uv + offset, in our bottom-left uv
/// convention (the glTF loader converts the extension's top-left one). The default is
/// TEXCOORD_0 as it is.
struct TextureMapping {
  uint8_t uvSet = 0;
  Mat2 linear{1.0f};
  Vec2 offset{0.0f};
  Vec2 apply(Vec2 uv) const { return linear * uv + offset; }
  bool isDefault() const { return uvSet == 0 && linear == Mat2(1.0f) && offset == Vec2(0.0f); }
};

/// A metallic-roughness texture (glTF pbrMetallicRoughness.metallicRoughnessTexture) on a
/// GGX-like material: at each point the model is gltfMetallicRoughnessModel(baseColor ×
/// albedo modulation (albedoModulation), metallic × B, roughness × G), B and G the texel's
/// blue and green channels (raw values), the factors the material's own. `texture` is an
/// index into Scene::textures (ImageDecode::Data) or −1 (none: the material's bsdf as it is).
struct MetallicRoughnessMap {
  int texture = -1;
  TextureMapping mapping;
  Rgb baseColor{1.0f};
  float metallic = 1.0f, roughness = 1.0f;
};

/// The glTF layer textures of a GltfPbrBsdf material (KHR_materials_specular, _clearcoat and
/// _sheen), each with its TextureMapping, and the material's glTF factors (`factors`) that they
/// and the core textures multiply. The path tracer rebuilds the model at every hit (bsdfAt):
/// gltfPbrFromInputs of the factors with baseColor × albedoModulation, metallic × B and
/// roughness × G of a metallic-roughness texture, specular × A, specularColor × RGB,
/// clearcoat × R, clearcoatRoughness × G, sheenColor × RGB and sheenRoughness × A of the
/// layer textures. Everything else keeps Material::bsdf, built from the factors × each
/// texture's mean (the bake's glossy maps, the renderers' highlights). Not stored in the .plf.
struct PbrLayerMaps {
  enum Slot : uint8_t { kSpecular, kSpecularColor, kClearcoat, kClearcoatRoughness, kSheenColor, kSheenRoughness, kSlots };
  /// The glTF names of the slots, in Slot order (for messages).
  static constexpr const char* kSlotNames[kSlots] = {"specularTexture",          "specularColorTexture",
                                                     "clearcoatTexture",         "clearcoatRoughnessTexture",
                                                     "sheenColorTexture",        "sheenRoughnessTexture"};
  std::array<int, kSlots> texture = {-1, -1, -1, -1, -1, -1};  ///< into Scene::textures, or −1
  std::array<TextureMapping, kSlots> mapping{};
  /// Each slot's mean texel (white without a texture): what stands in for the texel where a
  /// model is made per point without a hit (materialModelAt).
  std::array<Rgb, kSlots> meanTexel = {Rgb(1.0f), Rgb(1.0f), Rgb(1.0f), Rgb(1.0f), Rgb(1.0f), Rgb(1.0f)};
  GltfPbrInputs factors;
  /// Whether the factors are set (a glTF material with a layer extension): a varying base
  /// colour or metallic-roughness texture then rebuilds the layered model, not plain GGX.
  bool layered = false;
  bool any() const { return std::any_of(texture.begin(), texture.end(), [](int t) { return t >= 0; }); }
};

struct Material {
  std::string name;
  Bsdf bsdf = LambertBsdf{};
  /// Index into Scene::textures multiplying the diffuse albedo, or -1.
  int albedoTexture = -1;
  /// Emitted radiance Le (W·sr⁻¹·m⁻²), leaving the front side (along the geometric normal
  /// given by the triangle's winding, counter-clockwise = front) unless twoSided.
  Rgb emission{0.0f};
  bool twoSidedEmission = false;
  /// Emission texture (glTF emissiveTexture, JSON "emission_texture"): index into Scene::textures
  /// (ImageDecode::Colour, sRGB) or −1. Le at a point is emission × the texel at its uv through
  /// emissionMapping, at full resolution (emissionModulation).
  int emissionTexture = -1;
  /// Alpha mask (cut-out): coverage α = alphaFactor × (alphaTexture's coverage at uv, or 1
  /// without one) × the mesh's vertex alpha (Mesh::alphas, 1 without). Where α < alphaCutoff
  /// the surface is not there at all: ray casting (Accel) skips the hit, so every renderer,
  /// shadow ray and the bake see through it. alphaTexture is an index into Scene::textures
  /// (decoded as ImageDecode::Coverage) or -1.
  int alphaTexture = -1;
  float alphaFactor = 1.0f;
  float alphaCutoff = 0.5f;
  /// Tangent-space normal map (index into Scene::textures, ImageDecode::Data) or -1: a texel
  /// t ∈ [0,1]³ is the normal (2t − 1) in the frame (tangent = +u, bitangent = +v, shading
  /// normal), its x and y scaled by normalScale (glTF `scale`, MTL `-bm`). See surfaceAt().
  int normalTexture = -1;
  float normalScale = 1.0f;
  /// Light-field tixel density relative to the bake preset's (2 = tixels half as wide); a
  /// JSON scene's "tixel_density". Only the bake's parameterisation reads it.
  float tixelDensity = 1.0f;
  /// The uv set and transform each texture slot reads (TextureMapping; all default outside
  /// glTF). The alpha mask's is the albedo texture's in glTF (both are baseColorTexture).
  TextureMapping albedoMapping, alphaMapping, normalMapping, emissionMapping;
  /// Per-point metalness and roughness (glTF only); see MetallicRoughnessMap.
  MetallicRoughnessMap metallicRoughness;
  /// Per-hit glTF layer textures (glTF only, path tracer only); see PbrLayerMaps.
  PbrLayerMaps layers;
  /// Derived, not stored: whether a mesh with vertex colours (Mesh::colors) uses the material,
  /// so that its albedo varies over a surface even without a texture. Scene::finalize and the
  /// .plf reader set it (markVertexColoredMaterials).
  bool vertexColored = false;
  /// Derived, not stored: whether a mesh with vertex alphas (Mesh::alphas) uses the material,
  /// so that its coverage varies over a surface even without a texture (the same setters).
  bool vertexAlpha = false;

  bool isEmissive() const { return !isBlack(emission); }
  /// Whether the diffuse albedo varies over the surface (a texture or vertex colours): the
  /// renderers then read it per pixel (albedoModulation) instead of once per chart.
  bool albedoVaries() const { return albedoTexture >= 0 || vertexColored; }
  /// Whether the model varies over the surface at all (its albedo, or a metallic-roughness
  /// texture): materialModelAt is then needed per point.
  bool modelVaries() const { return albedoVaries() || metallicRoughness.texture >= 0; }
  /// Whether some of the surface may be cut away (the Accel filters hits on it).
  bool isMasked() const { return alphaTexture >= 0 || alphaFactor < alphaCutoff || vertexAlpha; }
};

/// The sidedness rule for emission, written once for the path tracer, the bake and the
/// renderers: Le towards a direction whose cosine against the geometric (winding) normal is
/// cosFront, i.e. emission leaves the front side only, unless the material is two-sided.
inline Rgb emittedRadiance(const Rgb& emission, bool twoSided, float cosFront) {
  return (cosFront > 0.0f || twoSided) ? emission : Rgb(0.0f);
}
inline Rgb emittedRadiance(const Material& m, float cosFront) {
  return emittedRadiance(m.emission, m.twoSidedEmission, cosFront);
}

/// Beer–Lambert, written once for the path tracer and the light field's specular chains: a
/// segment of length `distance` (scene units) that ends on the back of a surface (cosFront < 0,
/// the cosine of the direction back along the segment against the geometric normal) ran through
/// the inside of that closed mesh — its front side is the outside — and keeps exp(−σa·distance)
/// of its radiance, σa the model's interior absorption (bsdf.h; black for all but dielectrics).
inline Rgb interiorTransmittance(const Material& m, float cosFront, float distance) {
  if (!(cosFront < 0.0f)) return Rgb(1.0f);
  const Rgb sigma = interiorAbsorption(m.bsdf);
  return isBlack(sigma) ? Rgb(1.0f) : glm::exp(-sigma * distance);
}

/// Triangles sharing vertex arrays. Vertex attributes are per vertex; materials per triangle.
struct Mesh {
  std::string name;
  /// Vertex positions. Scene::finalize() reserves one element of padding past the end so
  /// that Embree may share this buffer (it reads 16 bytes at the last vertex).
  std::vector<Vec3> positions;
  std::vector<Vec3> normals;  ///< empty, or one per vertex (unit length)
  std::vector<Vec2> uvs;      ///< empty, or one per vertex
  /// A second uv set (glTF TEXCOORD_1), empty or one per vertex: read by the texture slots
  /// whose TextureMapping::uvSet is 1.
  std::vector<Vec2> uvs1;
  /// Linear RGB vertex colours (glTF COLOR_0), empty or one per vertex in [0, 1]: they
  /// multiply the diffuse albedo (albedoModulation), interpolated over each triangle.
  std::vector<Rgb> colors;
  /// Vertex alphas (glTF COLOR_0's alpha on an alpha-masked material), empty or one per vertex
  /// in [0, 1]: they multiply the alpha mask's coverage (coverageAt), interpolated over each
  /// triangle. The glTF loader keeps them only where they can cut something away.
  std::vector<float> alphas;
  std::vector<UVec3> triangles;
  std::vector<uint32_t> materials;  ///< one per triangle, index into Scene::materials
};


/// A camera as a scene file describes it. The camera module turns it into rays.
struct CameraDesc {
  std::string name;
  Vec3 eye{0.0f, 0.0f, 1.0f};
  Vec3 target{0.0f};
  Vec3 up{0.0f, 1.0f, 0.0f};
  float fovYDegrees = 40.0f;  ///< vertical field of view
  /// Thin lens (optional): f-number N (0 = pinhole) and focus distance in scene units.
  float fNumber = 0.0f;
  float focusDistance = 0.0f;
  /// Focal length in millimetres of a 35 mm-equivalent lens (used with fNumber to get the
  /// aperture diameter f/N in scene units; see camera.h). 0 = derive from the fov.
  float focalLengthMm = 0.0f;
  std::optional<float> aspectRatio;  ///< width / height if the file says so
};

/// Light arriving from infinity in directions no geometry covers:
///   Le(dir) = constant + map->radiance(dir)   (dir: unit world direction towards the sky).
/// `map` (optional, env/env.h) is an image-based environment that carries its own scale and
/// rotation about +y, and importance-samples itself (EnvironmentMap::sample / pdf, densities
/// per solid angle) so renderers can use it for next-event estimation with MIS.
struct Environment {
  Rgb constant{0.0f};
  std::shared_ptr<const EnvironmentMap> map;

  Rgb radiance(const Vec3& dir) const { return map ? constant + map->radiance(dir) : constant; }
  bool isBlack() const { return !map && pl::isBlack(constant); }
};

/// Render settings a scene file may suggest (the JSON scene's "settings"). Command-line flags
/// take precedence; unset values leave the command's defaults.
struct SceneSettings {
  std::optional<int> width, height;   ///< image size in pixels
  std::optional<int> spp;             ///< samples per pixel for `trace`
  std::optional<std::string> camera;  ///< name of the camera to use when --camera is absent
};

struct Scene {
  std::string sourcePath;  ///< the file it came from ("cornell" for the built-in box)
  std::vector<Mesh> meshes;
  std::vector<Material> materials;
  std::vector<Texture> textures;
  std::vector<Light> lights;  ///< light sources besides emissive materials and the environment (light/lights.h)
  std::vector<CameraDesc> cameras;
  Environment environment;
  SceneSettings settings;

  /// Checks the scene (checkScene below), prepares its textures (Texture::finish), drops
  /// degenerate triangles (with a warning; throws when none is left), normalises normals and
  /// light directions (and prepares the lights: light/lights.h), and pads the vertex buffers
  /// for sharing with Embree. Loaders call it last. The padding is spare *capacity*: a moved
  /// Scene keeps it, a copied one does not (build the Accel on the loaded object, or call
  /// finalize() again on a copy).
  void finalize();

  size_t triangleCount() const;
  /// Whether some material is thin glass (a DielectricBsdf sheet), which shadow rays pass with
  /// a coloured transmittance (light/light.h ShadowRays) and which rules out sun masks
  /// (lightfield.h sunMaskLights).
  bool hasThinGlass() const;
  /// Axis-aligned bounds of all vertices.
  void bounds(Vec3& lo, Vec3& hi) const;
  /// The camera called `name`; throws pl::Error listing the available ones if missing.
  const CameraDesc& camera(const std::string& name) const;
  /// A camera named "automatic" that frames the whole scene: it looks down −z at the centre of
  /// the bounding box from distance r / sin(20°), r = half the box diagonal, so the bounding
  /// sphere fits its 40° vertical field of view (and any image at least as wide as high).
  CameraDesc automaticCamera() const;
};

/// The one checker of a scene's consistency, for scenes from any source: Scene::finalize runs
/// it on every loaded scene and the .plf reader on the scene a file holds. Throws pl::Error
/// naming scene.sourcePath and the first problem: no materials or no triangles; a material's
/// emission (negative, not finite, above 1e12 W·sr⁻¹·m⁻²), model (validateMaterial), texture
/// indices, alpha or normal-map scale; a mesh's array sizes, non-finite vertices, normals or
/// uvs, or out-of-range vertex and material indices; a light (position, direction, intensity,
/// cone angles); a camera; the settings (positive sizes and spp, a camera that exists); the
/// environment colour. It changes nothing, so it also accepts a finalized scene.
void checkScene(const Scene& scene);

/// Loads `cornell`, .obj, .gltf/.glb or .json (see docs/scenes.md for the JSON schema).
/// Throws pl::Error with the file name and the problem for any malformed input.
Scene loadScene(const std::string& pathOrName);

/// The measured Cornell box (see cornell.cpp for the data source).
Scene makeCornellBox();

/// Everything a renderer needs about a ray's hit on a triangle.
struct SurfaceHit {
  Vec3 position{0.0f};
  Vec3 geometricNormal{0.0f, 0.0f, 1.0f};  ///< unit, from the triangle winding
  Vec3 shadingNormal{0.0f, 0.0f, 1.0f};    ///< unit, interpolated (or geometric), same side
  Vec2 uv{0.0f};
  Vec2 barycentrics{0.0f};                 ///< (b1, b2) on the triangle, as surfaceAt was given them
  uint32_t mesh = 0, triangle = 0, material = 0;
};

/// Surface data at barycentrics (b1, b2) of triangle `triangle` of mesh `mesh`
/// (point = (1−b1−b2)·p0 + b1·p1 + b2·p2, as Embree reports u, v). With a normal map the
/// shading normal is the mapped one (normalMapped), so the path tracer, mirror chains and the
/// renderers all shade with it.
SurfaceHit surfaceAt(const Scene& scene, uint32_t mesh, uint32_t triangle, Vec2 barycentrics);

/// The unit winding normal (p1 − p0) × (p2 − p0) of triangle `triangle` (the front side),
/// zero for a degenerate triangle.
inline Vec3 triangleNormal(const Mesh& mesh, uint32_t triangle) {
  const UVec3 t = mesh.triangles[triangle];
  const Vec3 n = glm::cross(mesh.positions[t[1]] - mesh.positions[t[0]], mesh.positions[t[2]] - mesh.positions[t[0]]);
  const float length = glm::length(n);
  return length > 0.0f ? n / length : Vec3(0.0f);
}

/// The interpolated vertex normal of triangle `triangle` at barycentrics (b1, b2), unit and on
/// the side of geometricNormal (the triangle's unit winding normal); geometricNormal itself when
/// the mesh has no normals or they cancel. surfaceAt's shading normal before any normal map.
Vec3 interpolatedNormal(const Mesh& mesh, uint32_t triangle, Vec2 barycentrics, const Vec3& geometricNormal);

/// The shading normal n perturbed by a tangent-space normal-map texel t ∈ [0,1]³ (as sampled
/// from an ImageDecode::Data texture): m = 2t − 1, m.xy × scale, n' = normalize(m.x T + m.y B
/// + m.z n). The tangent frame comes from the triangle's uv derivatives (one per triangle,
/// as MikkTSpace does per face without its vertex averaging): dp/du Gram-Schmidt
/// orthogonalised against n gives T, B = ±n × T with the sign of the uv mapping's handedness
/// (mirrored uvs keep +v). Returns n unchanged when the uvs are degenerate (no frame) or when
/// n' would fall behind the geometric surface (dot(n', ng) ≤ 0.01): the sidedness rule needs
/// the shading normal on the geometric normal's side.
Vec3 normalMapped(const Vec3& shadingNormal, const Vec3& geometricNormal, const Vec3 (&p)[3], const Vec2 (&uv)[3],
                  Rgb texel, float scale);

/// The point at barycentrics (b1, b2) of a triangle, exactly surfaceAt's position.
inline Vec3 positionAt(const Mesh& mesh, uint32_t triangle, Vec2 barycentrics) {
  const float b1 = barycentrics.x, b2 = barycentrics.y, b0 = 1.0f - b1 - b2;
  const UVec3 tri = mesh.triangles[triangle];
  return b0 * mesh.positions[tri.x] + b1 * mesh.positions[tri.y] + b2 * mesh.positions[tri.z];
}

/// The texture coordinates at barycentrics (b1, b2) of a triangle, exactly surfaceAt's uv
/// (the barycentrics themselves for a mesh without uvs), without the rest of surfaceAt: the
/// alpha-mask filter and the renderers' albedo lookups need only this.
inline Vec2 uvAt(const Mesh& mesh, uint32_t triangle, Vec2 barycentrics) {
  const float b1 = barycentrics.x, b2 = barycentrics.y, b0 = 1.0f - b1 - b2;
  if (mesh.uvs.empty()) return Vec2(b1, b2);
  const UVec3 tri = mesh.triangles[triangle];
  return b0 * mesh.uvs[tri.x] + b1 * mesh.uvs[tri.y] + b2 * mesh.uvs[tri.z];
}

/// The texture coordinates a slot with `mapping` reads at barycentrics (b1, b2): its uv set
/// interpolated (uvAt's rule: the barycentrics for a mesh without that set), then its transform.
inline Vec2 uvAt(const Mesh& mesh, uint32_t triangle, Vec2 barycentrics, const TextureMapping& mapping) {
  if (mapping.isDefault()) return uvAt(mesh, triangle, barycentrics);
  const std::vector<Vec2>& uvs = mapping.uvSet == 1 ? mesh.uvs1 : mesh.uvs;
  Vec2 uv(barycentrics);
  if (!uvs.empty()) {
    const float b1 = barycentrics.x, b2 = barycentrics.y, b0 = 1.0f - b1 - b2;
    const UVec3 tri = mesh.triangles[triangle];
    uv = b0 * uvs[tri.x] + b1 * uvs[tri.y] + b2 * uvs[tri.z];
  }
  return mapping.apply(uv);
}

/// The interpolated vertex colour at barycentrics (b1, b2) of a triangle (1 for a mesh without).
inline Rgb vertexColorAt(const Mesh& mesh, uint32_t triangle, Vec2 barycentrics) {
  if (mesh.colors.empty()) return Rgb(1.0f);
  const float b1 = barycentrics.x, b2 = barycentrics.y, b0 = 1.0f - b1 - b2;
  const UVec3 tri = mesh.triangles[triangle];
  return b0 * mesh.colors[tri.x] + b1 * mesh.colors[tri.y] + b2 * mesh.colors[tri.z];
}

/// Where a material's albedo is read at a surface point: the albedo texture's uv (its slot's
/// uv set and transform applied), the mip level (0 = full resolution, Texture::sampleLod) and
/// the interpolated vertex colour. albedoPointAt makes one at full resolution; the
/// light-field renderers set `lod` from their ray cones (lookup.h albedoLodAt).
struct AlbedoPoint {
  Vec2 uv{0.0f};
  float lod = 0.0f;
  Rgb vertexColor{1.0f};
  Vec2 metallicRoughnessUv{0.0f};  ///< where a metallic-roughness texture is read (its own slot)
  /// The emission texture at the point (emissionModulation; 1 without one): the renderers
  /// multiply a diffuse chart's emission by it per pixel.
  Rgb emission{1.0f};
};
AlbedoPoint albedoPointAt(const Scene& scene, uint32_t mesh, uint32_t triangle, Vec2 barycentrics);

/// The albedo rule, written once for the path tracer (bsdfAt), the bake's transport albedo and
/// both renderers (lookup.h diffuseAlbedoAt): what multiplies the material's diffuse albedo at
/// `p` — its albedo texture at p.uv and mip level p.lod (1 without one) × p.vertexColor.
Rgb albedoModulation(const Scene& scene, const Material& material, const AlbedoPoint& p);

/// The emission rule, written once for the path tracer, the light sampler, the bake and the
/// renderers: what multiplies Material::emission at barycentrics (b1, b2) of triangle
/// `triangle` of mesh `mesh` — the emission texture's texel at its slot's uv (Texture::sample:
/// full resolution, the texture's own wrap and filter), or 1 without one.
Rgb emissionModulation(const Scene& scene, const Material& material, uint32_t mesh, uint32_t triangle,
                       Vec2 barycentrics);

/// What is wrong with a material's texture mappings and metallic-roughness map ("" if nothing):
/// a uv set other than 0 and 1, a non-finite transform, a metallic-roughness texture on a
/// model other than GGX or with factors outside [0, 1]. Scene::finalize and the .plf reader.
std::string mappingProblem(const Material& material);

/// The material's model at albedo point p, the one rule bsdfAt and the renderers' albedos
/// (lookup.h diffuseAlbedoAt, glossyDiffuseAlbedoAt) apply: the model as it is when nothing
/// varies; with a metallic-roughness texture gltfMetallicRoughnessModel(baseColor × modulation,
/// metallic × B, roughness × G) of the texel at p.metallicRoughnessUv (full resolution), for a
/// glTF layered material the layered model of the same (PbrLayerMaps, with the layer textures'
/// means); otherwise the model with its diffuse albedo × albedoModulation(p).
Bsdf materialModelAt(const Scene& scene, const Material& material, const AlbedoPoint& p);

/// Sets Material::vertexColored and vertexAlpha from the meshes (Scene::finalize and the .plf
/// reader call it).
void markVertexColoredMaterials(Scene& scene);

/// The alpha mask's coverage at barycentrics (b1, b2) of a triangle: alphaFactor × texture
/// coverage at the interpolated uv × the interpolated vertex alpha. The Accel's hit filter.
float coverageAt(const Scene& scene, uint32_t mesh, uint32_t triangle, Vec2 barycentrics);

/// The sidedness rule for scattering, written once for the path tracer, the bake's specular
/// chains and the renderers. A reflecting BSDF is two-sided: both normals are turned to the
/// side wo comes from. A transmitting one keeps +z on the outside (bsdf.h), so its frame is
/// never turned. `frame` is the shading frame, woLocal = frame.toLocal(wo).
struct ScatteringFrame {
  Vec3 geometricNormal{0.0f, 0.0f, 1.0f};
  Frame frame;
  Vec3 woLocal{0.0f, 0.0f, 1.0f};
};
ScatteringFrame scatteringFrame(const SurfaceHit& surface, const Vec3& wo, const Bsdf& bsdf);

/// Whether world direction w (local wLocal in a ScatteringFrame) is on a side of the surface
/// the BSDF may use: for a reflecting BSDF above the (turned) geometric surface, which also
/// stops light leaking through where shading normals bend over the horizon; for a transmitting
/// one on the same side of the geometric and the shading normal, so that interpolated normals
/// cannot send a path through the surface on the wrong side. Scattering needs both wo and wi
/// on usable sides.
bool usableSide(const Vec3& w, const Vec3& wLocal, const Vec3& geometricNormal, const Bsdf& bsdf);

/// One scattering step, the bounce written once for the path tracer and the light field's
/// specular chains (lookup.h followSpecular: the bake's visibility field and both renderers):
/// sample() in the shading frame of `f` — mirror reflection and dielectric refraction about
/// the (possibly normal-mapped) shading normal, like every other lobe — then the sidedness
/// check of wi (usableSide). Nullopt when the BSDF returns nothing or wi is on an unusable
/// side (the path ends). The caller offsets the next ray's origin (accel.h offsetRayOrigin
/// along f.geometricNormal towards wi).
struct Scattered {
  BsdfSample sample;  ///< in f's local frame
  Vec3 wi{0.0f};      ///< the same direction in world space (unit)
};
std::optional<Scattered> scatter(const ScatteringFrame& f, const Bsdf& bsdf, Vec2 u);

/// The number of edges of mesh's subsurface triangles (bsdf.h SubsurfaceBsdf) that do not close
/// a volume: vertices welded by position (to 1e-6 of the mesh's extent), an edge is closed when
/// exactly one triangle runs along it each way. 0 for a closed, consistently wound surface (or no subsurface triangles).
size_t openSubsurfaceEdges(const Scene& scene, const Mesh& mesh);
/// Logs a warning naming the file, the mesh and the material for every mesh whose subsurface
/// triangles are not closed (openSubsurfaceEdges): a random walk leaves the medium only through
/// its surface, so through a gap it escapes into the open. Scene::finalize() calls it.
void warnAboutOpenSubsurfaceMeshes(const Scene& scene);

/// Throws pl::Error (naming sourcePath and the material) unless the material's model is valid
/// (bsdf.h bsdfProblem: energy conserved, parameters in range). Scene::finalize() checks every
/// material of a scene with it.
void validateMaterial(const Material& material, const std::string& sourcePath);

/// The material's BSDF at a hit: its diffuse albedo times albedoModulation at full resolution
/// (Texture::sample) — the path tracer integrates a pixel's footprint with its samples, and
/// the bake averages over each tixel's footprint itself; only the light-field renderers read
/// mip levels (lookup.h albedoTextureLod) — and with a metallic-roughness texture the GGX
/// parameters at the hit (MetallicRoughnessMap), with glTF layer textures the layered model
/// at the hit (PbrLayerMaps).
Bsdf bsdfAt(const Scene& scene, const SurfaceHit& hit);

}  // namespace pl
