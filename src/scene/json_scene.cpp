// The JSON scene description, through nlohmann-json (the only file that includes it).
//
// Schema (every key optional unless marked required; colours are linear RGB triples,
// positions/directions are [x, y, z] in scene units, relative paths are relative to the
// JSON file's directory):
//
// {
//   "include_cornell": false,               // true: start from the built-in Cornell box (mm)
//   "meshes": [ {
//       "file": "box.obj",                  // required: .obj, .gltf or .glb
//       "transform": [16 numbers]           // row-major 4×4 matrix (first four = first row),
//                 | {"translate": [x,y,z],  //   or T·R·S: translate,
//                    "rotate": {"axis": [x,y,z], "degrees": a},   // rotate (right-handed),
//                    "scale": s | [sx,sy,sz]},                    // scale
//       "material": "name"                  // every triangle of the file uses this material
//   } ],                                    //   from "materials" below
//   "materials": {
//     "name": {"type": "lambert",     "albedo": [r,g,b], "texture": "albedo.png"}
//           | {"type": "mirror",      "reflectance": [r,g,b], "fresnel": false}
//           | {"type": "blinn-phong", "diffuse": [r,g,b], "specular": [r,g,b], "exponent": n,
//              "texture": "albedo.png"}
//           | {"type": "ggx",         "diffuse": [r,g,b], "f0": [r,g,b],
//              "alpha": a | "roughness": r (alpha = r²), "texture": "albedo.png",
//              and the glTF layers (any of them makes it bsdf.h's GltfPbrBsdf): "f90": 1,
//              "clearcoat": 0, "clearcoat_roughness": 0, "sheen": [r,g,b], "sheen_roughness": 0.5}
//       (+ for every type: "emission": [r,g,b] radiance in W·sr⁻¹·m⁻², "two_sided": false,
//        "emission_texture": "glow.png" (sRGB colour multiplying "emission" at each point),
//        "alpha_texture": "mask.png" (cut-out: its alpha channel, or its first channel without
//        one), "alpha_cutoff": 0.5 (no surface where coverage < cutoff),
//        "normal_texture": "normals.png" (tangent-space, OpenGL +y = +v), "normal_scale": 1,
//        "tixel_density": 1 (light-field tixels per length relative to the bake preset, > 0))
//     A material whose name equals a material of a loaded file replaces it there.
//   },
//   "lights": [ {"type": "point", "position": [..], "intensity": [r,g,b] | I}, … ]
//       "type" names a light type of light/lights.h (point, spot, directional, …), the other
//       keys are its parameters, named and in the units of its parameters() hook
//       (docs/scenes.md lists them): a number or [x, y, z] (a colour: one number for grey);
//       angles in degrees.
//   "cameras": [ {"name": "main", "eye": [..], "target": [..], "up": [0,1,0],
//                 "fov": 40 (vertical, degrees), "fstop": 0 (0 = pinhole),
//                 "focus_distance": d, "focal_length": mm, "aspect": w/h} ],
//   "environment": {"color": [r,g,b],        // constant radiance from infinity, plus
//                   "file": "sky.hdr",       //   an environment map (env/env.h: 2:1 lat-long,
//                   "scale": 1,              //   cross, face directory or {face} pattern),
//                   "rotation": 0},          //   radiance × scale, rotated about +y (degrees)
//   "settings": {"width": 640, "height": 480, "spp": 64,       // suggestions; command-line
//                "camera": "main"}                             //   flags take precedence
// }
//
// Lights and cameras of the loaded mesh files are kept (and moved by their transform).
#include "core/error.h"
#include "scene/loaders.h"

#include <glm/gtc/matrix_transform.hpp>
#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <filesystem>
#include <iterator>
#include <fstream>
#include <map>
#include <optional>
#include <set>

