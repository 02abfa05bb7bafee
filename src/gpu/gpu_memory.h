#pragma once
// How much GPU memory the GPU renderer may take (internal to src/gpu): the driver's answer
// where it gives one, an override, or a documented default; and the refusal of a light field
// that does not fit.
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace pl::gpu {

/// The environment variable that sets the GPU memory the renderer may use, in bytes with an
/// optional K, M or G suffix (powers of 1024): it replaces the driver's answer (tests set a
/// small one; a user may set what a driver without a memory query has).
inline constexpr const char* kGpuMemoryVariable = "PLENOPTIC_GPU_MEMORY";
/// The memory assumed where the driver has no memory query (GL_NVX_gpu_memory_info,
/// GL_ATI_meminfo) and the variable is unset: Mesa's drivers, llvmpipe included.
inline constexpr uint64_t kDefaultGpuMemory = uint64_t(4) << 30;

/// The GPU memory available to the renderer on the current context and where that figure
/// comes from ("GL_NVX_gpu_memory_info: available video memory", …).
struct GpuMemoryBudget {
  uint64_t bytes = 0;
  std::string source;
};
/// Throws pl::Error (naming the variable and its value) for a malformed kGpuMemoryVariable.
GpuMemoryBudget gpuMemoryBudget();

/// Throws pl::Error unless buffers of the given sizes (what each holds, bytes) fit: in all
/// within gpuMemoryBudget(), and each within GL_MAX_SHADER_STORAGE_BLOCK_SIZE. The message
/// gives the sizes and suggests --renderer cpu. Needs the current context.
void checkGpuMemory(const std::vector<std::pair<std::string, uint64_t>>& buffers);

/// "1.5 MiB", "312 KiB", "2.25 GiB", "100 B": a byte count for messages.
std::string formatBytes(uint64_t bytes);

}  // namespace pl::gpu
