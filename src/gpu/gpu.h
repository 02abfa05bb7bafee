#pragma once
// The GPU light-field renderer (OpenGL 4.5 core, through a headless EGL context or a window's):
// the fast renderer's picture (realtime/realtime.h) drawn by the graphics processor — or, on a
// machine without one, by Mesa's llvmpipe software rasteriser, which is how the tests run it.
//
// A frame is three passes:
//   1. visibility: every triangle of the scene rasterised once with a reversed-Z float depth
//      buffer, writing its triangle id (+1; 0 = nothing) per pixel — the primary hit of the
//      ray through the pixel centre, as the CPU renderer's one sample per pixel; an
//      alpha-masked triangle is discarded where that ray meets it at a coverage below its
//      cutoff (coverageAt), as the ray caster's hit filter does. Then every vertex is drawn as
//      a one-pixel point that marks its pixel where it is nearer than the surface there;
//   2. resolve (a compute shader): per pixel, the camera ray of Camera::generateRay through the
//      pixel centre and its hit. Where that pixel and its 8 neighbours hold at most two ids,
//      none marked, the ray is tested against those triangles (the nearer hit; a miss where
//      it hits neither and one of the two is nothing), and where they hold more triangles, all
//      around one vertex, it takes the one of them it hits if it hits exactly one; elsewhere —
//      other surfaces nearby, a marked vertex (a triangle smaller than a pixel, which the
//      rasteriser's sub-pixel snapping can leave out of the id buffer though the ray through
//      the centre hits it), a ray hitting none of the triangles — the pixel is queued and its
//      ray cast through the BVH (gpu_bvh.h), as the CPU renderers cast theirs through Embree;
//      so only a sliver narrower than a pixel passing between the 3×3 centres with its
//      vertices elsewhere, a triangle smaller than a pixel whose vertices lie on the surfaces
//      seen there, or a tie between coplanar triangles, can make the two differ;
//   3. shading, a compute shader reading that hit: the hit point origin + t·direction (as the
//      CPU renderer takes it), the chart record the viewer sees (viewedChart) and the
//      16-neighbour lookup of lightfield/lookup.h (exitantRadianceLanes),
//      times the camera weight (cos⁴θ with vignetting). A miss sees the environment (the
//      constant and the map: EnvironmentMap::radiance, bilinear in the lat-long image). On a
//      chart whose albedo varies, the albedo texture is read at the CPU renderer's mip level
//      (albedoTextureLod: ray cones of textureConeSpread × t) exactly as Texture::sampleLod
//      reads it (wrap modes, nearest, trilinear between levels), times the vertex colour; an
//      emission texture is read at full resolution (emissionModulation); on a normal-mapped
//      chart the mapped normal (surfaceAt) bends the glossy lookup and selects the tilted
//      irradiances; a GGX-like diffuse base takes k(μ) from its table (gpu_surface_detail.h).
//      A hit on a mirror, glass or mirror-like record follows the chain of reflected, refracted and lobe-sampled rays,
//      traced through a BVH on the GPU, as the CPU renderers do (gpu_specular.h, gpu_bvh.h).
// The result is radiance (W·sr⁻¹·m⁻², camera weight included, no exposure), read back into an
// Image exactly where FastRenderer::render writes it; exposure and tone mapping are then the
// same CPU code for both renderers (jobs/ ViewSettings::writeImage). The viewer instead has
// the frame encoded into its window's 8-bit pixels on the GPU by DisplayEncoder's rule
// (encodeDisplay, gpu_display.h) and reads back those.
//
// The light field is uploaded once: its values as 16-byte RGBA (the CPU renderer's padded
// copy), its chart records with their precomputed shading (ChartShading), the vertex positions
// and normals (a curved glossy chart's map is read around the interpolated normal,
// chartShadingNormalAt), the triangle → chart map, the sun masks (one uint each; the masked
// lights are uniforms), the environment map's texels (RGBA) and the surface detail
// (gpu_surface_detail.h: the textures the shader reads — 4 bytes per texel of an 8-bit level
// as the CPU packs it, 12 of a float one, every mip level of an albedo texture — 292 bytes per
// material, 10 KiB of GGX and sheen albedo tables, and where a chart, mask or traced hit needs uvs, 36 bytes per vertex and 4 per triangle). So
// GPU memory is 16 bytes per value + 128 per chart + 32 per vertex + 28 per triangle + 4 per
// sun mask + 16 per environment texel + the surface detail + the BVH's 32 per node and 48 per
// triangle + (with mirrors, glass or punctual highlights) 64 per material and 4 per triangle for
// the chains and shadow rays, and 64 per delta light and 64 per material for the highlights +
// the frame's targets (radiance and the resolve pass's hits 16 bytes per pixel each, its queue
// of rays to cast 4 and 16 in all; id and depth 8 bytes per pixel, or per texel of the finer
// multi-sample visibility pass; once the viewer's display pass has run, 4 more per pixel and
// 16 per 16 pixels, and its 64 KiB sRGB table; once it refines a still view, 16 more per pixel
// for the sum of its batches; once it presents, 4 per pixel of the HUD, and of the frame where
// it is not the display pass's at the window's size).
// A light field whose buffers exceed the GPU
// memory available (gpu_memory.h: the driver's query, GL_NVX_gpu_memory_info or
// GL_ATI_meminfo; the PLENOPTIC_GPU_MEMORY variable; 4 GiB where neither says) is refused
// before anything is uploaded, with the sizes, and so is one with a buffer larger than the
// driver's largest storage block.
//
// What it does not render yet (gpuUnsupportedFeature names the first one a light field has;
// the constructor refuses such a light field with that name rather than draw a different
// picture): environment maps lighting mirror-like glossy lobes, mirror-like glTF PBR lobes or
// ones with a metallic-roughness texture, glTF materials with a
// clear coat or sheen and a metallic-roughness texture (each point's k(μ) normalisation), albedo
// textures on diffuse charts of a model other than Lambert or subsurface (which no bake makes),
// glTF layered materials on mirrors and glass. A clear coat or sheen over a diffuse base takes
// k(μ) from the GGX and sheen albedo tables (gpu_surface_detail.h); albedo textures and vertex
// colours on mirrors and glass change nothing of them (materialModelAt). Punctual highlights
// on glossy charts are evaluated per pixel with a shadow ray through the BVH
// (gpu_highlights.h); a metallic-roughness texture gives each pixel its own model (its diffuse
// part's ρ and k(μo), its highlights' lobe: gpu_surface_detail.h metallicRoughnessLobe). The traced rays read the surface detail at
// their hits as the camera rays do: they cut alpha masks (gpu_bvh.h BVH_ALPHA_MASKS), the
// lookup at a chain's end reads the albedo texture at the mip level of the chain's ray cone
// (textureConeSpread × the summed length), and surfaceAt bends a mirror's, glass's or
// highlight's normal by its normal map (gpu_surface_detail.h tracedSurfaceDetail).
//
// Several samples per pixel: the shading pass loops over the pixel's samples at the CPU
// renderers' film points (pixelSample's ZSobol sequence in 64-bit GLSL integers,
// GL_ARB_gpu_shader_int64); the visibility pass is then drawn at a finer resolution (16× per
// axis on small images, 4× at 1920×1080: its targets stay within 256 MiB) and each jittered ray
// takes its hit from the 3×3 of those finer texels around its film point by the same rule
// (at most two ids, unmarked, one of them hit by the ray), else it is cast through the BVH —
// in the shading pass itself, which then has no resolve pass before it.
//
// With PLENOPTIC_GPU_VISIBILITY=rays no ids are drawn and every camera ray is cast through the
// BVH (in the resolve pass, or the multi-sample shading pass): the same hits without the
// rasteriser, for measuring a GPU with few rasterising units (docs/benchmarks.md).
//
// A thin lens (depth of field): each sample's lens point is the CPU renderers' (pixelSample's
// second ZSobol dimension, mapped to the aperture by sampleConcentricDisk; the lens centre at
// one sample per pixel) and its ray starts there, off the eye the id buffer is rasterised
// from: every camera ray is cast through the BVH and the visibility pass is not drawn.
//
// The shader's lookup is checked against the C++ one (exitantRadiance) on random inputs by
// GpuRenderer::lookup, which runs the very GLSL function the shading pass calls.
// The light sampler's GLSL (gpu_lights.h) is checked against LightSampler the same way by
// GpuRenderer::sampleLights, and the mirror-like lobe's (gpu_mirror_like.h) by
// GpuRenderer::sampleLobes.
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "bsdf/bsdf.h"
#include "gpu/gpu_bvh.h"
#include "image/image.h"
#include "light/light.h"
#include "lightfield/lightfield.h"
#include "lightfield/render_settings.h"

