// Reading and writing environment maps in lat-long, six-face and cross layouts (env.h).
// Pixel IO itself is image/image.h; this file only knows layouts.
#include "core/error.h"
#include "env/env.h"

#include <fmt/format.h>

#include <algorithm>
#include <filesystem>

namespace pl {

namespace fs = std::filesystem;

EnvLayout parseEnvLayout(const std::string& name) {
  if (name == "latlong") return EnvLayout::LatLong;
  if (name == "cube") return EnvLayout::Cube;
  if (name == "cross") return EnvLayout::HorizontalCross;
  if (name == "vcross") return EnvLayout::VerticalCross;
  fail("unknown environment layout '{}' (expected latlong, cube, cross or vcross)", name);
}

namespace {

constexpr const char* kFacePlaceholder = "{face}";

std::string replaceFace(const std::string& pattern, const char* face) {
  std::string s = pattern;
  const size_t at = s.find(kFacePlaceholder);
  s.replace(at, std::string(kFacePlaceholder).size(), face);
  return s;
}

// Where each face sits in a cross, in units of N: (column, row), and whether it is rotated
// by 180° (only −Z in the vertical cross). Index = CubeFace.
struct CrossCell {
  int column, row;
  bool rotated;
};
constexpr std::array<CrossCell, 6> kHorizontalCross = {{{2, 1, false},
                                                        {0, 1, false},
                                                        {1, 0, false},
                                                        {1, 2, false},
                                                        {1, 1, false},
                                                        {3, 1, false}}};
constexpr std::array<CrossCell, 6> kVerticalCross = {{{2, 1, false},
                                                      {0, 1, false},
                                                      {1, 0, false},
                                                      {1, 2, false},
                                                      {1, 1, false},
                                                      {1, 3, true}}};

CubeMap facesToCube(const std::array<std::string, 6>& paths) {
  std::array<Image, 6> faces;
  for (int f = 0; f < 6; ++f) {
    faces[size_t(f)] = readImage(paths[size_t(f)]);
    const Image& img = faces[size_t(f)];
    if (img.width != img.height)
      fail("{}: cube face is not square ({}×{})", paths[size_t(f)], img.width, img.height);
    if (img.width != faces[0].width)
      fail("{}: cube face is {}×{} but {} is {}×{}; all six faces must have the same size", paths[size_t(f)],
           img.width, img.height, paths[0], faces[0].width, faces[0].height);
  }
  CubeMap cube(0);
  cube.size = faces[0].width;
  cube.faces = std::move(faces);
  return cube;
}

std::array<std::string, 6> facePathsInDirectory(const std::string& dir) {
  std::array<std::string, 6> paths;
  for (int f = 0; f < 6; ++f) {
    // Every readable image type (image.h), HDR first: the first that exists is the face.
    std::string tried;
    auto look = [&](std::string_view ext) {
      tried += tried.empty() ? std::string(ext) : "/" + std::string(ext);
      if (!paths[size_t(f)].empty()) return;
      const fs::path candidate = fs::path(dir) / (std::string(kCubeFaceNames[size_t(f)]) + std::string(ext));
      std::error_code ec;
      if (fs::exists(candidate, ec)) paths[size_t(f)] = candidate.string();
    };
    for (std::string_view ext : kHdrImageExtensions) look(ext);
    for (std::string_view ext : kLdrImageExtensions) look(ext);
    if (paths[size_t(f)].empty())
      fail("{}: cube face '{}' missing (looked for {}{})", dir, kCubeFaceNames[size_t(f)], kCubeFaceNames[size_t(f)],
           tried);
  }
  return paths;
}

}  // namespace

CubeMap crossToCube(const Image& image, const std::string& nameForErrors) {
  const bool horizontal = image.width * 3 == image.height * 4;
  const bool vertical = image.width * 4 == image.height * 3;
  if (!horizontal && !vertical)
    fail("{}: {}×{} is not a cross layout (a horizontal cross is 4N×3N, a vertical one 3N×4N)", nameForErrors,
         image.width, image.height);
  const int n = horizontal ? image.width / 4 : image.width / 3;
  if (n < 1) fail("{}: image too small for a cross layout ({}×{})", nameForErrors, image.width, image.height);
  const auto& cells = horizontal ? kHorizontalCross : kVerticalCross;
  CubeMap cube(n);
  for (int f = 0; f < 6; ++f) {
    const CrossCell c = cells[size_t(f)];
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        const int sx = c.rotated ? n - 1 - x : x, sy = c.rotated ? n - 1 - y : y;
        cube.faces[size_t(f)].at(x, y) = image.at(c.column * n + sx, c.row * n + sy);
      }
  }
  return cube;
}

