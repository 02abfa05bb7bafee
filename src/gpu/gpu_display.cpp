// The viewer's display pass on the GPU (gpu_display.h).
#include "gpu/gpu_display.h"

#include <epoxy/gl.h>
#include <fmt/format.h>

#include <cmath>

#include "image/display.h"

namespace pl::gpu {

std::string displayGlslConstants(uint32_t radianceImageUnit) {
  return fmt::format(
      "#define DISPLAY_WORDS_BINDING {}\n#define SRGB_TABLE_BINDING {}\n#define DISPLAY_STATISTICS_BINDING {}\n"
      "#define DISPLAY_RADIANCE_UNIT {}\n#define DISPLAY_ACCUMULATION_UNIT {}\n"
      "#define PRESENT_FRAME_UNIT {}\n#define PRESENT_OVERLAY_UNIT {}\n"
      "const uint kToneReinhard = {}u, kToneLinear = {}u, kToneClamp = {}u;\n"
      "const float kSrgbTableLast = {:.1f};\nconst uint kNonFiniteWord = {}u;\nconst int kStatisticsStride = {};\n"
      "const float kLogAverageDelta = {:.9e};\n#define LOG_SUM_RUN {}\n",
      kDisplayWordsBinding, kSrgbTableBinding, kDisplayStatisticsBinding, radianceImageUnit, kAccumulationImageUnit,
      kPresentFrameUnit, kPresentOverlayUnit,
      unsigned(ToneMapOperator::Reinhard), unsigned(ToneMapOperator::Linear), unsigned(ToneMapOperator::Clamp),
      double(DisplayEncoder::kSrgbTableSize - 1), DisplayEncoder::kNonFiniteWord, DisplayEncoder::kStatisticsStride,
      double(kLogAverageDelta), kLogSumRun);
}

int logSumRuns(int width, int height) {
  const int runsPerRow = (DisplayEncoder::statisticsSize(width) + kLogSumRun - 1) / kLogSumRun;
  return runsPerRow * DisplayEncoder::statisticsSize(height);
}

// ToneMapCurve::apply and DisplayEncoder::word (tonemap.cpp, display.h), statement for
// statement: rgbToYuv, the Reinhard curve (eq. 3, or eq. 4 with a white point), the scaled U
// and V, yuvToRgb, clip01; linear; clamp. `precise` keeps the compiler from fusing a multiply
// and an add the C++ rounds apart.
const char* const kDisplayGlsl = R"glsl(
uniform uint toneOperator;
uniform float luminanceScale, whiteScaled;
uniform bool whiteInfinite;  // whiteScaled = ∞: eq. 3
layout(std430, binding = SRGB_TABLE_BINDING) readonly buffer SrgbTable { uint srgbTable[]; };

float luminance709(vec3 c) {
  precise float y = 0.2126 * c.r + 0.7152 * c.g + 0.0722 * c.b;
  return y;
}
vec3 toneCurve(vec3 exposed) {
  if (toneOperator == kToneReinhard) {
    float y = luminance709(exposed);
    precise float u = (exposed.b - y) / 1.8556, v = (exposed.r - y) / 1.5748;
    if (!(y > 0.0)) return vec3(0.0);
    precise float l = luminanceScale * y;
    precise float ld = whiteInfinite ? l / (1.0 + l) : l * (1.0 + l / (whiteScaled * whiteScaled)) / (1.0 + l);
    precise float s = ld / y;
    precise float su = u * s, sv = v * s;
    precise float r = ld + 1.5748 * sv;
    precise float b = ld + 1.8556 * su;
    precise float g = (ld - 0.2126 * r - 0.0722 * b) / 0.7152;
    return clamp(vec3(r, g, b), vec3(0.0), vec3(1.0));
  }
  if (toneOperator == kToneLinear) {
    precise vec3 scaled = exposed * luminanceScale;
    return clamp(scaled, vec3(0.0), vec3(1.0));
  }
  vec3 c = max(exposed, vec3(0.0));
  float m = max(c.r, max(c.g, c.b));
  return m > 1.0 ? c / m : c;
}
bool nonFinite(vec3 c) { return any(isnan(c)) || any(isinf(c)); }
// logLuminanceTerm (tonemap.h) of a finite pixel, in float: ln(δ + max(0, Y)).
float logLuminanceTerm(vec3 exposed) { return log(kLogAverageDelta + max(0.0, luminance709(exposed))); }
uint tableLevel(float v) {
  precise float index = clamp(v, 0.0, 1.0) * kSrgbTableLast + 0.5;
  return srgbTable[uint(index)];
}
uint displayWord(vec3 exposed) {
  if (nonFinite(exposed)) return kNonFiniteWord;
  vec3 d = toneCurve(exposed);
  if (nonFinite(d)) return kNonFiniteWord;
  return 0xFF000000u | (tableLevel(d.r) << 16) | (tableLevel(d.g) << 8) | tableLevel(d.b);
}
)glsl";

