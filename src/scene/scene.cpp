// Scene validation, queries and per-hit surface data. No third-party library here.
#include "scene/scene.h"

#include "core/error.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <string>

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
  for (size_t i = 0; i < scene.lights.size(); ++i) {
    std::visit(
        [&](const auto& light) {
          using T = std::decay_t<decltype(light)>;
          if constexpr (std::is_same_v<T, PointLight>) {
            if (!isFinite(light.position) || !isFinite(light.intensity))
              fail("{}: point light {} has a non-finite position or intensity", scene.sourcePath, i);
          } else if constexpr (std::is_same_v<T, SpotLight>) {
            if (!isFinite(light.position) || !isFinite(light.intensity) || !isFinite(light.direction) ||
                glm::length(light.direction) == 0.0f)
              fail("{}: spot light {} has a non-finite position/intensity or no direction", scene.sourcePath, i);
            if (!(light.innerAngle >= 0.0f && light.innerAngle <= light.outerAngle && light.outerAngle <= kPi))
              fail("{}: spot light {} needs 0 <= inner angle ({}) <= outer angle ({}) <= pi", scene.sourcePath,
                   i, light.innerAngle, light.outerAngle);
          } else {
            if (!isFinite(light.direction) || !isFinite(light.irradiance) || glm::length(light.direction) == 0.0f)
              fail("{}: directional light {} has a non-finite irradiance or no direction", scene.sourcePath, i);
          }
        },
        scene.lights[i]);
  }
}

}  // namespace

/// The model's own validation (bsdf.h bsdfProblem), prefixed with the file and material.
void validateMaterial(const Material& material, const std::string& sourcePath) {
  if (const std::string problem = bsdfProblem(material.bsdf); !problem.empty())
    fail("{}: material '{}': {}", sourcePath, material.name, problem);
}


namespace {

/// The blocks per row of a texture packed in 4×4-texel blocks, and the place of texel (x, y).
int packedBlocksPerRow(int width) { return (width + 3) / 4; }
template <typename Blocks>  // const or not
auto& packedTexel(Blocks& blocks, int blocksPerRow, int x, int y) {
  return blocks[size_t(y >> 2) * size_t(blocksPerRow) + size_t(x >> 2)].texels[(y & 3) * 4 + (x & 3)];
}

/// Texture::packed and palette for `image`, or false (nothing changed) when its channels take
/// more than 256 distinct values. The distinct values go through a small open-addressing hash
/// table keyed by their bits (−0 and +0 stay distinct, so the palette gives back every bit).
bool packTexels(const Image& image, std::vector<Texture::PackedBlock>& packed, std::vector<float>& palette) {
  constexpr uint32_t kSlots = 1024, kEmpty = 0xffffffffu;  // kEmpty: a NaN pattern, never a finite texel
  std::vector<uint32_t> keys(kSlots, kEmpty);
  std::vector<uint8_t> indices(kSlots, 0);
  std::vector<float> values;
  auto indexOf = [&](float v, uint32_t& index) {
    const uint32_t bits = std::bit_cast<uint32_t>(v);
    for (uint32_t slot = (bits * 2654435761u) >> 22;; slot = (slot + 1) & (kSlots - 1)) {
      if (keys[slot] == bits) return index = indices[slot], true;
      if (keys[slot] != kEmpty) continue;
      if (values.size() == 256) return false;
      keys[slot] = bits;
      indices[slot] = uint8_t(values.size());
      index = uint32_t(values.size());
      values.push_back(v);
      return true;
    }
  };
  const int blocksPerRow = packedBlocksPerRow(image.width);
  std::vector<Texture::PackedBlock> blocks(size_t(blocksPerRow) * size_t((image.height + 3) / 4), Texture::PackedBlock{});
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) {
      const Rgb& texel = image.at(x, y);
      uint32_t r, g, b;
      if (!indexOf(texel.r, r) || !indexOf(texel.g, g) || !indexOf(texel.b, b)) return false;
      packedTexel(blocks, blocksPerRow, x, y) = r | g << 8 | b << 16;
    }
  packed = std::move(blocks);
  palette = std::move(values);
  return true;
}

}  // namespace