Image cubeToCross(const CubeMap& cube, bool vertical) {
  const int n = cube.size;
  const auto& cells = vertical ? kVerticalCross : kHorizontalCross;
  Image out(vertical ? 3 * n : 4 * n, vertical ? 4 * n : 3 * n, Rgb(0.0f));
  for (int f = 0; f < 6; ++f) {
    const CrossCell c = cells[size_t(f)];
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        const int sx = c.rotated ? n - 1 - x : x, sy = c.rotated ? n - 1 - y : y;
        out.at(c.column * n + sx, c.row * n + sy) = cube.faces[size_t(f)].at(x, y);
      }
  }
  return out;
}

EnvImage loadEnvironment(const std::string& path) {
  if (path.find(kFacePlaceholder) != std::string::npos) {
    std::array<std::string, 6> paths;
    for (int f = 0; f < 6; ++f) {
      paths[size_t(f)] = replaceFace(path, kCubeFaceNames[size_t(f)]);
      std::error_code ec;
      if (!fs::exists(paths[size_t(f)], ec))
        fail("{}: cube face '{}' missing ({} does not exist)", path, kCubeFaceNames[size_t(f)], paths[size_t(f)]);
    }
    return facesToCube(paths);
  }
  std::error_code ec;
  if (fs::is_directory(path, ec)) return facesToCube(facePathsInDirectory(path));
  if (!fs::exists(path, ec)) failFile(path, "{}: no such file or directory", path);

  Image image = readImage(path);
  if (image.width == 2 * image.height && image.height > 0) return LatLongMap{std::move(image)};
  if (image.width * 3 == image.height * 4 || image.width * 4 == image.height * 3) return crossToCube(image, path);
  fail("{}: cannot tell the environment layout from the size {}×{} (expected 2:1 lat-long, 4:3 horizontal "
       "cross or 3:4 vertical cross)",
       path, image.width, image.height);
}

void saveEnvironment(const std::string& path, const EnvImage& env, EnvLayout layout) {
  switch (layout) {
    case EnvLayout::LatLong: {
      if (const auto* ll = std::get_if<LatLongMap>(&env)) {
        writeHdrImage(path, ll->image);
      } else {
        writeHdrImage(path, toLatLong(env, equivalentLatLongHeight(env)).image);
      }
      return;
    }
    case EnvLayout::HorizontalCross:
    case EnvLayout::VerticalCross: {
      const bool vertical = layout == EnvLayout::VerticalCross;
      if (const auto* cube = std::get_if<CubeMap>(&env)) {
        writeHdrImage(path, cubeToCross(*cube, vertical));
      } else {
        writeHdrImage(path, cubeToCross(toCube(env, equivalentFaceSize(env)), vertical));
      }
      return;
    }
    case EnvLayout::Cube: {
      const CubeMap cube = std::holds_alternative<CubeMap>(env) ? std::get<CubeMap>(env)
                                                                 : toCube(env, equivalentFaceSize(env));
      std::string pattern = path;
      if (pattern.find(kFacePlaceholder) == std::string::npos) {
        std::error_code ec;
        fs::create_directories(path, ec);
        if (ec) fail("{}: cannot create directory for the cube faces: {}", path, ec.message());
        pattern = (fs::path(path) / "{face}.hdr").string();
      } else {
        const fs::path parent = fs::path(pattern).parent_path();
        std::error_code ec;
        if (!parent.empty()) fs::create_directories(parent, ec);
      }
      for (int f = 0; f < 6; ++f) writeHdrImage(replaceFace(pattern, kCubeFaceNames[size_t(f)]), cube.faces[size_t(f)]);
      return;
    }
  }
}

}  // namespace pl
