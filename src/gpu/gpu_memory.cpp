// The GPU renderer's memory budget and check (gpu_memory.h).
#include "gpu/gpu_memory.h"

#include <epoxy/gl.h>
#include <fmt/format.h>

#include <cstdlib>

#include "core/error.h"
#include "gpu/gpu.h"

namespace pl {

uint64_t lightFieldMemoryBytes(const LightField& lf) {
  uint64_t bytes = lf.values.size() * sizeof(Rgb) + lf.charts.size() * sizeof(Chart) + lf.sunMasks.size() * sizeof(SunMask);
  for (const std::vector<uint32_t>& charts : lf.triangleChart) bytes += charts.size() * sizeof(uint32_t);
  for (const Mesh& m : lf.scene.meshes)
    bytes += (m.positions.size() + m.normals.size() + m.colors.size()) * sizeof(Vec3) + (m.uvs.size() + m.uvs1.size()) * sizeof(Vec2) +
             m.triangles.size() * sizeof(UVec3) + m.materials.size() * sizeof(uint32_t);
  auto level = [](const Image& image, const std::vector<Texture::PackedBlock>& packed, const std::vector<float>& palette) {
    return image.pixels.size() * sizeof(Rgb) + packed.size() * sizeof(Texture::PackedBlock) + palette.size() * sizeof(float);
  };
  for (const Texture& t : lf.scene.textures) {
    bytes += level(t.image, t.packed, t.palette);
    for (const Texture::Level& l : t.mips) bytes += level(l.image, l.packed, l.palette);
  }
  return bytes;
}

}  // namespace pl

namespace pl::gpu {
namespace {

// The memory queries' enums (GL_NVX_gpu_memory_info, GL_ATI_meminfo): kibibytes.
constexpr GLenum kNvxCurrentAvailableVidmem = 0x9049, kAtiVboFreeMemory = 0x87FB;

/// kGpuMemoryVariable's value in bytes: digits, then optionally K, M or G (× 1024^1,2,3).
uint64_t parseMemorySize(const std::string& text) {
  size_t digits = 0;
  while (digits < text.size() && text[digits] >= '0' && text[digits] <= '9') ++digits;
  const std::string suffix = text.substr(digits);
  const int shift = suffix.empty() ? 0 : suffix == "K" ? 10 : suffix == "M" ? 20 : suffix == "G" ? 30 : -1;
  if (digits == 0 || digits > 12 || shift < 0)
    fail("{}={}: expected a number of bytes with an optional K, M or G suffix (e.g. 512M)", kGpuMemoryVariable, text);
  return std::stoull(text.substr(0, digits)) << shift;
}

}  // namespace

GpuMemoryBudget gpuMemoryBudget() {
  if (const char* value = std::getenv(kGpuMemoryVariable); value != nullptr && *value != '\0')
    return {parseMemorySize(value), fmt::format("{}={}", kGpuMemoryVariable, value)};
  if (epoxy_has_gl_extension("GL_NVX_gpu_memory_info")) {
    GLint kib = 0;
    glGetIntegerv(kNvxCurrentAvailableVidmem, &kib);
    if (glGetError() == GL_NO_ERROR && kib > 0)
      return {uint64_t(kib) << 10, "available video memory, GL_NVX_gpu_memory_info"};
  }
  if (epoxy_has_gl_extension("GL_ATI_meminfo")) {
    GLint kib[4] = {};
    glGetIntegerv(kAtiVboFreeMemory, kib);
    if (glGetError() == GL_NO_ERROR && kib[0] > 0) return {uint64_t(kib[0]) << 10, "free buffer memory, GL_ATI_meminfo"};
  }
  return {kDefaultGpuMemory, fmt::format("the default where the driver has no memory query; set {} to change it",
                                         kGpuMemoryVariable)};
}

std::string formatBytes(uint64_t bytes) {
  if (bytes < 1024) return fmt::format("{} B", bytes);
  const char* units[] = {"KiB", "MiB", "GiB", "TiB"};
  double value = double(bytes) / 1024.0;
  int unit = 0;
  while (value >= 1024.0 && unit < 3) value /= 1024.0, ++unit;
  return fmt::format("{:.3g} {}", value, units[unit]);
}

void checkGpuMemory(const std::vector<std::pair<std::string, uint64_t>>& buffers) {
  uint64_t total = 0;
  for (const auto& [what, bytes] : buffers) total += bytes;
  // The parts worth naming: each of at least 1 % of the total.
  std::string parts;
  for (const auto& [what, bytes] : buffers)
    if (bytes * 100 >= total) parts += fmt::format("{}{} {}", parts.empty() ? "" : ", ", what, formatBytes(bytes));
  const GpuMemoryBudget budget = gpuMemoryBudget();
  if (total > budget.bytes)
    fail("GPU renderer: the light field needs {} of GPU memory ({}) but {} is available ({}): render it with "
         "--renderer cpu",
         formatBytes(total), parts, formatBytes(budget.bytes), budget.source);
  GLint64 maxBlock = 0;
  glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &maxBlock);
  for (const auto& [what, bytes] : buffers)
    if (maxBlock > 0 && bytes > uint64_t(maxBlock))
      fail("GPU renderer: the light field's {} take {}, more than this driver's largest storage buffer ({}, "
           "GL_MAX_SHADER_STORAGE_BLOCK_SIZE): render it with --renderer cpu",
           what, formatBytes(bytes), formatBytes(uint64_t(maxBlock)));
}

}  // namespace pl::gpu