namespace {

/// The 2×2 texels sample(uv) blends and their weights, or false for a non-finite uv.
struct BilinearFootprint {
  int x0, x1, y0, y1;
  float fx, fy;
};
bool bilinearFootprint(const Image& image, Vec2 uv, BilinearFootprint& f) {
  // Texel (x, y) has its centre at u = (x + 0.5)/W and v = 1 − (y + 0.5)/H (row 0 is the top
  // of the image, v = 0 its bottom). Continuous texel coordinates of uv:
  const float x = uv.x * float(image.width) - 0.5f;
  const float y = (1.0f - uv.y) * float(image.height) - 0.5f;
  if (!std::isfinite(x) || !std::isfinite(y)) return false;
  const float x0f = std::floor(x), y0f = std::floor(y);
  f.fx = x - x0f;
  f.fy = y - y0f;
  // Wrap-around (repeat) with a non-negative modulo. i is a whole number; below 2^30 in
  // magnitude the integer remainder is exactly fmod's (and much cheaper per pixel); fmod
  // keeps huge coordinates in range.
  auto wrap = [](float i, int n) {
    // Most lookups are inside the image (uv in [0, 1)): no division at all (an integer
    // remainder costs tens of cycles, four per footprint).
    if (i >= 0.0f && i < float(n)) return int(i);
    if (std::abs(i) < 0x1p30f) {
      const int k = int(i) % n;
      return k < 0 ? k + n : k;
    }
    float m = std::fmod(i, float(n));
    if (m < 0.0f) m += float(n);
    int k = int(m);
    return k >= n ? 0 : k;
  };
  f.x0 = wrap(x0f, image.width), f.x1 = wrap(x0f + 1.0f, image.width);
  f.y0 = wrap(y0f, image.height), f.y1 = wrap(y0f + 1.0f, image.height);
  return true;
}

}  // namespace

namespace {

/// bilinearFootprint for a uv already reduced to [0, 1)² (Texture::sampleLod): the texel
/// coordinate x = u·W − ½ lies in [−½, W − ½), so ⌊x⌋ ∈ [−1, W − 1] is the truncation of x + 1
/// minus 1, and the wrap is one comparison per index — no floor, no division. Always true
/// (a NaN uv was sent to sample() before).
bool reducedFootprint(const Image& image, Vec2 uv, BilinearFootprint& f) {
  auto axis = [](float x, int n, int& i0, int& i1, float& fraction) {
    const int below = int(x + 1.0f) - 1;  // ⌊x⌋ for x ≥ −1
    fraction = x - float(below);
    i0 = below < 0 ? n - 1 : below;
    i1 = below + 1 >= n ? 0 : below + 1;
  };
  axis(uv.x * float(image.width) - 0.5f, image.width, f.x0, f.x1, f.fx);
  axis((1.0f - uv.y) * float(image.height) - 0.5f, image.height, f.y0, f.y1, f.fy);
  return true;
}

/// The two footprints as function objects of their own types, so that sampleLevel and
/// prefetchLevel inline them (passed as plain functions they were called through a pointer:
/// perf showed the call and reducedFootprint itself at 6 % of a Sponza walk-through frame).
constexpr auto kBilinearFootprint = [](const Image& image, Vec2 uv, BilinearFootprint& f) {
  return bilinearFootprint(image, uv, f);
};
constexpr auto kReducedFootprint = [](const Image& image, Vec2 uv, BilinearFootprint& f) {
  return reducedFootprint(image, uv, f);
};

/// Bilinear, repeat, in one level (its float image, and its packed texels when present), the
/// footprint from `footprint` (kBilinearFootprint or kReducedFootprint); false for a non-finite uv.
template <typename Footprint>
bool sampleLevel(const Image& image, const std::vector<Texture::PackedBlock>& packed, const std::vector<float>& palette,
                 Vec2 uv, Footprint&& footprint, Rgb& result) {
  BilinearFootprint f;
  if (!footprint(image, uv, f)) return false;
  auto bilinear = [&](auto&& texel) {
    const Rgb top = (1.0f - f.fx) * texel(f.x0, f.y0) + f.fx * texel(f.x1, f.y0);
    const Rgb bottom = (1.0f - f.fx) * texel(f.x0, f.y1) + f.fx * texel(f.x1, f.y1);
    return (1.0f - f.fy) * top + f.fy * bottom;
  };
  if (packed.empty()) {
    result = bilinear([&](int tx, int ty) { return image.at(tx, ty); });
    return true;
  }
  const int blocksPerRow = packedBlocksPerRow(image.width);
  const float* values = palette.data();
  result = bilinear([&](int tx, int ty) {
    const uint32_t p = packedTexel(packed, blocksPerRow, tx, ty);
    return Rgb(values[p & 0xffu], values[(p >> 8) & 0xffu], values[(p >> 16) & 0xffu]);
  });
  return true;
}

template <typename Footprint>
void prefetchLevel(const Image& image, const std::vector<Texture::PackedBlock>& packed, Vec2 uv, Footprint&& footprint) {
  BilinearFootprint f;
  if (!footprint(image, uv, f)) return;
  if (packed.empty()) {
    __builtin_prefetch(&image.at(f.x0, f.y0));
    __builtin_prefetch(&image.at(f.x1, f.y1));
    return;
  }
  // Two opposite corners: all the blocks of a footprint that spans one or two (most of them),
  // two of the four at a block corner.
  const int blocksPerRow = packedBlocksPerRow(image.width);
  __builtin_prefetch(&packedTexel(packed, blocksPerRow, f.x0, f.y0));
  __builtin_prefetch(&packedTexel(packed, blocksPerRow, f.x1, f.y1));
}

/// The source texels under each texel of one axis shrunk from n to m ≤ n texels, with their
/// weights: target texel i covers source [i·n/m, (i+1)·n/m), and source texel j gets the
/// length of [j, j+1) inside it divided by n/m (the weights of a target texel sum to 1).
struct BoxTap {
  int source;
  double weight;
};
std::vector<std::vector<BoxTap>> boxTaps(int n, int m) {
  std::vector<std::vector<BoxTap>> taps(size_t(m), std::vector<BoxTap>{});
  const double scale = double(n) / double(m);
  for (int i = 0; i < m; ++i) {
    // Exact in doubles for the sizes of images: i·n and (i+1)·n are integers, divided once.
    const double lo = double(i) * double(n) / double(m), hi = double(i + 1) * double(n) / double(m);
    for (int j = int(std::floor(lo)); j < n && double(j) < hi; ++j) {
      const double overlap = std::min(hi, double(j + 1)) - std::max(lo, double(j));
      if (overlap > 0.0) taps[size_t(i)].push_back({j, overlap / scale});
    }
  }
  return taps;
}

/// The next mip level of `image`: max(1, ⌊W/2⌋) × max(1, ⌊H/2⌋) exact box averages (Texture::mips).
Image downsampleBox(const Image& image) {
  const int width = std::max(1, image.width / 2), height = std::max(1, image.height / 2);
  const auto tapsX = boxTaps(image.width, width), tapsY = boxTaps(image.height, height);
  Image next(width, height);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      glm::dvec3 sum(0.0);
      for (const BoxTap& ty : tapsY[size_t(y)])
        for (const BoxTap& tx : tapsX[size_t(x)]) sum += (ty.weight * tx.weight) * glm::dvec3(image.at(tx.source, ty.source));
      next.at(x, y) = Rgb(sum);
    }
  }
  return next;
}

}  // namespace