namespace pl {

class Camera;
class DisplayEncoder;
struct ToneMapCurve;
struct ToneMapSettings;

/// The first feature of `lightField` the GPU renderer does not draw yet, as a phrase for a
/// message ("alpha masks", …); empty when it draws all of it.
std::string gpuUnsupportedFeature(const LightField& lightField);

/// The bytes the CPU renderers hold of `lightField` once decoded: its values (12 bytes each),
/// chart records, triangle → chart map and sun masks, its scene's geometry (positions,
/// normals, uvs, vertex colours, triangles and their materials) and textures (every level's
/// float texels and packed ones, Texture::mips). What GpuRenderer::gpuBytes is measured
/// against (docs/benchmarks.md).
uint64_t lightFieldMemoryBytes(const LightField& lightField);

/// Whether a headless OpenGL 4.5 core context can be created here; `why` gets the EGL/GL
/// error when not.
bool gpuAvailable(std::string* why = nullptr);

/// What a headless OpenGL 4.5 core context reports here (probeGpu).
struct GpuProbe {
  bool available = false;
  std::string error;      ///< why there is none (the EGL error), when !available
  std::string device;     ///< as GpuRenderer::deviceName
  bool software = false;  ///< a software rasteriser (isSoftwareRasteriser): no graphics card
};
/// Creates a context for a moment and asks it (no shaders, no upload).
GpuProbe probeGpu();

/// Whether a GL_RENDERER string names one of Mesa's software rasterisers (llvmpipe, softpipe,
/// swrast "Software Rasterizer"), which run on the CPU: there the CPU fast renderer is faster
/// (docs/benchmarks.md), so `view` takes the GPU renderer only when asked to.
bool isSoftwareRasteriser(const std::string& glRenderer);

/// The GPU's own time for a frame, pass by pass, in milliseconds (GL timestamp queries): the
/// visibility pass (the triangle ids rasterised), the resolve pass (one sample per pixel: each
/// pixel's camera ray cast — the id buffer's triangle or the BVH's), the shading pass (the
/// lookup; with several samples per pixel their rays too).
struct GpuPassMilliseconds {
  double visibility = 0.0, resolve = 0.0, shading = 0.0;
  double total() const { return visibility + resolve + shading; }
};

/// Where a GpuRenderer's OpenGL context comes from.
enum class GpuContext {
  /// Its own, without a window: EGL on Mesa's surfaceless platform, else on the default
  /// display with a 1×1 pbuffer. It renders into framebuffer objects only.
  Headless,
  /// The OpenGL 4.5 core context current on the calling thread — a window's (the viewer's,
  /// made by SDL) — which the caller keeps current whenever it calls the renderer; present()
  /// draws into its window.
  Current,
};

/// 0xAARRGGBB words in memory (as SDL_PIXELFORMAT_ARGB8888 and DisplayEncoder write them),
/// `pitchBytes` per row, top row first.
struct DisplayPixels {
  const uint32_t* words = nullptr;
  int width = 0, height = 0, pitchBytes = 0;
};

class GpuRenderer {
 public:
  /// Creates the headless context (GpuContext::Headless) or takes the current one, compiles
  /// the shaders and uploads the light field. Throws pl::Error naming the EGL or GL error when
  /// no OpenGL 4.5 core context can be had (or the current one is older or not a core one),
  /// naming the feature (gpuUnsupportedFeature) for a light field it cannot draw, and giving
  /// the sizes for one that does not fit the GPU memory. `lightField` must outlive the
  /// renderer. Use it from one thread: the context's.
  explicit GpuRenderer(const LightField& lightField, GpuContext context = GpuContext::Headless);
  ~GpuRenderer();
  GpuRenderer(const GpuRenderer&) = delete;
  GpuRenderer& operator=(const GpuRenderer&) = delete;