namespace pl::detail {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

struct JsonContext {
  std::string path;
  fs::path dir;
};

const json* find(const json& object, const char* key) {
  auto it = object.find(key);
  return it == object.end() ? nullptr : &*it;
}

float number(const JsonContext& ctx, const json& value, const std::string& where) {
  if (!value.is_number()) fail("{}: {}: expected a number, got {}", ctx.path, where, value.dump());
  const double v = value.get<double>();
  if (!std::isfinite(v)) fail("{}: {}: not a finite number", ctx.path, where);
  return float(v);
}

Vec3 vec3(const JsonContext& ctx, const json& value, const std::string& where) {
  if (!value.is_array() || value.size() != 3) fail("{}: {}: expected [x, y, z], got {}", ctx.path, where, value.dump());
  return Vec3(number(ctx, value[0], where), number(ctx, value[1], where), number(ctx, value[2], where));
}

/// A colour: [r, g, b], or one number for grey.
Rgb colour(const JsonContext& ctx, const json& value, const std::string& where) {
  if (value.is_number()) return Rgb(number(ctx, value, where));
  return vec3(ctx, value, where);
}

float numberOr(const JsonContext& ctx, const json& object, const char* key, float fallback, const std::string& where) {
  const json* value = find(object, key);
  return value ? number(ctx, *value, where + "." + key) : fallback;
}
Rgb colourOr(const JsonContext& ctx, const json& object, const char* key, Rgb fallback, const std::string& where) {
  const json* value = find(object, key);
  return value ? colour(ctx, *value, where + "." + key) : fallback;
}
Vec3 vec3Or(const JsonContext& ctx, const json& object, const char* key, Vec3 fallback, const std::string& where) {
  const json* value = find(object, key);
  return value ? vec3(ctx, *value, where + "." + key) : fallback;
}
std::string stringOf(const JsonContext& ctx, const json& value, const std::string& where) {
  if (!value.is_string()) fail("{}: {}: expected a string, got {}", ctx.path, where, value.dump());
  return value.get<std::string>();
}
bool boolOr(const JsonContext& ctx, const json& object, const char* key, bool fallback, const std::string& where) {
  const json* value = find(object, key);
  if (!value) return fallback;
  if (!value->is_boolean()) fail("{}: {}.{}: expected true or false", ctx.path, where, key);
  return value->get<bool>();
}

void checkKeys(const JsonContext& ctx, const json& object, const std::set<std::string>& known, const std::string& where) {
  for (auto it = object.begin(); it != object.end(); ++it)
    if (!known.count(it.key())) fail("{}: {}: unknown key '{}'", ctx.path, where, it.key());
}

Mat4 parseTransform(const JsonContext& ctx, const json& value, const std::string& where) {
  if (value.is_array()) {
    if (value.size() != 16) fail("{}: {}: a matrix needs 16 numbers, got {}", ctx.path, where, value.size());
    Mat4 m;
    for (int row = 0; row < 4; ++row)
      for (int col = 0; col < 4; ++col) m[col][row] = number(ctx, value[size_t(row * 4 + col)], where);  // row-major in
    return m;
  }
  if (!value.is_object()) fail("{}: {}: expected a 16-number matrix or {{translate, rotate, scale}}", ctx.path, where);
  checkKeys(ctx, value, {"translate", "rotate", "scale"}, where);
  Mat4 m(1.0f);
  if (const json* t = find(value, "translate")) m = glm::translate(m, vec3(ctx, *t, where + ".translate"));
  if (const json* r = find(value, "rotate")) {
    if (!r->is_object()) fail("{}: {}.rotate: expected {{\"axis\": [x,y,z], \"degrees\": a}}", ctx.path, where);
    checkKeys(ctx, *r, {"axis", "degrees"}, where + ".rotate");
    const Vec3 axis = vec3Or(ctx, *r, "axis", Vec3(0.0f, 1.0f, 0.0f), where + ".rotate");
    if (glm::length(axis) == 0.0f) fail("{}: {}.rotate.axis is zero", ctx.path, where);
    m = glm::rotate(m, glm::radians(numberOr(ctx, *r, "degrees", 0.0f, where + ".rotate")), glm::normalize(axis));
  }
  if (const json* s = find(value, "scale")) m = glm::scale(m, colour(ctx, *s, where + ".scale"));
  return m;
}

int loadTexture(const JsonContext& ctx, Scene& scene, const json& value, const std::string& where,
                ImageDecode decode = ImageDecode::Colour) {
  const fs::path file = ctx.dir / stringOf(ctx, value, where);
  if (const std::string problem = inputFileProblem(file); !problem.empty())
    fail("{}: {}: texture file '{}' {}", ctx.path, where, file.string(), problem);
  scene.textures.push_back(loadTextureFile(file.string(), decode));
  return int(scene.textures.size()) - 1;
}

Material parseMaterial(const JsonContext& ctx, Scene& scene, const std::string& name, const json& value) {
  const std::string where = "materials." + name;
  if (!value.is_object()) fail("{}: {}: expected an object", ctx.path, where);
  const json* typeValue = find(value, "type");
  if (!typeValue) fail("{}: {}: missing \"type\" (lambert, mirror, blinn-phong, ggx, dielectric, subsurface)", ctx.path, where);
  const std::string type = stringOf(ctx, *typeValue, where + ".type");
  Material material;
  material.name = name;
  material.emission = colourOr(ctx, value, "emission", Rgb(0.0f), where);
  material.twoSidedEmission = boolOr(ctx, value, "two_sided", false, where);
  material.tixelDensity = numberOr(ctx, value, "tixel_density", 1.0f, where);
  if (!(material.tixelDensity > 0.0f) || !std::isfinite(material.tixelDensity))
    fail("{}: {}: tixel_density {} must be a positive number", ctx.path, where, material.tixelDensity);
  std::set<std::string> known = {"type", "emission", "emission_texture", "two_sided", "alpha_texture", "alpha_cutoff", "normal_texture",
                                  "normal_scale", "tixel_density"};
  if (type == "lambert") {
    material.bsdf = LambertBsdf{colourOr(ctx, value, "albedo", Rgb(0.8f), where)};
    known.insert({"albedo", "texture"});
  } else if (type == "mirror") {
    material.bsdf = MirrorBsdf{colourOr(ctx, value, "reflectance", Rgb(1.0f), where), boolOr(ctx, value, "fresnel", false, where)};
    known.insert({"reflectance", "fresnel"});
  } else if (type == "blinn-phong") {
    material.bsdf = BlinnPhongBsdf{colourOr(ctx, value, "diffuse", Rgb(0.5f), where),
                                   colourOr(ctx, value, "specular", Rgb(0.04f), where),
                                   numberOr(ctx, value, "exponent", 64.0f, where)};
    known.insert({"diffuse", "specular", "exponent", "texture"});
  } else if (type == "ggx") {
    GgxBsdf ggx;
    ggx.diffuse = colourOr(ctx, value, "diffuse", Rgb(0.0f), where);
    ggx.f0 = colourOr(ctx, value, "f0", Rgb(0.04f), where);
    if (find(value, "alpha") && find(value, "roughness"))
      fail("{}: {}: give either \"alpha\" or \"roughness\", not both", ctx.path, where);
    if (const json* roughness = find(value, "roughness")) {
      ggx.alpha = alphaFromRoughness(number(ctx, *roughness, where + ".roughness"));
    } else {
      ggx.alpha = numberOr(ctx, value, "alpha", ggx.alpha, where);
    }
    if (!(ggx.alpha > 0.0f && ggx.alpha <= 1.0f)) fail("{}: {}: GGX alpha {} must be in (0, 1]", ctx.path, where, ggx.alpha);
    material.bsdf = ggx;
    // The glTF layers (bsdf.h GltfPbrBsdf): any of these keys makes the model the layered one.
    static constexpr const char* kLayerKeys[] = {"f90", "clearcoat", "clearcoat_roughness", "sheen", "sheen_roughness"};
    if (std::any_of(std::begin(kLayerKeys), std::end(kLayerKeys), [&](const char* key) { return find(value, key); })) {
      GltfPbrBsdf pbr;
      pbr.diffuse = ggx.diffuse;
      pbr.f0 = ggx.f0;
      pbr.alpha = ggx.alpha;
      pbr.f90 = numberOr(ctx, value, "f90", 1.0f, where);
      pbr.clearcoat = numberOr(ctx, value, "clearcoat", 0.0f, where);
      const float coatRoughness = numberOr(ctx, value, "clearcoat_roughness", 0.0f, where);
      if (!(coatRoughness >= 0.0f && coatRoughness <= 1.0f))
        fail("{}: {}: clearcoat_roughness {} must be in [0, 1]", ctx.path, where, coatRoughness);
      pbr.clearcoatAlpha = ggxAlphaFromRoughness(coatRoughness);
      pbr.sheenColor = colourOr(ctx, value, "sheen", Rgb(0.0f), where);
      pbr.sheenRoughness = numberOr(ctx, value, "sheen_roughness", 0.5f, where);
      // The diffuse under the whole lobe, as "ggx" couples it (no metal member).
      pbr.dielectricF0 = pbr.f0;
      pbr.dielectricF90 = pbr.f90;
      material.bsdf = pbr;
    }
    known.insert({"diffuse", "f0", "alpha", "roughness", "texture"});
    known.insert(std::begin(kLayerKeys), std::end(kLayerKeys));
  } else if (type == "dielectric") {
    DielectricBsdf glass;
    glass.ior = numberOr(ctx, value, "ior", glass.ior, where);
    glass.transmittance = colourOr(ctx, value, "transmittance", Rgb(1.0f), where);
    const float roughness = numberOr(ctx, value, "roughness", 0.0f, where);
    if (!(roughness >= 0.0f && roughness <= 1.0f)) fail("{}: {}: roughness {} must be in [0, 1]", ctx.path, where, roughness);
    glass.alpha = dielectricAlphaFromRoughness(roughness);
    glass.thin = boolOr(ctx, value, "thin", false, where);
    glass.absorption = colourOr(ctx, value, "absorption", Rgb(0.0f), where);
    if (glass.thin && roughness > 0.0f) fail("{}: {}: a thin dielectric is smooth (roughness must be 0)", ctx.path, where);
    material.bsdf = glass;
    known.insert({"ior", "transmittance", "roughness", "thin", "absorption"});
  } else if (type == "subsurface") {
    const json* radius = find(value, "radius");
    if (!radius) fail("{}: {}: a subsurface material needs \"radius\" (scene units, a number or [r, g, b])", ctx.path, where);
    material.bsdf = SubsurfaceBsdf{colourOr(ctx, value, "albedo", Rgb(0.8f), where), colour(ctx, *radius, where + ".radius")};
    known.insert({"albedo", "radius", "texture"});
  } else {
    fail("{}: {}: unknown material type '{}' (lambert, mirror, blinn-phong, ggx, dielectric, subsurface)", ctx.path, where, type);
  }
  checkKeys(ctx, value, known, where);
  if (const json* texture = find(value, "texture")) material.albedoTexture = loadTexture(ctx, scene, *texture, where + ".texture");
  if (const json* texture = find(value, "alpha_texture"))
    material.alphaTexture = loadTexture(ctx, scene, *texture, where + ".alpha_texture", ImageDecode::Coverage);
  material.alphaCutoff = numberOr(ctx, value, "alpha_cutoff", material.alphaCutoff, where);
  if (!(material.alphaCutoff >= 0.0f && material.alphaCutoff <= 1.0f))
    fail("{}: {}: alpha_cutoff {} must be in [0, 1]", ctx.path, where, material.alphaCutoff);
  if (find(value, "alpha_cutoff") && material.alphaTexture < 0)
    fail("{}: {}: alpha_cutoff needs an alpha_texture", ctx.path, where);
  if (const json* texture = find(value, "emission_texture")) {
    if (!material.isEmissive()) fail("{}: {}: emission_texture needs a non-black \"emission\"", ctx.path, where);
    material.emissionTexture = loadTexture(ctx, scene, *texture, where + ".emission_texture");
  }
  if (const json* texture = find(value, "normal_texture"))
    material.normalTexture = loadTexture(ctx, scene, *texture, where + ".normal_texture", ImageDecode::Data);
  material.normalScale = numberOr(ctx, value, "normal_scale", material.normalScale, where);
  if (find(value, "normal_scale") && material.normalTexture < 0)
    fail("{}: {}: normal_scale needs a normal_texture", ctx.path, where);
  // Checked here, not only by Scene::finalize(): a JSON material enters the scene only where
  // it is used, and an unused one that creates energy is still a mistake in the file.
  validateMaterial(material, ctx.path);
  return material;
}

/// Moves everything of `part` by matrix m (positions, normals, lights, cameras).
void transformScene(Scene& part, const Mat4& m) {
  const Mat3 linear(m);
  const Mat3 normalMatrix = glm::transpose(glm::inverse(linear));
  const bool mirrored = glm::determinant(linear) < 0.0f;
  auto point = [&](const Vec3& p) { return Vec3(m * Vec4(p, 1.0f)); };
  for (Mesh& mesh : part.meshes) {
    for (Vec3& p : mesh.positions) p = point(p);
    for (Vec3& n : mesh.normals) n = normalMatrix * n;
    if (mirrored)
      for (UVec3& t : mesh.triangles) std::swap(t.y, t.z);
  }
  for (Light& light : part.lights) transformLight(light, m);
  for (CameraDesc& camera : part.cameras) {
    camera.eye = point(camera.eye);
    camera.target = point(camera.target);
    const Vec3 up = linear * camera.up;
    if (glm::length(up) > 0.0f) camera.up = glm::normalize(up);
  }
}

Scene parseScene(const JsonContext& ctx, const json& root) {
  if (!root.is_object()) fail("{}: the top level must be a JSON object", ctx.path);
  checkKeys(ctx, root, {"include_cornell", "meshes", "materials", "lights", "cameras", "environment", "settings"},
            "top level");
  Scene scene;
  scene.sourcePath = ctx.path;
  // JSON materials are parsed first but enter the scene only where they are used, so the
  // loaded files keep their own material indices (a JSON override of a file's material then
  // leaves the geometry/material layout, and the bake's visibility hash, unchanged):
  //  - a JSON material whose name equals a loaded file's material replaces it in place;
  //  - one forced on a mesh ("material": NAME) is appended once, at first use.
  std::map<std::string, Material> jsonMaterials;
  if (const json* materials = find(root, "materials")) {
    if (!materials->is_object()) fail("{}: \"materials\" must be an object of name → material", ctx.path);
    for (auto it = materials->begin(); it != materials->end(); ++it)
      jsonMaterials.emplace(it.key(), parseMaterial(ctx, scene, it.key(), it.value()));
  }
  std::map<std::string, uint32_t> appendedMaterials;  // forced JSON materials → scene index
  auto appendPart = [&](Scene part) {
    const size_t materialOffset = scene.materials.size();
    appendScene(scene, std::move(part));
    for (size_t m = materialOffset; m < scene.materials.size(); ++m)
      if (auto it = jsonMaterials.find(scene.materials[m].name); it != jsonMaterials.end())
        scene.materials[m] = it->second;  // textures are shared: their indices are global
  };

  if (boolOr(ctx, root, "include_cornell", false, "top level")) appendPart(makeCornellBox());

  if (const json* meshes = find(root, "meshes")) {
    if (!meshes->is_array()) fail("{}: \"meshes\" must be an array", ctx.path);
    for (size_t i = 0; i < meshes->size(); ++i) {
      const json& entry = (*meshes)[i];
      const std::string where = fmt::format("meshes[{}]", i);
      if (!entry.is_object()) fail("{}: {}: expected an object", ctx.path, where);
      checkKeys(ctx, entry, {"file", "transform", "material"}, where);
      const json* file = find(entry, "file");
      if (!file) fail("{}: {}: missing \"file\"", ctx.path, where);
      const fs::path meshPath = ctx.dir / stringOf(ctx, *file, where + ".file");
      std::string extension = meshPath.extension().string();
      std::transform(extension.begin(), extension.end(), extension.begin(), [](unsigned char c) { return char(std::tolower(c)); });
      if (extension != ".obj" && extension != ".gltf" && extension != ".glb")
        fail("{}: {}.file: '{}' must be .obj, .gltf or .glb", ctx.path, where, meshPath.string());
      Scene part;
      try {
        part = loadScene(meshPath.string());
      } catch (const Error& e) {
        fail("{}: {}: {}", ctx.path, where, e.what());
      }
      if (const json* transform = find(entry, "transform")) transformScene(part, parseTransform(ctx, *transform, where + ".transform"));
      std::optional<uint32_t> forced;
      if (const json* name = find(entry, "material")) {
        const std::string materialName = stringOf(ctx, *name, where + ".material");
        auto it = jsonMaterials.find(materialName);
        if (it == jsonMaterials.end()) fail("{}: {}.material: no material named '{}' in \"materials\"", ctx.path, where, materialName);
        auto [slot, inserted] = appendedMaterials.emplace(materialName, uint32_t(scene.materials.size()));
        if (inserted) scene.materials.push_back(it->second);
        forced = slot->second;
      }
      const size_t meshOffset = scene.meshes.size();
      appendPart(std::move(part));
      if (forced)
        for (size_t m = meshOffset; m < scene.meshes.size(); ++m)
          std::fill(scene.meshes[m].materials.begin(), scene.meshes[m].materials.end(), *forced);
    }
  }

  if (const json* lights = find(root, "lights")) {
    if (!lights->is_array()) fail("{}: \"lights\" must be an array", ctx.path);
    for (size_t i = 0; i < lights->size(); ++i) {
      const json& entry = (*lights)[i];
      const std::string where = fmt::format("lights[{}]", i);
      if (!entry.is_object() || !find(entry, "type")) fail("{}: {}: expected an object with a \"type\"", ctx.path, where);
      const std::string type = stringOf(ctx, entry["type"], where + ".type");
      // Every other key is a parameter of the type (light/lights.h createLight): a number or
      // [x, y, z], angles in degrees.
      LightParameters parameters;
      for (auto it = entry.begin(); it != entry.end(); ++it) {
        if (it.key() == "type") continue;
        const std::string key = where + "." + it.key();
        if (it->is_number()) parameters[it.key()] = number(ctx, *it, key);
        else if (it->is_array() && it->size() == 3) parameters[it.key()] = vec3(ctx, *it, key);
        else fail("{}: {}: expected a number or [x, y, z], got {}", ctx.path, key, it->dump());
      }
      scene.lights.push_back(createLight(type, parameters, fmt::format("{}: {}", ctx.path, where), {.anglesInDegrees = true}));
    }
  }

  if (const json* cameras = find(root, "cameras")) {
    if (!cameras->is_array()) fail("{}: \"cameras\" must be an array", ctx.path);
    for (size_t i = 0; i < cameras->size(); ++i) {
      const json& entry = (*cameras)[i];
      const std::string where = fmt::format("cameras[{}]", i);
      if (!entry.is_object()) fail("{}: {}: expected an object", ctx.path, where);
      checkKeys(ctx, entry, {"name", "eye", "target", "up", "fov", "fstop", "focus_distance", "focal_length", "aspect"}, where);
      CameraDesc camera;
      camera.name = find(entry, "name") ? stringOf(ctx, entry["name"], where + ".name") : fmt::format("camera{}", i);
      camera.eye = vec3Or(ctx, entry, "eye", camera.eye, where);
      camera.target = vec3Or(ctx, entry, "target", camera.target, where);
      camera.up = vec3Or(ctx, entry, "up", camera.up, where);
      camera.fovYDegrees = numberOr(ctx, entry, "fov", camera.fovYDegrees, where);
      camera.fNumber = numberOr(ctx, entry, "fstop", 0.0f, where);
      camera.focusDistance = numberOr(ctx, entry, "focus_distance", glm::length(camera.target - camera.eye), where);
      camera.focalLengthMm = numberOr(ctx, entry, "focal_length", 0.0f, where);
      if (find(entry, "aspect")) camera.aspectRatio = number(ctx, entry["aspect"], where + ".aspect");
      scene.cameras.push_back(camera);
    }
  }

  if (const json* environment = find(root, "environment")) {
    if (!environment->is_object()) fail("{}: \"environment\" must be an object", ctx.path);
    checkKeys(ctx, *environment, {"color", "file", "scale", "rotation"}, "environment");
    scene.environment.constant = colourOr(ctx, *environment, "color", Rgb(0.0f), "environment");
    if (const json* file = find(*environment, "file")) {
      const float scale = numberOr(ctx, *environment, "scale", 1.0f, "environment");
      const float rotation = numberOr(ctx, *environment, "rotation", 0.0f, "environment");
      if (scale < 0.0f) fail("{}: environment.scale must be ≥ 0, got {}", ctx.path, scale);
      const fs::path mapPath = ctx.dir / stringOf(ctx, *file, "environment.file");
      try {
        scene.environment.map = loadEnvironmentMap(mapPath.string(), scale, rotation);
      } catch (const Error& e) {
        fail("{}: environment.file: {}", ctx.path, e.what());
      }
    } else if (find(*environment, "scale") || find(*environment, "rotation")) {
      fail("{}: environment: \"scale\" and \"rotation\" need a \"file\"", ctx.path);
    }
  }
  if (const json* settings = find(root, "settings")) {
    if (!settings->is_object()) fail("{}: \"settings\" must be an object", ctx.path);
    checkKeys(ctx, *settings, {"width", "height", "spp", "camera"}, "settings");
    auto positiveInt = [&](const char* key) -> std::optional<int> {
      const json* value = find(*settings, key);
      if (!value) return std::nullopt;
      if (!value->is_number_integer() || value->get<long long>() <= 0 || value->get<long long>() > (1 << 30))
        fail("{}: settings.{}: expected a positive integer, got {}", ctx.path, key, value->dump());
      return int(value->get<long long>());
    };
    scene.settings.width = positiveInt("width");
    scene.settings.height = positiveInt("height");
    scene.settings.spp = positiveInt("spp");
    if (const json* camera = find(*settings, "camera")) scene.settings.camera = stringOf(ctx, *camera, "settings.camera");
  }
  scene.finalize();
  return scene;
}

}  // namespace

Scene loadJsonScene(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) failFile(path, "{}: cannot open file", path);
  json root;
  try {
    root = json::parse(in);
  } catch (const json::parse_error& e) {
    fail("{}: malformed JSON at byte {}: {}", path, e.byte, e.what());
  } catch (const json::exception& e) {  // e.g. out_of_range: a number beyond a double (1e400)
    fail("{}: malformed JSON: {}", path, e.what());
  }
  const JsonContext ctx{path, fs::path(path).parent_path()};
  try {
    return parseScene(ctx, root);
  } catch (const json::exception& e) {
    fail("{}: {}", path, e.what());
  }
}

}  // namespace pl::detail