Rgb Texture::sample(Vec2 uv) const {
  if (image.empty()) return Rgb(1.0f);
  Rgb result;
  return sampleLevel(image, packed, palette, uv, kBilinearFootprint, result) ? result : average;
}

Rgb Texture::sampleLod(Vec2 uv, float lod) const {
  if (!(lod > 0.0f) || mips.empty()) return sample(uv);  // also NaN
  // uv reduced to [0, 1) once for both levels (repeat), so that each level's footprint is
  // reducedFootprint's few integer operations (per pixel the renderers take four footprints:
  // two levels, sampled and prefetched). Not bit-identical to sample() at level 0 (the
  // rounding of u·W differs), which is why lod ≤ 0 goes through sample().
  uv -= glm::floor(uv);
  if (!(uv.x < 1.0f)) uv.x = 0.0f;  // u − ⌊u⌋ rounds up to 1 for tiny negative u
  if (!(uv.y < 1.0f)) uv.y = 0.0f;
  const size_t coarsest = mips.size();                   // level index of mips.back()
  const float clamped = std::min(lod, float(coarsest));
  const size_t fine = size_t(clamped);  // ⌊lod⌋ ≥ 0
  const float f = clamped - float(fine);
  auto level = [&](size_t l, Rgb& out) {
    return l == 0 ? sampleLevel(image, packed, palette, uv, kReducedFootprint, out)
                  : sampleLevel(mips[l - 1].image, mips[l - 1].packed, mips[l - 1].palette, uv, kReducedFootprint, out);
  };
  Rgb a, b;
  if (!(uv.x >= 0.0f && uv.y >= 0.0f)) return average;  // a non-finite uv
  level(fine, a);
  if (f == 0.0f) return a;
  level(fine + 1, b);  // fine < coarsest here (f > 0 needs clamped < coarsest)
  return (1.0f - f) * a + f * b;
}