  /// Renders camera.width() × camera.height() pixels of radiance into `image` (resized only
  /// when its size differs), like FastRenderer::render: one ray through each pixel centre (and
  /// a thin lens's centre), or with several samples per pixel the CPU renderers' film and lens
  /// points (pixelSample, render_settings.h), averaged. Throws pl::Error for settings it does not
  /// support (checkSettings).
  void render(const Camera& camera, const RenderSettings& settings, Image& image);
  /// render() in two steps: draw() renders the frame and leaves its radiance on the GPU;
  /// readRadiance() reads it back into `image` as render() does, or encodeDisplay() turns it
  /// into the window's pixels there (the viewer's path). Either may be called several times
  /// for one draw(), until the next draw() or render().
  void draw(const Camera& camera, const RenderSettings& settings);
  void readRadiance(Image& image);
  /// The last draw()'s frame as display words, the same as `encoder.encode(radiance,
  /// exposureScale, settings, pixels, pitchBytes)` on readRadiance()'s image (image/display.h):
  /// the statistics the curve needs are read back — the partial sums of the subsample's
  /// log-average for Reinhard's key, the subsample itself for the automatic key, nothing
  /// otherwise (gpu_display.h) — and encoder.resolveCurve resolves the curve from them on the
  /// CPU; the display pass (gpu_display.h) computes each pixel's word, 0xFFRRGGBB, on the
  /// GPU and 4 bytes per pixel are read back into `pixels` (`pitchBytes` per row, the bytes
  /// between rows left as they are) — instead of 12 of radiance and a tone-mapping pass on the
  /// CPU.
  /// With `average`, the frame encoded is the average of the accumulated ones (accumulate:
  /// their sum × 1 / their count, as the viewer averages its refinement batches on the CPU).
  /// With `pixels` null nothing is read back: the words stay on the GPU for present().
  void encodeDisplay(DisplayEncoder& encoder, float exposureScale, const ToneMapSettings& settings, uint32_t* pixels,
                     int pitchBytes, bool average = false);
  /// The viewer's picture drawn into the current context's window (framebuffer 0: its back
  /// buffer; the caller swaps it in) at windowWidth × windowHeight: the frame — `frame`, or
  /// where frame.words is null the last encodeDisplay's words, still on the GPU — stretched
  /// over the window (texel for pixel where the sizes agree, else bilinear), and `overlay`
  /// (the HUD; none where its words are null) blended over the window's top-left corner by its
  /// alpha (gpu_display.h kPresentFragment). So with GpuContext::Current a frame the GPU drew
  /// never leaves it: no read-back, no copy through the CPU.
  void present(const DisplayPixels& frame, const DisplayPixels& overlay, int windowWidth, int windowHeight);
  /// present()'s picture drawn into an offscreen target instead and read back, top row first:
  /// what the window shows (gpu_test checks it).
  std::vector<uint32_t> presentOffscreen(const DisplayPixels& frame, const DisplayPixels& overlay, int windowWidth,
                                         int windowHeight);
  /// The window's back buffer as present() left it (call it before the swap), top row first:
  /// what the window shows (`view --window-shot`).
  std::vector<uint32_t> readPresented(int windowWidth, int windowHeight);
  /// Adds the last draw()'s radiance to the accumulation on the GPU (16 bytes per pixel, made
  /// on the first call), or starts it again from that frame (`restart`; also after the image
  /// size changed): the viewer's refinement of a still view in batches of samples. The
  /// average is shown by encodeDisplay(…, true) and read back by readAverage; accumulatedFrames
  /// says how many frames it holds.
  void accumulate(bool restart);
  int accumulatedFrames() const;
  void readAverage(Image& image);
  /// Compiles the display pass's programs and uploads its table now rather than at the first
  /// encodeDisplay: the viewer does it while it chooses its renderer, so that a driver that
  /// fails on them is a reason to take the CPU renderer (pl::Error with the driver's log).
  void prepareDisplay();
  /// The display pass's GLSL (displayWord) on given exposed colours with `curve`: what
  /// DisplayEncoder::word(curve, exposed) gives, one word each (gpu_test checks the two agree).
  std::vector<uint32_t> displayWords(const ToneMapCurve& curve, const std::vector<Rgb>& exposed);
  /// The display pass's log sum term (logLuminanceTerm, in float) of given exposed colours,
  /// NaN for a non-finite one (left out of the sum): what tonemap.h's logLuminanceTerm gives,
  /// to float rounding (gpu_test checks the two agree).
  std::vector<float> logLuminanceTerms(const std::vector<Rgb>& exposed);