const char* const kDisplayStatisticsCompute = R"glsl(
layout(local_size_x = 8, local_size_y = 8) in;
uniform ivec2 size;
uniform float weight;  // the shown image is the bound one × weight (1 / the frames accumulated)
layout(binding = DISPLAY_RADIANCE_UNIT, rgba32f) uniform readonly image2D radiance;
layout(std430, binding = DISPLAY_STATISTICS_BINDING) writeonly buffer Statistics { vec4 statistics[]; };
void main() {
  ivec2 sub = ivec2(gl_GlobalInvocationID.xy);
  ivec2 subSize = (size + kStatisticsStride - 1) / kStatisticsStride;
  if (sub.x >= subSize.x || sub.y >= subSize.y) return;
  precise vec3 shown = imageLoad(radiance, sub * kStatisticsStride).rgb * weight;
  statistics[sub.y * subSize.x + sub.x] = vec4(shown, 0.0);
}
)glsl";

const char* const kDisplayLogSumCompute = R"glsl(
// One invocation per run of LOG_SUM_RUN subsample pixels along a row: a loop, no shared
// memory or barriers (which a software rasteriser runs slowly), compensated (Kahan) so that
// a run's float sum is off by a rounding or two of the sum, not one per term.
layout(local_size_x = 64) in;
uniform ivec2 size;
uniform float weight, exposureScale;
layout(binding = DISPLAY_RADIANCE_UNIT, rgba32f) uniform readonly image2D radiance;
struct LogSum { float sum; uint count; };
layout(std430, binding = DISPLAY_STATISTICS_BINDING) writeonly buffer LogSums { LogSum logSums[]; };
void main() {
  ivec2 subSize = (size + kStatisticsStride - 1) / kStatisticsStride;
  int runsPerRow = (subSize.x + LOG_SUM_RUN - 1) / LOG_SUM_RUN;
  int run = int(gl_GlobalInvocationID.x);
  if (run >= runsPerRow * subSize.y) return;
  int y = run / runsPerRow, first = (run % runsPerRow) * LOG_SUM_RUN;
  int last = min(first + LOG_SUM_RUN, subSize.x);
  precise float sum = 0.0, compensation = 0.0;
  uint count = 0u;
  for (int x = first; x < last; ++x) {
    precise vec3 shown = imageLoad(radiance, ivec2(x, y) * kStatisticsStride).rgb * weight;
    precise vec3 exposed = shown * exposureScale;
    if (nonFinite(exposed)) continue;
    precise float term = logLuminanceTerm(exposed) - compensation;
    precise float next = sum + term;
    compensation = (next - sum) - term;
    sum = next;
    ++count;
  }
  logSums[run] = LogSum(sum, count);
}
)glsl";

const char* const kDisplayEncodeCompute = R"glsl(
layout(local_size_x = 8, local_size_y = 8) in;
uniform ivec2 size;
uniform float weight, exposureScale;
layout(binding = DISPLAY_RADIANCE_UNIT, rgba32f) uniform readonly image2D radiance;
layout(std430, binding = DISPLAY_WORDS_BINDING) writeonly buffer Words { uint words[]; };
void main() {
  ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
  if (pixel.x >= size.x || pixel.y >= size.y) return;
  precise vec3 shown = imageLoad(radiance, pixel).rgb * weight;
  precise vec3 exposed = shown * exposureScale;
  words[pixel.y * size.x + pixel.x] = displayWord(exposed);
}
)glsl";