void Texture::prefetch(Vec2 uv, float lod) const {
  if (image.empty()) return;
  if (!(lod > 0.0f) || mips.empty()) return prefetchLevel(image, packed, uv, kBilinearFootprint);
  uv -= glm::floor(uv);  // as sampleLod
  if (!(uv.x >= 0.0f && uv.x < 1.0f && uv.y >= 0.0f && uv.y < 1.0f)) return;
  // The finer level of the pair only: the coarser one has a quarter of its texels and is
  // more often cached, and its footprint would cost as much again.
  const size_t fine = size_t(std::min(lod, float(mips.size())));
  if (fine == 0)
    prefetchLevel(image, packed, uv, kReducedFootprint);
  else
    prefetchLevel(mips[fine - 1].image, mips[fine - 1].packed, uv, kReducedFootprint);
}

void Texture::finish(const std::string& sceneSource) {
  if (image.empty() || image.width <= 0 || image.height <= 0 ||
      image.pixels.size() != size_t(image.width) * size_t(image.height))
    fail("{}: texture '{}' is empty", sceneSource, path);
  Rgb sum(0.0f);
  for (const Rgb& texel : image.pixels) {
    if (!isFinite(texel)) fail("{}: texture '{}' contains a non-finite texel", sceneSource, path);
    sum += texel;
  }
  average = sum / float(image.pixels.size());
  packed.clear();
  palette.clear();
  packTexels(image, packed, palette);
  // The mip pyramid, each level from the one before (box averages of linear values); albedo
  // textures only (the light-field renderers' LOD reads no other kind).
  mips.clear();
  if (decode != ImageDecode::Colour) return;
  for (const Image* above = &image; above->width > 1 || above->height > 1; above = &mips.back().image) {
    Level level;
    level.image = downsampleBox(*above);
    packTexels(level.image, level.packed, level.palette);
    mips.push_back(std::move(level));
  }
}

Texture loadTextureFile(const std::string& path, ImageDecode decode) {
  ImageFile file = readImageFile(path, decode);
  Texture texture;
  texture.path = path;
  texture.decode = decode;
  texture.image = std::move(file.image);
  if (!file.ldrBytes.empty())
    texture.encoded = std::make_shared<const std::vector<unsigned char>>(std::move(file.ldrBytes));
  return texture;
}

Texture textureFromEncoded(std::string path, std::vector<unsigned char> bytes, const std::string& label,
                           ImageDecode decode) {
  Texture texture;
  texture.path = std::move(path);
  texture.decode = decode;
  texture.image = decodeLdrImage(bytes, label, decode);
  texture.encoded = std::make_shared<const std::vector<unsigned char>>(std::move(bytes));
  return texture;
}

