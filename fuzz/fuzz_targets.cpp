// The fuzz targets of fuzz_targets.h: each writes its input where the reader expects it and
// calls the reader the command-line program uses.
#include "fuzz/fuzz_targets.h"

#include <spdlog/spdlog.h>
#include <stdlib.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "camera/camera_path.h"
#include "core/error.h"
#include "core/file_io.h"
#include "core/hash.h"
#include "image/image.h"
#include "bake/first_shot.h"
#include "plf/plf_file.h"
#include "plf/plt_file.h"
#include "plf/plv_file.h"
#include "scene/scene.h"

namespace pl::fuzz {

namespace {

namespace fs = std::filesystem;

/// A private directory under $TMPDIR for the files of one input, removed at normal exit.
class TemporaryDirectory {
 public:
  TemporaryDirectory() {
    std::string pattern = (fs::temp_directory_path() / "plenoptic-fuzz-XXXXXX").string();
    if (!mkdtemp(pattern.data())) fail("{}: cannot create a temporary directory", pattern);
    path_ = pattern;
  }
  ~TemporaryDirectory() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

/// A triangle with normals, uvs and a material library, which fuzzed JSON scenes may refer
/// to as "mesh.obj" (the JSON seeds do).
constexpr std::string_view kHelperObj =
    "mtllib mesh.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nvn 0 0 1\nusemtl white\n"
    "f 1/1/1 2/2/1 3/3/1\n";
constexpr std::string_view kHelperMtl = "newmtl white\nKd 0.5 0.5 0.5\nKs 0.1 0.1 0.1\nNs 20\n";

const fs::path& scratch() {
  static const TemporaryDirectory directory = [] {
    spdlog::set_level(spdlog::level::off);  // the loaders' warnings would only slow fuzzing down
    return TemporaryDirectory();
  }();
  return directory.path();
}

/// Writes `bytes` as `name` in the scratch directory and returns its path.
std::string putFile(const char* name, std::string_view bytes) {
  const std::string path = (scratch() / name).string();
  writeFileBytes(path, bytes.data(), bytes.size());
  return path;
}
std::string putFile(const char* name, std::span<const uint8_t> bytes) {
  return putFile(name, std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
}
void removeFile(const char* name) {
  std::error_code ec;
  fs::remove(scratch() / name, ec);
}

uint64_t loadU64(const uint8_t* p) {
  uint64_t v;
  std::memcpy(&v, p, 8);
  return v;
}
void storeU64(uint8_t* p, uint64_t v) { std::memcpy(p, &v, 8); }

// ---- targets ----

void runObj(std::span<const uint8_t> input) {
  const std::string_view text(reinterpret_cast<const char*>(input.data()), input.size());
  const size_t split = text.find(kObjMtlSeparator);
  if (split == std::string_view::npos) {
    removeFile("scene.mtl");
  } else {
    putFile("scene.mtl", text.substr(split + kObjMtlSeparator.size()));
  }
  loadScene(putFile("scene.obj", text.substr(0, split)));
}

void runGltf(std::span<const uint8_t> input) {
  const bool binary = input.size() >= 4 && std::memcmp(input.data(), "glTF", 4) == 0;
  removeFile(binary ? "scene.gltf" : "scene.glb");  // the previous input's, which this one could refer to
  loadScene(putFile(binary ? "scene.glb" : "scene.gltf", input));
}

void runJsonScene(std::span<const uint8_t> input) {
  putFile("mesh.obj", kHelperObj);
  putFile("mesh.mtl", kHelperMtl);
  loadScene(putFile("scene.json", input));
}

void runCameraPath(std::span<const uint8_t> input) {
  parseCameraPath(std::string(reinterpret_cast<const char*>(input.data()), input.size()), "path.json");
}

void runHdr(std::span<const uint8_t> input) { readImage(putFile("image.hdr", input)); }

void runExr(std::span<const uint8_t> input) { readImage(putFile("image.exr", input)); }

void runPlf(std::span<const uint8_t> input) {
  const std::string path = putFile("field.plf", input);
  readLightFieldInfo(path);
  readLightField(path);
}

/// .plf with its integrity fields made to match the mutated bytes: every section checksum
/// whose section lies inside the input, the total size and the header hash (see plf_file.h
/// for the layout), so that mutations reach the decoders behind the checks.
void runPlfFixed(std::span<const uint8_t> input) {
  std::vector<uint8_t> bytes(input.begin(), input.end());
  if (bytes.size() >= kPlfHeaderSize) {
    uint32_t sectionCount;
    std::memcpy(&sectionCount, bytes.data() + 12, 4);
    const size_t tableEntries = std::min<size_t>(sectionCount, (bytes.size() - kPlfHeaderSize) / kPlfSectionEntrySize);
    for (size_t s = 0; s < tableEntries; ++s) {
      uint8_t* entry = bytes.data() + kPlfHeaderSize + s * kPlfSectionEntrySize;
      const uint64_t offset = loadU64(entry + 8), storedSize = loadU64(entry + 16);
      if (offset <= bytes.size() && storedSize <= bytes.size() - offset)
        storeU64(entry + 32, xxh64(bytes.data() + offset, storedSize));
    }
    storeU64(bytes.data() + 16, bytes.size());
    if (tableEntries == sectionCount) {
      Xxh64Stream hash;
      hash.update(bytes.data(), 24);
      hash.update(bytes.data() + kPlfHeaderSize, tableEntries * kPlfSectionEntrySize);
      storeU64(bytes.data() + 24, hash.digest());
    }
  }
  runPlf(bytes);
}

// .plv header (plf/plv_file.h): magic 8, version 4, gridSide 4, hash 8 at 16, tixelCount,
// entryCount, extraCount, payloadHash 8 at 48; payload from 56.
constexpr size_t kPlvHashOffset = 16, kPlvPayloadHashOffset = 48, kPlvHeaderBytes = 56;

void runPlv(std::span<const uint8_t> input) {
  // The expected hash is the file's own, so the reader goes past the staleness check.
  const uint64_t expected = input.size() >= kPlvHashOffset + 8 ? loadU64(input.data() + kPlvHashOffset) : 0;
  VisibilityField field;
  std::string why;
  readVisibility(putFile("field.plv", input), expected, field, &why);
}

/// .plv with the payload checksum recomputed over the mutated payload.
void runPlvFixed(std::span<const uint8_t> input) {
  std::vector<uint8_t> bytes(input.begin(), input.end());
  if (bytes.size() >= kPlvHeaderBytes)
    storeU64(bytes.data() + kPlvPayloadHashOffset, xxh64(bytes.data() + kPlvHeaderBytes, bytes.size() - kPlvHeaderBytes));
  runPlv(bytes);
}

// .plt header (plf/plt_file.h): magic 8, version 4, array count 4, hash 8 at 16, tixel count,
// payloadHash 8 at 32, key count 8; payload from 48.
constexpr size_t kPltHashOffset = 16, kPltPayloadHashOffset = 32, kPltHeaderBytes = 48;

void runPlt(std::span<const uint8_t> input) {
  // The expected hash is the file's own, so the reader goes past the staleness check.
  const uint64_t expected = input.size() >= kPltHashOffset + 8 ? loadU64(input.data() + kPltHashOffset) : 0;
  TixelSetupFile file;
  std::string why;
  readTixelSetupFile(putFile("setup.plt", input), expected, file, &why);
}

/// .plt with the payload checksum recomputed over the mutated payload.
void runPltFixed(std::span<const uint8_t> input) {
  std::vector<uint8_t> bytes(input.begin(), input.end());
  if (bytes.size() >= kPltHeaderBytes)
    storeU64(bytes.data() + kPltPayloadHashOffset, xxh64(bytes.data() + kPltHeaderBytes, bytes.size() - kPltHeaderBytes));
  runPlt(bytes);
}

// .pls header (bake/first_shot.h): magic 8, version 4, light count 4 at 12, hash 8 at 16, key 8
// at 24, value count 8 at 32, flags 8 at 40, payloadHash 8 at 48; payload from 56.
constexpr size_t kPlsPayloadHashOffset = 48, kPlsHeaderBytes = 56;

void runPls(std::span<const uint8_t> input) {
  // The expected hash, key and counts are the file's own, so the reader goes past the
  // staleness checks (a relighting passes its light field's).
  if (input.size() < kPlsHeaderBytes) {
    FirstShotBySource shot;
    readFirstShot(putFile("shot.pls", input), 0, 0, 0, 0, false, shot);
    return;
  }
  uint32_t lights = 0;
  std::memcpy(&lights, input.data() + 12, 4);
  FirstShotBySource shot;
  std::string why;
  readFirstShot(putFile("shot.pls", input), loadU64(input.data() + 16), loadU64(input.data() + 24), lights,
                loadU64(input.data() + 32), loadU64(input.data() + 40) == 1, shot, &why);
}

/// .pls with the payload checksum recomputed over the mutated payload.
void runPlsFixed(std::span<const uint8_t> input) {
  std::vector<uint8_t> bytes(input.begin(), input.end());
  if (bytes.size() >= kPlsHeaderBytes)
    storeU64(bytes.data() + kPlsPayloadHashOffset, xxh64(bytes.data() + kPlsHeaderBytes, bytes.size() - kPlsHeaderBytes));
  runPls(bytes);
}

constexpr FuzzTarget kTargets[] = {
    {"obj", "Wavefront OBJ + MTL scene (loadScene)", runObj},
    {"gltf", "glTF 2.0 scene, .gltf or .glb by the magic (loadScene)", runGltf},
    {"json_scene", "JSON scene description (loadScene)", runJsonScene},
    {"camera_path", "--path camera-path JSON (parseCameraPath)", runCameraPath},
    {"hdr", "Radiance .hdr image (readImage)", runHdr},
    {"exr", "OpenEXR image (readImage)", runExr},
    {"plf", "light field .plf (readLightFieldInfo, readLightField)", runPlf},
    {"plf_fixed", "light field .plf with checksums recomputed after mutation", runPlfFixed},
    {"plv", "visibility field .plv (readVisibility)", runPlv},
    {"plv_fixed", "visibility field .plv with the payload checksum recomputed after mutation", runPlvFixed},
    {"plt", "tixel-setup file .plt (readTixelSetupFile)", runPlt},
    {"plt_fixed", "tixel-setup file .plt with the payload checksum recomputed after mutation", runPltFixed},
    {"pls", "first shot by source .pls (readFirstShot)", runPls},
    {"pls_fixed", "first shot by source .pls with the payload checksum recomputed after mutation", runPlsFixed},
};

}  // namespace

std::span<const FuzzTarget> fuzzTargets() { return kTargets; }

const FuzzTarget* findFuzzTarget(std::string_view name) {
  for (const FuzzTarget& target : kTargets)
    if (name == target.name) return &target;
  return nullptr;
}

void runFuzzInput(const FuzzTarget& target, std::span<const uint8_t> input) {
  try {
    target.run(input);
  } catch (const Error&) {
    // The expected outcome for bad input.
  }
}

}  // namespace pl::fuzz