  /// What this driver lacks for `settings` (several samples per pixel, a thin lens's default
  /// among them, need GL_ARB_gpu_shader_int64); empty when render() can draw them.
  std::string unsupportedSetting(const RenderSettings& settings, const Camera& camera) const;
  /// checkRenderSettings, then throws pl::Error naming unsupportedSetting's answer, if any.
  void checkSettings(const RenderSettings& settings, const Camera& camera) const;

  /// The rasterisation pass alone (`render --stats` primary_ms_median for this renderer),
  /// finished on the GPU before it returns; idScale: at that many times the camera's
  /// resolution per axis (render() takes more than 1 for several samples per pixel).
  void drawVisibility(const Camera& camera, int idScale = 1);

  /// The GPU's own time for the last frame read back (render(), or draw() then readRadiance()
  /// or encodeDisplay()), in milliseconds, pass by pass: from the start of its first pass to
  /// the end of its shading pass by GL timestamp queries — what a frame costs the GPU, the
  /// read-back and the display pass excluded (`render --stats` gpu_ms_median for the total,
  /// gpu_visibility_ms_median, ... for the passes).
  GpuPassMilliseconds lastGpuPasses() const;
  /// The share of that frame's pixels whose camera ray the resolve pass cast through
  /// the BVH: those the id texels could not answer (edges, silhouettes, triangles smaller than a
  /// pixel; every pixel of a thin lens, or with PLENOPTIC_GPU_VISIBILITY=rays) — `render --stats`
  /// gpu_bvh_ray_share_median. Empty after a frame of several samples per pixel, whose rays are
  /// cast in the shading pass.
  std::optional<double> lastBvhRayShare() const;
  /// The most pixels (width × height) render() draws on this driver: the resolve pass's queue
  /// of rays to cast, 4 bytes per pixel, within its largest storage block
  /// (GL_MAX_SHADER_STORAGE_BLOCK_SIZE: 128 MiB on llvmpipe, 33.5 M pixels). render() refuses a
  /// larger image with the sizes.
  uint64_t maxImagePixels() const;