void Scene::finalize() {
  const std::string& src = sourcePath;
  if (materials.empty()) fail("{}: the scene has no materials", src);

  for (size_t m = 0; m < materials.size(); ++m) {
    const Material& material = materials[m];
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
    validateMaterial(material, sourcePath);
    for (const int texture : {material.albedoTexture, material.alphaTexture, material.normalTexture})
      if (texture < -1 || texture >= int(textures.size()))
        fail("{}: material '{}' refers to texture {} but the scene has {}", src, material.name, texture,
             textures.size());
    if (!(material.alphaFactor >= 0.0f && material.alphaFactor <= 1.0f) ||
        !(material.alphaCutoff >= 0.0f && material.alphaCutoff <= 1.0f))
      fail("{}: material '{}' has alpha {} and alpha cutoff {}; both must be in [0, 1]", src, material.name,
           material.alphaFactor, material.alphaCutoff);
    if (!std::isfinite(material.normalScale))
      fail("{}: material '{}' has a non-finite normal-map scale", src, material.name);
  }
  for (Texture& texture : textures) texture.finish(src);

  size_t totalBefore = 0, dropped = 0;
  for (Mesh& mesh : meshes) {
    const size_t vertexCount = mesh.positions.size();
    if (!mesh.normals.empty() && mesh.normals.size() != vertexCount)
      fail("{}: mesh '{}' has {} normals for {} vertices", src, mesh.name, mesh.normals.size(), vertexCount);
    if (!mesh.uvs.empty() && mesh.uvs.size() != vertexCount)
      fail("{}: mesh '{}' has {} texture coordinates for {} vertices", src, mesh.name, mesh.uvs.size(),
           vertexCount);
    if (mesh.materials.size() != mesh.triangles.size())
      fail("{}: mesh '{}' has {} material indices for {} triangles", src, mesh.name, mesh.materials.size(),
           mesh.triangles.size());
    for (size_t v = 0; v < vertexCount; ++v)
      if (!isFinite(mesh.positions[v]))
        fail("{}: mesh '{}': vertex {} is not finite {}", src, mesh.name, v, vecString(mesh.positions[v]));
    for (size_t v = 0; v < mesh.normals.size(); ++v) {
      Vec3& n = mesh.normals[v];
      if (!isFinite(n)) fail("{}: mesh '{}': normal {} is not finite {}", src, mesh.name, v, vecString(n));
      // Zero normals stay zero: surfaceAt() falls back to the geometric normal there.
      const float length = glm::length(n);
      if (length > 0.0f) n /= length;
    }
    for (size_t v = 0; v < mesh.uvs.size(); ++v)
      if (!isFinite2(mesh.uvs[v]))
        fail("{}: mesh '{}': texture coordinate {} is not finite", src, mesh.name, v);

    totalBefore += mesh.triangles.size();
    size_t kept = 0;
    for (size_t t = 0; t < mesh.triangles.size(); ++t) {
      const UVec3 tri = mesh.triangles[t];
      for (int k = 0; k < 3; ++k)
        if (tri[k] >= vertexCount)
          fail("{}: mesh '{}': triangle {} refers to vertex {} but the mesh has {} vertices", src, mesh.name, t,
               tri[k], vertexCount);
      if (mesh.materials[t] >= materials.size())
        fail("{}: mesh '{}': triangle {} uses material {} but the scene has {}", src, mesh.name, t,
             mesh.materials[t], materials.size());
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
  if (meshes.empty()) {
    if (totalBefore == 0) fail("{}: the scene has no triangles", src);
    fail("{}: all {} triangles are degenerate (zero area)", src, totalBefore);
  }
  if (dropped > 0)
    spdlog::warn("{}: dropped {} degenerate (zero-area) triangle(s) of {}", src, dropped, totalBefore);

  // Embree reads vertex buffers with 16-byte loads, so the last Vec3 needs 4 readable bytes
  // past it: one element of spare capacity (a copy of the Scene does not keep it, so the
  // renderers build their Accel from the Scene object that was finalized or moved).
  for (Mesh& mesh : meshes) mesh.positions.reserve(mesh.positions.size() + 1);

  validateLights(*this);
  for (Light& light : lights) {
    if (auto* spot = std::get_if<SpotLight>(&light)) spot->direction = glm::normalize(spot->direction);
    if (auto* sun = std::get_if<DirectionalLight>(&light)) sun->direction = glm::normalize(sun->direction);
  }
  for (const CameraDesc& camera : cameras) {
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
  if ((settings.width && *settings.width <= 0) || (settings.height && *settings.height <= 0) ||
      (settings.spp && *settings.spp <= 0))
    fail("{}: settings: width, height and spp must be positive", src);
  if (settings.camera) (void)camera(*settings.camera);  // throws, listing the cameras, if unknown
  if (!isFinite(environment.constant) || environment.constant.r < 0.0f || environment.constant.g < 0.0f ||
      environment.constant.b < 0.0f)
    fail("{}: the environment colour {} is invalid", src, vecString(environment.constant));
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
  if (material.normalTexture >= 0 && !mesh.uvs.empty()) {
    const Vec3 p[3] = {p0, p1, p2};
    const Vec2 uv[3] = {mesh.uvs[tri.x], mesh.uvs[tri.y], mesh.uvs[tri.z]};
    hit.shadingNormal = normalMapped(hit.shadingNormal, hit.geometricNormal, p, uv,
                                     scene.textures[size_t(material.normalTexture)].sample(hit.uv), material.normalScale);
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
  if (material.alphaTexture < 0) return material.alphaFactor;
  // Only uv is needed (this runs per candidate hit inside Embree's traversal).
  return material.alphaFactor * scene.textures[size_t(material.alphaTexture)].sample(uvAt(mesh, triangle, barycentrics)).r;
}

Bsdf bsdfAt(const Scene& scene, const SurfaceHit& hit) {
  const Material& material = scene.materials[hit.material];
  if (material.albedoTexture < 0) return material.bsdf;
  const Rgb texel = scene.textures[size_t(material.albedoTexture)].sample(hit.uv);
  return withDiffuseAlbedo(material.bsdf, diffuseAlbedo(material.bsdf) * texel);
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