const char* const kAccumulateCompute = R"glsl(
layout(local_size_x = 8, local_size_y = 8) in;
uniform ivec2 size;
uniform bool restart;
layout(binding = DISPLAY_RADIANCE_UNIT, rgba32f) uniform readonly image2D radiance;
layout(binding = DISPLAY_ACCUMULATION_UNIT, rgba32f) uniform image2D accumulation;
void main() {
  ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
  if (pixel.x >= size.x || pixel.y >= size.y) return;
  vec4 frame = imageLoad(radiance, pixel);
  precise vec4 sum = restart ? frame : imageLoad(accumulation, pixel) + frame;
  imageStore(accumulation, pixel, sum);
}
)glsl";

const char* const kDisplayQueriesCompute = R"glsl(
layout(std430, binding = QUERIES_BINDING) readonly buffer Queries { vec4 queries[]; };
layout(std430, binding = RESULTS_BINDING) writeonly buffer Results { uint results[]; };
void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= count) return;
  vec3 exposed = queries[i].rgb;
  results[2u * i] = displayWord(exposed);
  results[2u * i + 1u] = nonFinite(exposed) ? 0x7FC00000u : floatBitsToUint(logLuminanceTerm(exposed));
}
)glsl";

const char* const kPresentVertex = R"glsl(
void main() {
  // (−1, −1), (3, −1), (−1, 3): one triangle covering the viewport.
  vec2 corner = vec2(float((gl_VertexID & 1) << 2) - 1.0, float((gl_VertexID & 2) << 1) - 1.0);
  gl_Position = vec4(corner, 0.0, 1.0);
}
)glsl";

const char* const kPresentFragment = R"glsl(
uniform ivec2 windowSize, frameSize, overlaySize;
uniform bool wordsInBuffer;  // the display pass's words at the window's size: read as they are
layout(std430, binding = DISPLAY_WORDS_BINDING) readonly buffer Words { uint words[]; };
layout(binding = PRESENT_FRAME_UNIT) uniform sampler2D frame;
layout(binding = PRESENT_OVERLAY_UNIT) uniform sampler2D overlay;
out vec4 colour;
void main() {
  // gl_FragCoord counts rows from the bottom; the frame's and overlay's row 0 is the top.
  ivec2 pixel = ivec2(int(gl_FragCoord.x), windowSize.y - 1 - int(gl_FragCoord.y));
  vec3 c;
  if (wordsInBuffer) {
    uint w = words[pixel.y * windowSize.x + pixel.x];
    c = vec3(float((w >> 16) & 255u), float((w >> 8) & 255u), float(w & 255u)) / 255.0;
  } else {
    c = frameSize == windowSize ? texelFetch(frame, pixel, 0).rgb
                                : texture(frame, (vec2(pixel) + 0.5) / vec2(windowSize)).rgb;
  }
  if (pixel.x < overlaySize.x && pixel.y < overlaySize.y) {
    vec4 o = texelFetch(overlay, pixel, 0);
    c = o.rgb * o.a + c * (1.0 - o.a);
  }
  colour = vec4(c, 1.0);
}
)glsl";

void setToneCurveUniforms(uint32_t program, const ToneMapCurve& curve) {
  glProgramUniform1ui(program, glGetUniformLocation(program, "toneOperator"), unsigned(curve.op));
  glProgramUniform1f(program, glGetUniformLocation(program, "luminanceScale"), curve.luminanceScale);
  const bool infinite = std::isinf(curve.whiteScaled);
  glProgramUniform1f(program, glGetUniformLocation(program, "whiteScaled"), infinite ? 1.0f : curve.whiteScaled);
  glProgramUniform1i(program, glGetUniformLocation(program, "whiteInfinite"), infinite ? 1 : 0);
}

}  // namespace pl::gpu