  /// One lookup query: the chart record as triangleChart gives it (facingChart turns it to the
  /// side the viewer is on), a world point and the unit direction towards the viewer.
  struct LookupQuery {
    uint32_t chart = 0;
    Vec3 position{0.0f}, towardsViewer{0.0f, 0.0f, 1.0f};
  };
  /// The shading pass's lookup function run on each query in a compute shader: the radiance
  /// exitantRadiance(lightField, chart, position, towardsViewer, uv) gives on the CPU (planar
  /// charts; curved ones are read around the chart normal here; no surface detail: the albedo
  /// modulation and emission texel 1, the chart normal as the mapped normal).
  std::vector<Rgb> lookup(const std::vector<LookupQuery>& queries);

  /// The closest hits of `rays` in (tMin, tMax) by the BVH traversal the shading pass traces
  /// mirrors and glass with (gpu_bvh.h bvhIntersect), run in a compute shader; triangle is
  /// the index in the scene's meshes' triangles in order (mesh 0's first). `occluded`, when
  /// given, gets bvhOccluded's answer per ray (1: blocked).
  std::vector<BvhHit> intersect(const std::vector<Ray>& rays, std::vector<uint8_t>* occluded = nullptr);

  /// One query of the light sampler's GLSL (gpu_lights.h), at `position` with the numbers `u`;
  /// emitterPdf's arguments (triangle: the scene's index, mesh by mesh), environmentPdf's
  /// direction and sphereLightAlong's ray (from origin along unit direction, in (0, tMax),
  /// the receiver `position`).
  struct LightQuery {
    Vec3 position{0.0f};
    Vec2 u{0.0f};
    uint32_t triangle = 0;
    float distance = 1.0f, cosLight = 1.0f;
    Vec3 origin{0.0f}, direction{0.0f, 0.0f, 1.0f};
    float tMax = kInfinity;
  };
  /// What the GLSL answers: LightSampler::sample (sampled: it returned a sample; delta: a delta
  /// light, whose fields are unset), emitterPdf, environmentPdf and sphereLightAlong.
  struct LightAnswer {
    bool sampled = false;
    LightSample sample;
    float emitterPdf = 0.0f, environmentPdf = 0.0f;
    bool sphere = false;  ///< sphereLightAlong found one
    LightSampler::SphereCrossing crossing;
  };
  /// The light sampler's GLSL run on each query in a compute shader, with `sampler`'s tables
  /// uploaded (a sampler of this renderer's scene). Throws pl::Error for lights it does not
  /// sample (gpuUnsupportedLights).
  std::vector<LightAnswer> sampleLights(const LightSampler& sampler, const std::vector<LightQuery>& queries);

