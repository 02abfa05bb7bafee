// Compressed glTF meshes (gltf_compression.h): a quad encoded here with the libraries' own
// encoders — Draco (KHR_draco_mesh_compression) and meshoptimizer (EXT_meshopt_compression) —
// loads as the same two triangles as the uncompressed quad, and a damaged buffer is refused
// with an error naming the file and the mesh or buffer view. Built only where both libraries are.
#include "core/error.h"
#include "scene/scene.h"

#include <draco/compression/encode.h>
#include <draco/mesh/triangle_soup_mesh_builder.h>
#include <gtest/gtest.h>
#include <meshoptimizer.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include "support/expect_error.h"
#include "support/expect_vec3.h"

namespace pl {
namespace {

namespace fs = std::filesystem;

constexpr float kTight = 1e-6f;

// The quad (0,0)–(2,1) in z = 0, its glTF uvs and its triangles.
const float kPositions[4][3] = {{0, 0, 0}, {2, 0, 0}, {2, 1, 0}, {0, 1, 0}};
const float kUvs[4][2] = {{0, 1}, {1, 1}, {1, 0}, {0, 0}};
const uint32_t kIndices[6] = {0, 1, 2, 0, 2, 3};

fs::path scratch(const std::string& name) {
  const fs::path dir = fs::path(testing::TempDir()) / ("pl_gltf_compression_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

void writeBytes(const fs::path& path, const std::vector<unsigned char>& bytes) {
  std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
}

using test_support::expectError;

/// The loaded quad: two triangles of total area 2 inside the quad's bounds, uv = position / (2, 1).
void expectQuad(const Scene& scene) {
  ASSERT_EQ(scene.meshes.size(), 1u);
  const Mesh& mesh = scene.meshes[0];
  ASSERT_EQ(mesh.triangles.size(), 2u);
  float area = 0.0f;
  for (uint32_t t = 0; t < 2; ++t) {
    const UVec3 tri = mesh.triangles[t];
    area += 0.5f * glm::length(glm::cross(mesh.positions[tri.y] - mesh.positions[tri.x], mesh.positions[tri.z] - mesh.positions[tri.x]));
    EXPECT_GT(triangleNormal(mesh, t).z, 0.0f);  // the winding kept
  }
  EXPECT_NEAR(area, 2.0f, kTight);
  ASSERT_EQ(mesh.uvs.size(), mesh.positions.size());
  for (size_t v = 0; v < mesh.positions.size(); ++v)
    EXPECT_VEC3_NEAR(Vec3(mesh.uvs[v], 0.0f), Vec3(mesh.positions[v].x / 2.0f, mesh.positions[v].y, 0.0f), kTight);
}

/// The quad as a Draco mesh (no quantization: exact floats), and the unique ids of its
/// position and uv attributes.
std::vector<unsigned char> dracoQuad(int& positionId, int& uvId) {
  draco::TriangleSoupMeshBuilder builder;
  builder.Start(2);
  const int position = builder.AddAttribute(draco::GeometryAttribute::POSITION, 3, draco::DT_FLOAT32);
  const int uv = builder.AddAttribute(draco::GeometryAttribute::TEX_COORD, 2, draco::DT_FLOAT32);
  for (int f = 0; f < 2; ++f) {
    const uint32_t* t = kIndices + 3 * f;
    builder.SetAttributeValuesForFace(position, draco::FaceIndex(f), kPositions[t[0]], kPositions[t[1]], kPositions[t[2]]);
    builder.SetAttributeValuesForFace(uv, draco::FaceIndex(f), kUvs[t[0]], kUvs[t[1]], kUvs[t[2]]);
  }
  const std::unique_ptr<draco::Mesh> mesh = builder.Finalize();
  positionId = int(mesh->attribute(position)->unique_id());
  uvId = int(mesh->attribute(uv)->unique_id());
  draco::Encoder encoder;
  encoder.SetEncodingMethod(draco::MESH_SEQUENTIAL_ENCODING);
  draco::EncoderBuffer buffer;
  EXPECT_TRUE(encoder.EncodeMeshToBuffer(*mesh, &buffer).ok());
  return {buffer.data(), buffer.data() + buffer.size()};
}

/// A .glb of `json` and `bin`: header, JSON chunk, BIN chunk, each chunk padded to 4 bytes.
std::vector<unsigned char> glbBytes(std::string json, std::vector<unsigned char> bin) {
  while (json.size() % 4 != 0) json += ' ';
  while (bin.size() % 4 != 0) bin.push_back(0);
  std::vector<unsigned char> glb;
  auto u32 = [&](uint32_t v) { glb.insert(glb.end(), reinterpret_cast<unsigned char*>(&v), reinterpret_cast<unsigned char*>(&v) + 4); };
  glb.insert(glb.end(), {'g', 'l', 'T', 'F'});
  u32(2);
  u32(uint32_t(12 + 8 + json.size() + 8 + bin.size()));
  u32(uint32_t(json.size()));
  glb.insert(glb.end(), {'J', 'S', 'O', 'N'});
  glb.insert(glb.end(), json.begin(), json.end());
  u32(uint32_t(bin.size()));
  glb.insert(glb.end(), {'B', 'I', 'N', '\0'});
  glb.insert(glb.end(), bin.begin(), bin.end());
  return glb;
}

/// The Draco quad as draco.gltf (the stream in draco.bin), or with `binary` as draco.glb (the
/// stream in its binary chunk). Its index accessor has no buffer view, as exporters write it.
std::string dracoGltf(const fs::path& dir, const std::vector<unsigned char>& bytes, int positionId, int uvId,
                      bool binary = false) {
  writeBytes(dir / "draco.bin", bytes);
  const std::string uri = binary ? "" : R"(, "uri": "draco.bin")";
  std::string text = R"({"asset": {"version": "2.0"},
    "extensionsUsed": ["KHR_draco_mesh_compression"], "extensionsRequired": ["KHR_draco_mesh_compression"],
    "buffers": [{"byteLength": )" + std::to_string(bytes.size()) + uri + R"(}],
    "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": )" + std::to_string(bytes.size()) + R"(}],
    "accessors": [{"componentType": 5126, "count": 4, "type": "VEC3", "min": [0,0,0], "max": [2,1,0]},
                  {"componentType": 5126, "count": 4, "type": "VEC2"},
                  {"componentType": 5125, "count": 6, "type": "SCALAR"}],
    "meshes": [{"name": "squashed", "primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "indices": 2,
      "extensions": {"KHR_draco_mesh_compression": {"bufferView": 0, "attributes": {"POSITION": )" +
                           std::to_string(positionId) + R"(, "TEXCOORD_0": )" + std::to_string(uvId) + R"(}}}}]}],
    "nodes": [{"mesh": 0}], "scenes": [{"nodes": [0]}]})";
  if (!binary) {
    std::ofstream(dir / "draco.gltf", std::ios::binary) << text;
    return (dir / "draco.gltf").string();
  }
  const std::vector<unsigned char> glb = glbBytes(text, bytes);
  writeBytes(dir / "draco.glb", glb);
  return (dir / "draco.glb").string();
}

TEST(GltfCompression, DracoQuadLoadsAndADamagedBufferIsRefused) {
  const fs::path dir = scratch("draco");
  int positionId = 0, uvId = 0;
  const std::vector<unsigned char> bytes = dracoQuad(positionId, uvId);
  expectQuad(loadScene(dracoGltf(dir, bytes, positionId, uvId)));
  expectQuad(loadScene(dracoGltf(dir, bytes, positionId, uvId, /*binary=*/true)));
  // Truncated, and with its header overwritten: refused, naming the file and the mesh.
  const std::vector<unsigned char> truncated(bytes.begin(), bytes.begin() + std::ptrdiff_t(bytes.size() / 2));
  expectError([&] { loadScene(dracoGltf(dir, truncated, positionId, uvId)); }, {"draco.gltf", "mesh 'squashed'", "Draco"});
  std::vector<unsigned char> garbage = bytes;
  for (size_t i = 0; i < 8 && i < garbage.size(); ++i) garbage[i] = 0xff;
  expectError([&] { loadScene(dracoGltf(dir, garbage, positionId, uvId)); }, {"draco.gltf", "mesh 'squashed'", "Draco"});
  // An attribute id the buffer does not have.
  expectError([&] { loadScene(dracoGltf(dir, bytes, positionId, 17)); }, {"draco.gltf", "mesh 'squashed'", "attribute 17"});
}

/// How meshoptGltf stores the compressed streams and the fallback buffer.
enum class MeshoptLayout {
  Files,     ///< meshopt.gltf: streams in meshopt.bin, a zero fallback in fallback.bin
  Gltfpack,  ///< meshopt.glb as gltfpack writes it: streams in the binary chunk, a fallback
             ///< buffer without uri declared larger than that chunk
};

/// What meshoptGltf varies beyond the layout: the extension, the attribute streams' first
/// byte (the codec version: 0xa0 as the encoder writes it, or another), the uv view's filter,
/// and whether the vertex view names both extensions.
struct MeshoptVariant {
  std::string extension = "EXT_meshopt_compression";
  int attributeHeader = -1;  ///< −1: as encoded
  std::string uvFilter = "NONE";
  bool bothExtensions = false;
};

/// The quad with meshopt-compressed views (`variant.extension`): vertices (stride 12), uvs
/// (stride 8) and indices (TRIANGLES, stride 2); where they and the fallback are, `layout` says.
std::string meshoptGltf(const fs::path& dir, bool damage, MeshoptLayout layout = MeshoptLayout::Files,
                        const MeshoptVariant& variant = {}) {
  std::vector<unsigned char> vertices(meshopt_encodeVertexBufferBound(4, 12));
  vertices.resize(meshopt_encodeVertexBuffer(vertices.data(), vertices.size(), kPositions, 4, 12));
  std::vector<unsigned char> uvs(meshopt_encodeVertexBufferBound(4, 8));
  uvs.resize(meshopt_encodeVertexBuffer(uvs.data(), uvs.size(), kUvs, 4, 8));
  std::vector<unsigned char> indices(meshopt_encodeIndexBufferBound(6, 4));
  indices.resize(meshopt_encodeIndexBuffer(indices.data(), indices.size(), kIndices, 6));
  if (damage) vertices.resize(vertices.size() / 2);
  if (variant.attributeHeader >= 0) vertices[0] = uvs[0] = (unsigned char)(variant.attributeHeader);
  const std::string& ext = variant.extension;
  const std::string other = variant.bothExtensions ? R"(, "KHR_meshopt_compression": {"buffer": 0, "byteLength": 1,
        "byteStride": 12, "count": 4, "mode": "ATTRIBUTES"})" : "";
  std::vector<unsigned char> all = vertices;
  all.insert(all.end(), uvs.begin(), uvs.end());
  all.insert(all.end(), indices.begin(), indices.end());
  const bool glb = layout == MeshoptLayout::Gltfpack;
  // gltfpack's fallback holds the views uncompressed (92 bytes here) and has no data; 4096
  // bytes makes it larger than the binary chunk, as it is for a real mesh.
  const std::string fallbackLength = glb ? "4096" : "92";
  const std::string streams = glb ? "" : R"(, "uri": "meshopt.bin")", fallback = glb ? "" : R"(, "uri": "fallback.bin")";
  if (!glb) {
    writeBytes(dir / "meshopt.bin", all);
    writeBytes(dir / "fallback.bin", std::vector<unsigned char>(92, 0));
  }
  const size_t v = vertices.size(), u = uvs.size(), i = indices.size();
  const std::string text = R"({"asset": {"version": "2.0"},
    "extensionsUsed": [")" + ext + R"("], "extensionsRequired": [")" + ext + R"("],
    "buffers": [{"byteLength": )" + std::to_string(all.size()) + streams + R"(},
                {"byteLength": )" + fallbackLength + fallback + R"(, "extensions": {")" + ext + R"(": {"fallback": true}}}],
    "bufferViews": [
      {"buffer": 1, "byteOffset": 0, "byteLength": 48, "byteStride": 12, "extensions": {")" + ext + R"(":
        {"buffer": 0, "byteOffset": 0, "byteLength": )" + std::to_string(v) + R"(, "byteStride": 12, "count": 4, "mode": "ATTRIBUTES"})" + other + R"(}},
      {"buffer": 1, "byteOffset": 48, "byteLength": 32, "byteStride": 8, "extensions": {")" + ext + R"(":
        {"buffer": 0, "byteOffset": )" + std::to_string(v) + R"(, "byteLength": )" + std::to_string(u) +
                           R"(, "byteStride": 8, "count": 4, "mode": "ATTRIBUTES", "filter": ")" + variant.uvFilter + R"("}}},
      {"buffer": 1, "byteOffset": 80, "byteLength": 12, "extensions": {")" + ext + R"(":
        {"buffer": 0, "byteOffset": )" + std::to_string(v + u) + R"(, "byteLength": )" + std::to_string(i) +
                           R"(, "byteStride": 2, "count": 6, "mode": "TRIANGLES"}}}],
    "accessors": [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0,0,0], "max": [2,1,0]},
                  {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC2"},
                  {"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"}],
    "meshes": [{"name": "packed", "primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "indices": 2}]}],
    "nodes": [{"mesh": 0}], "scenes": [{"nodes": [0]}]})";
  if (glb) {
    EXPECT_LT(all.size(), 4096u);
    writeBytes(dir / "meshopt.glb", glbBytes(text, all));
    return (dir / "meshopt.glb").string();
  }
  std::ofstream(dir / "meshopt.gltf", std::ios::binary) << text;
  return (dir / "meshopt.gltf").string();
}

TEST(GltfCompression, MeshoptQuadLoadsAndADamagedStreamIsRefused) {
  const fs::path dir = scratch("meshopt");
  expectQuad(loadScene(meshoptGltf(dir, false)));
  expectError([&] { loadScene(meshoptGltf(dir, true)); }, {"meshopt.gltf", "buffer view 0", "EXT_meshopt_compression"});
}

// gltfpack's .glb: the fallback buffer has no data and a byteLength larger than the binary
// chunk, which tinygltf alone refuses. The fuzzing seed seed-meshopt-fallback.glb is this
// file (written by this test to its scratch folder, copied), so it is checked here too.
TEST(GltfCompression, MeshoptGlbWithAFallbackLargerThanItsBinaryChunkLoads) {
  const fs::path dir = scratch("meshopt_glb");
  expectQuad(loadScene(meshoptGltf(dir, false, MeshoptLayout::Gltfpack)));
  expectQuad(loadScene(std::string(PLENOPTIC_TEST_DATA_DIR) + "/fuzz/gltf/seed-meshopt-fallback.glb"));
  expectError([&] { loadScene(meshoptGltf(dir, true, MeshoptLayout::Gltfpack)); },
              {"meshopt.glb", "buffer view 0", "EXT_meshopt_compression"});
}

// KHR_meshopt_compression, the ratified successor: the same views decode (its attribute codec
// version 0 is EXT_meshopt_compression's bitstream), with the fallback as gltfpack writes it too.
TEST(GltfCompression, KhrMeshoptQuadLoads) {
  const fs::path dir = scratch("meshopt_khr");
  const MeshoptVariant khr{.extension = "KHR_meshopt_compression"};
  expectQuad(loadScene(meshoptGltf(dir, false, MeshoptLayout::Files, khr)));
  expectQuad(loadScene(meshoptGltf(dir, false, MeshoptLayout::Gltfpack, khr)));
  expectError([&] { loadScene(meshoptGltf(dir, true, MeshoptLayout::Files, khr)); },
              {"meshopt.gltf", "buffer view 0", "KHR_meshopt_compression", "does not decode"});
}

// What the KHR extension adds beyond this build's meshoptimizer is refused by name: attribute
// codec version 1 (0.23 decodes it) and the COLOR filter (0.25). The EXT extension has neither:
// a version 1 stream or a COLOR filter there is an error of the file.
TEST(GltfCompression, MeshoptModesOutsideTheExtensionOrTheLibraryAreRefusedByName) {
  const fs::path dir = scratch("meshopt_modes");
  const MeshoptVariant extV1{.attributeHeader = 0xa1};
  expectError([&] { loadScene(meshoptGltf(dir, false, MeshoptLayout::Files, extV1)); },
              {"meshopt.gltf", "buffer view 0", "version 1", "KHR_meshopt_compression's, not EXT_meshopt_compression's"});
  const MeshoptVariant extColor{.uvFilter = "COLOR"};
  expectError([&] { loadScene(meshoptGltf(dir, false, MeshoptLayout::Files, extColor)); },
              {"meshopt.gltf", "buffer view 1", "unknown EXT_meshopt_compression filter 'COLOR'"});
#if MESHOPTIMIZER_VERSION < 230
  const MeshoptVariant khrV1{.extension = "KHR_meshopt_compression", .attributeHeader = 0xa1};
  expectError([&] { loadScene(meshoptGltf(dir, false, MeshoptLayout::Files, khrV1)); },
              {"meshopt.gltf", "buffer view 0", "KHR_meshopt_compression attribute codec version 1", "not supported"});
#endif
#if MESHOPTIMIZER_VERSION < 250
  const MeshoptVariant khrColor{.extension = "KHR_meshopt_compression", .uvFilter = "COLOR"};
  expectError([&] { loadScene(meshoptGltf(dir, false, MeshoptLayout::Files, khrColor)); },
              {"meshopt.gltf", "buffer view 1", "KHR_meshopt_compression filter COLOR is not supported"});
#endif
  const MeshoptVariant unknown{.extension = "KHR_meshopt_compression", .uvFilter = "SPECTRAL"};
  expectError([&] { loadScene(meshoptGltf(dir, false, MeshoptLayout::Files, unknown)); },
              {"meshopt.gltf", "buffer view 1", "unknown KHR_meshopt_compression filter 'SPECTRAL'"});
  const MeshoptVariant both{.bothExtensions = true};
  expectError([&] { loadScene(meshoptGltf(dir, false, MeshoptLayout::Files, both)); },
              {"meshopt.gltf", "buffer view 0", "both EXT_meshopt_compression and KHR_meshopt_compression"});
}

}  // namespace
}  // namespace pl
