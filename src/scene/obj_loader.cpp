// Wavefront OBJ + MTL through tinyobjloader (the only file that includes it).
//
// tinyobjloader is lenient: it reads a non-numeric coordinate as 0 and keeps going. So before
// handing a file to it we scan the OBJ and its MTL files line by line (CRLF tolerated) and
// reject what it would silently misread, with "file:line: problem" messages.
//
// MTL → BSDF mapping (Ka, Pe, Pr, Pm are ignored). A key given twice in one material: the
// last one wins (tinyobjloader overwrites; scene_test checks it).
//  * dielectric (DielectricBsdf) when the material asks for refraction: illum 4, 6 or 7, or no
//    illum at all (tinyobjloader's 0) with Ni > 1 and a non-black Tf (McGuire's
//    CornellBox-Sphere states only Ni and Tf). Smooth; index = Ni (1.5 when Ni is absent or
//    ≤ 1); transmittance (per refraction) = Tf (1 when absent or black). Kd, Ks, Ns and map_Kd
//    are ignored on it (Fresnel gives the reflection).
//  * thin glass (DielectricBsdf, thin) when d < 1 (or Tr > 0) on any other material: a
//    smooth sheet of index Ni (1.5 when absent or ≤ 1) whose one-pass transmittance is
//    (1 − d)·Tf (Tf as above).
//  * mirror when the material is mirror-like: illum 3 or 5 (with non-black Ks), or
//    Ks ≥ 0.9 with Ns ≥ 1000 (a lobe narrower than ~2°), or Kd ≈ 0 (≤ 0.02) with Ks ≥ 0.5
//    and Ns ≥ 1000. Reflectance = Ks; illum 5 ("Fresnel on") → Schlick Fresnel with F0 = Ks.
//  * normalized Blinn-Phong when Ks is non-black: diffuse = Kd, specular = Ks, exponent = Ns.
//    Where Kd + Ks > 1 in a channel both are scaled by 1/(Kd + Ks) there, so that the model
//    conserves energy (bsdf.h), with a warning.
//  * Lambert with albedo Kd otherwise.
//  * Ke → emitted radiance (front side). map_Kd → albedo texture multiplying Kd (a Kd of
//    exactly 0 next to a map_Kd is read as 1, the usual exporter habit), path relative to the
//    MTL file, PNG/JPG decoded from sRGB by readImage().
//  * map_d → alpha mask (Material::alphaTexture, cutoff 0.5): the image's alpha channel, or its
//    first channel when it has none, times d. A scalar d < 1 without map_d is thin glass (above).
//  * norm, or map_bump/bump when there is no norm → tangent-space normal map
//    (Material::normalTexture, read without sRGB decoding), -bm → normalScale. A grey
//    map_bump is a height map: warned about and ignored.
//  * A missing .mtl file: warning, and its materials become a grey Lambert (albedo 0.8).
#include "core/error.h"
#include "core/file_io.h"
#include "scene/loaders.h"

#include <spdlog/spdlog.h>
#include <tiny_obj_loader.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <unordered_map>