  /// One query of the mirror-like lobe's GLSL (gpu_mirror_like.h): material `material`'s model
  /// sampled for local direction wo with the numbers u, and its density for wi.
  struct LobeQuery {
    uint32_t material = 0;
    Vec3 wo{0.0f, 0.0f, 1.0f}, wi{0.0f, 0.0f, 1.0f};
    Vec2 u{0.0f};
  };
  /// What the GLSL answers: sample(bsdf, wo, u) (sampled: it returned one; its wi, weight and
  /// pdf) and pdf(bsdf, wo, wi) as wiPdf.
  struct LobeAnswer {
    bool sampled = false;
    BsdfSample sample;
    float wiPdf = 0.0f;
  };
  /// The mirror-like lobe's GLSL run on each query in a compute shader.
  std::vector<LobeAnswer> sampleLobes(const std::vector<LobeQuery>& queries);

  /// The GL_RENDERER and GL_VERSION strings of the context (e.g. "llvmpipe (LLVM 15.0.6, 256
  /// bits)", "4.5 (Core Profile) Mesa 22.3.6").
  std::string deviceName() const;
  /// Bytes of GPU buffers and textures this renderer holds (the light field's and the frame's).
  uint64_t gpuBytes() const;
  /// Of gpuBytes, the light field's buffers alone (uploaded once; the rest is the frame's
  /// targets, which follow the image size).
  uint64_t lightFieldGpuBytes() const;

 private:
  /// present() into `framebuffer` (0: the window's back buffer).
  void presentInto(uint32_t framebuffer, const DisplayPixels& frame, const DisplayPixels& overlay, int windowWidth,
                   int windowHeight);
  /// displayWords's and logLuminanceTerms's queries: per colour its word, then its term's bits.
  std::vector<uint32_t> displayQueries(const ToneMapCurve& curve, const std::vector<Rgb>& exposed);

  struct State;
  const LightField& lightField_;
  std::unique_ptr<State> state_;
};

}  // namespace pl