namespace pl::detail {

namespace {

namespace fs = std::filesystem;

constexpr float kDefaultGrey = 0.8f;

std::vector<std::string> splitWhitespace(const std::string& line) {
  std::vector<std::string> tokens;
  std::istringstream stream(line);
  std::string token;
  while (stream >> token) tokens.push_back(token);
  return tokens;
}

bool parseFloat(const std::string& text, float& value) {
  const char* end = text.data() + text.size();
  auto [ptr, ec] = std::from_chars(text.data(), end, value);
  return ec == std::errc() && ptr == end;
}

bool parseInt(const std::string& text, long& value) {
  const char* end = text.data() + text.size();
  auto [ptr, ec] = std::from_chars(text.data(), end, value);
  return ec == std::errc() && ptr == end;
}

/// Reads a text file into lines, stripping a trailing '\r' (CRLF files) and comments.
std::vector<std::string> readLines(const std::string& path) {
  requireRegularFile(path);
  std::ifstream in(path, std::ios::binary);
  if (!in) failFile(path, "{}: cannot open file", path);
  std::vector<std::string> lines;
  std::string line;
  while (std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (const size_t hash = line.find('#'); hash != std::string::npos) line.resize(hash);
    lines.push_back(line);
  }
  return lines;
}

/// Checks numeric statements and face indices of an OBJ; returns the mtllib file names.
std::vector<std::string> validateObj(const std::string& path) {
  const std::vector<std::string> lines = readLines(path);
  long positions = 0, texcoords = 0, normals = 0;
  std::vector<std::string> libraries;
  for (size_t i = 0; i < lines.size(); ++i) {
    const size_t lineNumber = i + 1;
    const std::vector<std::string> tokens = splitWhitespace(lines[i]);
    if (tokens.empty()) continue;
    const std::string& keyword = tokens[0];
    if (keyword == "v" || keyword == "vn" || keyword == "vt") {
      const size_t needed = keyword == "vt" ? 2 : 3;
      if (tokens.size() < needed + 1)
        fail("{}:{}: '{}' needs {} numbers, found {}", path, lineNumber, keyword, needed, tokens.size() - 1);
      for (size_t k = 1; k < tokens.size(); ++k) {
        float value;
        if (!parseFloat(tokens[k], value) || !std::isfinite(value))
          fail("{}:{}: '{}' is not a finite number in '{}' statement", path, lineNumber, tokens[k], keyword);
      }
      (keyword == "v" ? positions : keyword == "vn" ? normals : texcoords)++;
    } else if (keyword == "f") {
      if (tokens.size() < 4) fail("{}:{}: a face needs at least 3 vertices, found {}", path, lineNumber, tokens.size() - 1);
      for (size_t k = 1; k < tokens.size(); ++k) {
        // v, v/vt, v//vn or v/vt/vn; negative indices count back from the last element.
        const std::string& token = tokens[k];
        const long counts[3] = {positions, texcoords, normals};
        const char* names[3] = {"vertex", "texture coordinate", "normal"};
        size_t start = 0;
        for (int part = 0; part < 3 && start <= token.size(); ++part) {
          const size_t slash = token.find('/', start);
          const std::string field = token.substr(start, slash == std::string::npos ? std::string::npos : slash - start);
          // Only the texture coordinate of v//vn may be empty: "1/", "1//", "1/2/" name an
          // element without giving its index (tinyobjloader would read it as index 0).
          if (field.empty() && !(part == 1 && slash != std::string::npos))
            fail("{}:{}: empty {} index in '{}'", path, lineNumber, names[part], token);
          if (!field.empty()) {
            long index;
            if (!parseInt(field, index) || index == 0)
              fail("{}:{}: bad face index '{}' in '{}'", path, lineNumber, field, token);
            const long resolved = index > 0 ? index : counts[part] + index + 1;
            if (resolved < 1 || resolved > counts[part])
              fail("{}:{}: face {} index {} out of range ({} defined so far)", path, lineNumber, names[part], index,
                   counts[part]);
          }
          if (slash == std::string::npos) break;
          start = slash + 1;
        }
      }
    } else if (keyword == "mtllib") {
      if (tokens.size() < 2) fail("{}:{}: 'mtllib' without a file name", path, lineNumber);
      for (size_t k = 1; k < tokens.size(); ++k) libraries.push_back(tokens[k]);
    }
  }
  return libraries;
}

/// Checks the numeric statements of an MTL file.
void validateMtl(const std::string& path) {
  const std::vector<std::string> lines = readLines(path);
  bool inMaterial = false;
  for (size_t i = 0; i < lines.size(); ++i) {
    const size_t lineNumber = i + 1;
    const std::vector<std::string> tokens = splitWhitespace(lines[i]);
    if (tokens.empty()) continue;
    const std::string& keyword = tokens[0];
    if (keyword == "newmtl") {
      if (tokens.size() < 2) fail("{}:{}: 'newmtl' without a material name", path, lineNumber);
      inMaterial = true;
      continue;
    }
    static const char* colours[] = {"Ka", "Kd", "Ks", "Ke", "Tf"};
    static const char* scalars[] = {"Ns", "Ni", "d", "Tr", "illum", "Pr", "Pm"};
    size_t minCount = 0, maxCount = 0;
    if (std::find(std::begin(colours), std::end(colours), keyword) != std::end(colours)) minCount = 1, maxCount = 3;
    if (std::find(std::begin(scalars), std::end(scalars), keyword) != std::end(scalars)) minCount = maxCount = 1;
    if (minCount == 0) continue;
    if (!inMaterial) fail("{}:{}: '{}' before any 'newmtl'", path, lineNumber, keyword);
    if (tokens.size() - 1 < minCount)
      fail("{}:{}: '{}' needs {} number(s)", path, lineNumber, keyword, maxCount);
    // Colours may carry a trailing comment-free extra token in some exporters ("Tf 1 1 1 "):
    // only the first maxCount tokens must be numbers, and at least one must be.
    for (size_t k = 1; k < tokens.size() && k <= maxCount; ++k) {
      float value;
      if (!parseFloat(tokens[k], value) || !std::isfinite(value))
        fail("{}:{}: '{}' is not a finite number in '{}' statement", path, lineNumber, tokens[k], keyword);
      if (value < 0.0f && keyword != "illum")
        fail("{}:{}: negative value {} in '{}' statement", path, lineNumber, value, keyword);
    }
  }
}

Rgb rgbOf(const tinyobj::real_t* values) { return Rgb(float(values[0]), float(values[1]), float(values[2])); }

Material convertMaterial(const tinyobj::material_t& mtl, const std::string& mtlPath, Scene& scene,
                         std::map<std::string, int>& textureIndex, const std::vector<fs::path>& mtlDirs) {
  Material material;
  material.name = mtl.name;
  Rgb kd = rgbOf(mtl.diffuse);
  Rgb ks = rgbOf(mtl.specular);
  const float ns = float(mtl.shininess);
  material.emission = rgbOf(mtl.emission);

  const bool hasSpecular = maxComponent(ks) > 0.0f;
  const bool mirrorLike = (hasSpecular && (mtl.illum == 3 || mtl.illum == 5)) ||
                          (maxComponent(ks) >= 0.9f && ns >= 1000.0f) ||
                          (maxComponent(kd) <= 0.02f && maxComponent(ks) >= 0.5f && ns >= 1000.0f);
  const Rgb tf = rgbOf(mtl.transmittance);
  const bool refracts = mtl.illum == 4 || mtl.illum == 6 || mtl.illum == 7 ||
                        (mtl.illum == 0 && mtl.ior > 1.0 && !isBlack(tf));
  const bool thinGlass = !refracts && mtl.dissolve < 1.0f && mtl.alpha_texname.empty();
  if (refracts || thinGlass) {
    DielectricBsdf glass;
    glass.ior = mtl.ior > 1.0 ? float(mtl.ior) : 1.5f;
    glass.transmittance = isBlack(tf) ? Rgb(1.0f) : glm::min(tf, Rgb(1.0f));
    if (thinGlass) {
      glass.thin = true;
      glass.transmittance *= std::clamp(1.0f - float(mtl.dissolve), 0.0f, 1.0f);
    }
    material.bsdf = glass;
    return material;
  }

  // A texture file named in the MTL, resolved against the MTL file's directory (the first
  // library directory holding it), read once per (file, decoding).
  auto texture = [&](const std::string& name, ImageDecode decode, const char* key) {
    fs::path resolved = mtlDirs.empty() ? fs::path(name) : mtlDirs.front() / name;
    for (const fs::path& dir : mtlDirs)
      if (inputFileProblem(dir / name).empty()) {
        resolved = dir / name;
        break;
      }
    const std::string file = resolved.lexically_normal().string();
    if (const std::string problem = inputFileProblem(resolved); !problem.empty())
      fail("{}: material '{}': {} texture file '{}' {}", mtlPath, mtl.name, key, file, problem);
    auto [it, inserted] = textureIndex.try_emplace(fmt::format("{}\n{}", int(decode), file), int(scene.textures.size()));
    if (inserted) {
      scene.textures.push_back(loadTextureFile(file, decode));
    }
    return it->second;
  };

  if (!mtl.diffuse_texname.empty()) {
    if (mirrorLike) spdlog::warn("{}: material '{}': map_Kd ignored on a mirror", mtlPath, mtl.name);
    else {
      material.albedoTexture = texture(mtl.diffuse_texname, ImageDecode::Colour, "map_Kd");
      if (isBlack(kd)) kd = Rgb(1.0f);
    }
  }
  // map_d: an alpha mask, cut out below coverage 0.5 (alpha channel, or the first channel of
  // an image without one).
  if (!mtl.alpha_texname.empty()) {
    material.alphaTexture = texture(mtl.alpha_texname, ImageDecode::Coverage, "map_d");
    material.alphaFactor = std::clamp(float(mtl.dissolve), 0.0f, 1.0f);
  }
  // norm, or map_bump / bump holding a tangent-space normal map (what exporters and Crytek's
  // Sponza put there); -bm scales its x and y. A grey bump map is a height field, which this
  // renderer does not read: warned and ignored.
  const bool normalFromBump = mtl.normal_texname.empty() && !mtl.bump_texname.empty();
  const std::string& normalName = normalFromBump ? mtl.bump_texname : mtl.normal_texname;
  if (!normalName.empty()) {
    const tinyobj::texture_option_t& option = normalFromBump ? mtl.bump_texopt : mtl.normal_texopt;
    const int index = texture(normalName, ImageDecode::Data, normalFromBump ? "map_bump" : "norm");
    const Image& image = scene.textures[size_t(index)].image;
    const bool grey = std::all_of(image.pixels.begin(), image.pixels.end(),
                                  [](const Rgb& p) { return p.r == p.g && p.g == p.b; });
    if (grey) {
      spdlog::warn("{}: material '{}': '{}' is a grey height (bump) map; only normal maps are read, ignored", mtlPath,
                   mtl.name, normalName);
    } else {
      material.normalTexture = index;
      material.normalScale = float(option.bump_multiplier);
    }
  }

  if (mirrorLike) {
    material.bsdf = MirrorBsdf{glm::min(ks, Rgb(1.0f)), mtl.illum == 5};
  } else if (hasSpecular) {
    const Rgb sum = kd + ks;
    if (maxComponent(sum) > 1.0f) {
      spdlog::warn("{}: material '{}': Kd + Ks = ({}, {}, {}) exceeds 1; scaled down to conserve energy", mtlPath,
                   mtl.name, sum.r, sum.g, sum.b);
      for (int c = 0; c < 3; ++c)
        if (sum[c] > 1.0f) kd[c] /= sum[c], ks[c] /= sum[c];
    }
    material.bsdf = BlinnPhongBsdf{kd, ks, std::max(ns, 0.0f)};
  } else {
    if (maxComponent(kd) > 1.0f)
      spdlog::warn("{}: material '{}': Kd ({}, {}, {}) exceeds 1; clamped to conserve energy", mtlPath, mtl.name,
                   kd.r, kd.g, kd.b);
    material.bsdf = LambertBsdf{glm::min(kd, Rgb(1.0f))};
  }
  return material;
}

struct VertexKey {
  int position, texcoord, normal;
  bool operator==(const VertexKey&) const = default;
};
struct VertexKeyHash {
  size_t operator()(const VertexKey& k) const {
    return std::hash<int64_t>()((int64_t(k.position) * 73856093) ^ (int64_t(k.texcoord) * 19349663) ^
                                (int64_t(k.normal) * 83492791));
  }
};

}  // namespace

Scene loadObj(const std::string& path) {
  const fs::path objPath(path);
  const fs::path objDir = objPath.parent_path();
  const std::vector<std::string> libraries = validateObj(path);

  std::vector<fs::path> mtlDirs;
  std::string mtlNames;
  for (const std::string& library : libraries) {
    const fs::path mtlPath = objDir / library;
    if (const std::string problem = inputFileProblem(mtlPath); !problem.empty()) {
      spdlog::warn("{}: material library '{}' {}; its materials become grey Lambert", path, mtlPath.string(),
                   problem);
      continue;
    }
    validateMtl(mtlPath.string());
    mtlDirs.push_back(mtlPath.parent_path());
    mtlNames += (mtlNames.empty() ? "" : ", ") + mtlPath.string();
  }

  tinyobj::ObjReaderConfig config;
  config.triangulate = true;
  config.vertex_color = false;
  config.mtl_search_path = objDir.string();
  tinyobj::ObjReader reader;
  if (!reader.ParseFromFile(path, config)) fail("{}: {}", path, reader.Error());
  std::string attribWarning = reader.Warning();
  while (!attribWarning.empty() && std::isspace(static_cast<unsigned char>(attribWarning.back()))) attribWarning.pop_back();
  // Missing libraries were reported above; other tinyobjloader warnings are passed on.
  if (!attribWarning.empty() && attribWarning.find("not found") == std::string::npos)
    spdlog::warn("{}: {}", path, attribWarning);

  const tinyobj::attrib_t& attrib = reader.GetAttrib();
  Scene scene;
  scene.sourcePath = path;
  std::map<std::string, int> textureIndex;
  const std::string mtlLabel = mtlNames.empty() ? path : mtlNames;
  for (const tinyobj::material_t& mtl : reader.GetMaterials())
    scene.materials.push_back(convertMaterial(mtl, mtlLabel, scene, textureIndex, mtlDirs));
  int defaultMaterial = -1;  // added on first use by a face without a (known) material

  for (const tinyobj::shape_t& shape : reader.GetShapes()) {
    Mesh mesh;
    mesh.name = shape.name;
    const tinyobj::mesh_t& objMesh = shape.mesh;
    bool anyNormal = false, anyTexcoord = false;
    for (const tinyobj::index_t& index : objMesh.indices) {
      anyNormal |= index.normal_index >= 0;
      anyTexcoord |= index.texcoord_index >= 0;
    }
    std::unordered_map<VertexKey, uint32_t, VertexKeyHash> vertexOf;
    size_t offset = 0;
    for (size_t face = 0; face < objMesh.num_face_vertices.size(); ++face) {
      const unsigned count = objMesh.num_face_vertices[face];
      if (count != 3) fail("{}: face {} of '{}' has {} vertices after triangulation", path, face, shape.name, count);
      UVec3 triangle;
      for (unsigned k = 0; k < 3; ++k) {
        const tinyobj::index_t& index = objMesh.indices[offset + k];
        const VertexKey key{index.vertex_index, index.texcoord_index, index.normal_index};
        auto [it, inserted] = vertexOf.try_emplace(key, uint32_t(mesh.positions.size()));
        if (inserted) {
          const auto p = size_t(index.vertex_index);
          if (index.vertex_index < 0 || 3 * p + 2 >= attrib.vertices.size())
            fail("{}: shape '{}': vertex index {} out of range", path, shape.name, index.vertex_index);
          mesh.positions.emplace_back(attrib.vertices[3 * p], attrib.vertices[3 * p + 1], attrib.vertices[3 * p + 2]);
          if (anyNormal) {
            // Faces without normals get zero ones: surfaceAt() then uses the geometric normal.
            Vec3 n(0.0f);
            if (index.normal_index >= 0) {
              const auto q = size_t(index.normal_index);
              if (3 * q + 2 >= attrib.normals.size())
                fail("{}: shape '{}': normal index {} out of range", path, shape.name, index.normal_index);
              n = Vec3(attrib.normals[3 * q], attrib.normals[3 * q + 1], attrib.normals[3 * q + 2]);
            }
            mesh.normals.push_back(n);
          }
          if (anyTexcoord) {
            Vec2 uv(0.0f);
            if (index.texcoord_index >= 0) {
              const auto q = size_t(index.texcoord_index);
              if (2 * q + 1 >= attrib.texcoords.size())
                fail("{}: shape '{}': texture coordinate index {} out of range", path, shape.name, index.texcoord_index);
              uv = Vec2(attrib.texcoords[2 * q], attrib.texcoords[2 * q + 1]);
            }
            mesh.uvs.push_back(uv);
          }
        }
        triangle[int(k)] = it->second;
      }
      offset += 3;
      int material = face < objMesh.material_ids.size() ? objMesh.material_ids[face] : -1;
      if (material < 0 || size_t(material) >= scene.materials.size()) {
        if (defaultMaterial < 0) {
          defaultMaterial = int(scene.materials.size());
          scene.materials.push_back({.name = "default", .bsdf = LambertBsdf{Rgb(kDefaultGrey)}});
        }
        material = defaultMaterial;
      }
      mesh.triangles.push_back(triangle);
      mesh.materials.push_back(uint32_t(material));
    }
    if (!mesh.triangles.empty()) scene.meshes.push_back(std::move(mesh));
  }
  if (scene.materials.empty()) scene.materials.push_back({.name = "default", .bsdf = LambertBsdf{Rgb(kDefaultGrey)}});
  scene.finalize();
  return scene;
}

}  // namespace pl::detail
