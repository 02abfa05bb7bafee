// `plenoptic env convert|sh|irradiance|prefilter|splitsum-error`: environment-map tools
// (src/env/env.h for layouts and conventions, src/env/ibl.h for the maths).
#include <fmt/format.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "app/commands.h"
#include "core/error.h"
#include "core/file_io.h"
#include "core/timing.h"
#include "env/env.h"
#include "env/ibl.h"
#include "image/image.h"

namespace pl {
namespace {

namespace fs = std::filesystem;

// Ranges of the options, declared once.
constexpr int kMaxMapSize = 16384;
constexpr int kMaxSamples = 1 << 20;

struct ConvertOptions {
  std::string input;   ///< image file, directory of faces, or pattern with {face}
  std::string output;  ///< file (latlong, cross, vcross) or directory / {face} pattern (cube)
  std::string layout = "latlong";
  int size = 0;  ///< lat-long height or cube face size; 0 = same angular resolution as the input
};

struct ShOptions {
  std::string input;
  bool json = false;
};

struct IrradianceOptions {
  std::string input;
  std::string output;
  std::string method = "both";  ///< sh | brute | both
  std::string layout = "latlong";
  int size = 32;          ///< output: lat-long height (width 2×) or cube face size
  int sourceHeight = 128; ///< brute force integrates over the input resampled to this lat-long height (0 = full)
};

struct PrefilterCliOptions {
  std::string input;
  std::string output;
  std::string model = "ggx";
  std::string layout = "latlong";
  int levels = 6;
  int size = 128;       ///< lat-long height of level 0
  int samples = PrefilterOptions{}.samples;  ///< BSDF samples per texel
  int lutSize = 64;
  int lutSamples = 1024;
};

struct SplitSumCliOptions {
  std::string input;
  bool json = false;
  std::string plot;
  std::string model = "ggx";
  float f0 = 1.0f;
  int normals = 16;
  int samples = 4096;
  std::vector<float> roughness = SplitSumOptions{}.roughness;
  std::vector<float> viewDegrees = SplitSumOptions{}.viewDegrees;
};

/// `dir/name.ext` + tag → `dir/name.tag.ext`.
std::string withTag(const std::string& path, const std::string& tag) {
  const fs::path p(path);
  return (p.parent_path() / (p.stem().string() + "." + tag + p.extension().string())).string();
}

/// Where `irradiance --method both` writes the SH map beside the brute-force one at `path`:
/// NAME.sh.EXT for files and {face} patterns, DIR.sh/ for a cube directory.
std::string shSibling(const std::string& path, EnvLayout layout) {
  if (layout == EnvLayout::Cube && path.find("{face}") == std::string::npos) {
    std::string dir = path;
    while (dir.size() > 1 && dir.back() == '/') dir.pop_back();
    return dir + ".sh";
  }
  return withTag(path, "sh");
}

/// Fails before any work if `path` cannot receive an environment in `layout`.
void checkEnvOutput(const std::string& path, EnvLayout layout) {
  if (layout == EnvLayout::Cube && path.find("{face}") == std::string::npos) return;  // a directory, created
  if (layout == EnvLayout::Cube) {  // a {face} pattern: its directory is created
    if (!isHdrExtension(path)) failUsage("-o {}: expected an .exr, .hdr or .pfm file name", path);
    return;
  }
  checkOutputPath(path, kHdrImageExtensions, "-o");
}

void runConvert(const ConvertOptions& o, const GlobalOptions& global) {
  Runtime runtime(global);
  const EnvLayout layout = parseEnvLayout(o.layout);
  checkEnvOutput(o.output, layout);
  const EnvImage env = loadEnvironment(o.input);
  EnvImage out;
  if (layout == EnvLayout::LatLong)
    out = toLatLong(env, o.size > 0 ? o.size : equivalentLatLongHeight(env));
  else
    out = toCube(env, o.size > 0 ? o.size : equivalentFaceSize(env));
  saveEnvironment(o.output, out, layout);
  fmt::print("{}: {} → {} ({})\n", o.input, describe(env), describe(out), o.output);
}

void runSh(const ShOptions& o, const GlobalOptions& global) {
  Runtime runtime(global);
  const EnvImage env = loadEnvironment(o.input);
  const auto start = std::chrono::steady_clock::now();
  const Sh9 sh = projectSh9(env);
  const double seconds = secondsSince(start);
  if (o.json) {
    fmt::print("{}\n", shToJson(sh, o.input));
    return;
  }
  fmt::print("{}: {}, SH projection in {:.1f} ms\n", o.input, describe(env), 1e3 * seconds);
  fmt::print("radiance SH coefficients L_k = ∫ L Y_k dω (orthonormal real SH, world axes, +y up)\n");
  static const char* names[9] = {"L00  (1)", "L1-1 (y)", "L10  (z)", "L11  (x)", "L2-2 (xy)",
                                 "L2-1 (yz)", "L20  (3z²-1)", "L21  (xz)", "L22  (x²-y²)"};
  for (int k = 0; k < 9; ++k) {
    const DVec3& c = sh.coefficients[size_t(k)];
    fmt::print("  {:<14} {:>14.8g} {:>14.8g} {:>14.8g}\n", names[k], c.x, c.y, c.z);
  }
  const DVec3 up = shIrradiance(sh, {0, 1, 0}), down = shIrradiance(sh, {0, -1, 0});
  fmt::print("irradiance from SH: up (+y) {:.6g} {:.6g} {:.6g}, down (−y) {:.6g} {:.6g} {:.6g} W·m⁻²\n", up.x, up.y,
             up.z, down.x, down.y, down.z);
}

void runIrradiance(const IrradianceOptions& o, const GlobalOptions& global) {
  Runtime runtime(global);
  const EnvLayout layout = parseEnvLayout(o.layout);
  if (o.method != "sh" && o.method != "brute" && o.method != "both")
    fail("--method {}: expected sh, brute or both", o.method);
  checkEnvOutput(o.output, layout);
  const bool cube = layout != EnvLayout::LatLong;
  const EnvImage env = loadEnvironment(o.input);
  fmt::print("{}: {}\n", o.input, describe(env));

  std::optional<EnvImage> fromSh, brute;
  if (o.method != "brute") {
    const auto start = std::chrono::steady_clock::now();
    const Sh9 sh = projectSh9(env);
    const double projectSeconds = secondsSince(start);
    const auto startEval = std::chrono::steady_clock::now();
    fromSh = irradianceFromSh(sh, cube, o.size);
    fmt::print("SH: projection {:.1f} ms (full resolution), irradiance map {} in {:.1f} ms\n", 1e3 * projectSeconds,
               describe(*fromSh), 1e3 * secondsSince(startEval));
  }
  if (o.method != "sh") {
    // The integration source: the input at a reduced resolution (solid-angle-weighted
    // averaging; the cosine kernel is smooth, so this costs little accuracy), or all of it.
    const auto startResample = std::chrono::steady_clock::now();
    EnvImage source = env;
    if (o.sourceHeight > 0 && o.sourceHeight < equivalentLatLongHeight(env)) {
      if (const auto* ll = std::get_if<LatLongMap>(&env); ll && ll->height() % o.sourceHeight == 0)
        source = downsampleLatLong(*ll, ll->height() / o.sourceHeight);
      else if (std::holds_alternative<CubeMap>(env))
        source = toCube(env, std::max(1, o.sourceHeight / 2));  // exact quad solid angles
      else
        source = toLatLong(env, o.sourceHeight);
    }
    const double resampleSeconds = secondsSince(startResample);
    const auto start = std::chrono::steady_clock::now();
    brute = irradianceBruteForce(source, cube, o.size);
    fmt::print("brute force: over {} ({} texels, resampled in {:.1f} ms), irradiance map {} in {:.1f} ms\n",
               describe(source), sphereTexels(source).size(), 1e3 * resampleSeconds, describe(*brute),
               1e3 * secondsSince(start));
  }
  if (fromSh && brute) {
    const MapDifference d = compareMaps(*fromSh, *brute);
    fmt::print("SH vs brute force (relative, luminance): max {:.3f} % at direction ({:.3f}, {:.3f}, {:.3f}), "
               "RMS {:.3f} %\n",
               100.0 * d.maxRelative, d.maxAt.x, d.maxAt.y, d.maxAt.z, 100.0 * d.rmsRelative);
    saveEnvironment(o.output, *brute, layout);
    const std::string shPath = shSibling(o.output, layout);
    saveEnvironment(shPath, *fromSh, layout);
    fmt::print("wrote {} (brute force) and {} (SH)\n", o.output, shPath);
  } else {
    saveEnvironment(o.output, fromSh ? *fromSh : *brute, layout);
    fmt::print("wrote {}\n", o.output);
  }
}

void runPrefilter(const PrefilterCliOptions& o, const GlobalOptions& global) {
  Runtime runtime(global);
  const EnvLayout layout = parseEnvLayout(o.layout);
  if (layout == EnvLayout::Cube) fail("--layout cube is not supported by prefilter (use latlong, cross or vcross)");
  checkEnvOutput(o.output, layout);
  PrefilterOptions p;
  p.model = parseSpecularModel(o.model);
  p.levels = o.levels;
  p.height = o.size;
  p.samples = o.samples;
  const EnvImage env = loadEnvironment(o.input);
  const auto start = std::chrono::steady_clock::now();
  const auto levels = prefilter(env, p);
  fmt::print("{}: {}, {} levels of {} prefiltered in {:.2f} s\n", o.input, describe(env), levels.size(), o.model,
             secondsSince(start));
  for (size_t k = 0; k < levels.size(); ++k) {
    const std::string path = withTag(o.output, fmt::format("level{}", k));
    saveEnvironment(path, levels[k].map, layout);
    const float alpha = ggxAlphaFromRoughness(levels[k].roughness);
    fmt::print("  {}  roughness {:.3f} (α = {:.4g}{})  {}\n", path, levels[k].roughness, alpha,
               p.model == SpecularModel::BlinnPhong ? fmt::format(", exponent {:.4g}", blinnPhongExponentFromAlpha(alpha))
                                                    : std::string(),
               describe(levels[k].map));
  }
  const auto startLut = std::chrono::steady_clock::now();
  const Image lut = dfgTable(p.model, o.lutSize, o.lutSamples);
  const std::string lutPath = withTag(o.output, "dfg");
  writeHdrImage(lutPath, lut);
  fmt::print("  {}  split-sum table {}×{} (x = N·V, y = roughness, R = scale A, G = bias B) in {:.2f} s\n", lutPath,
             o.lutSize, o.lutSize, secondsSince(startLut));
}

void runSplitSum(const SplitSumCliOptions& o, const GlobalOptions& global) {
  Runtime runtime(global);
  if (!o.plot.empty()) {
    checkOutputPath(o.plot, {".png"}, "--plot");
  }
  SplitSumOptions s;
  s.model = parseSpecularModel(o.model);
  s.f0 = o.f0;
  s.normals = o.normals;
  s.samples = o.samples;
  s.roughness = o.roughness;
  s.viewDegrees = o.viewDegrees;
  s.seed = global.seed;
  const auto env = loadEnvironmentMap(o.input);
  const auto start = std::chrono::steady_clock::now();
  const SplitSumReport report = splitSumError(*env, s);
  const double seconds = secondsSince(start);
  if (o.json) {
    fmt::print("{}\n", splitSumToJson(report, s, o.input));
  } else {
    fmt::print("{}: split-sum (prefiltered radiance × DFG) vs exact ∫ f L cos dω, model {}, f0 {}, {} normals, "
               "{} MIS samples per strategy, {:.1f} s\n",
               o.input, o.model, o.f0, o.normals, o.samples, seconds);
    fmt::print("{}", splitSumTable(report));
  }
  if (!o.plot.empty()) {
    double maxValue = 0.0;
    for (const SplitSumCell& c : report.cells) maxValue = std::max(maxValue, c.meanAbsRelative);
    writePng(o.plot, splitSumHeatMap(report, maxValue));
    fmt::print(o.json ? stderr : stdout,
               "wrote {} (rows: roughness {}…{} top to bottom; columns: view angle {}°…{}° left to right; colour "
               "0 … {:.2f} % mean |relative error|, bar on the right)\n",
               o.plot, o.roughness.front(), o.roughness.back(), o.viewDegrees.front(), o.viewDegrees.back(),
               100.0 * maxValue);
  }
}

}  // namespace

void addEnvCommand(CLI::App& app, const GlobalOptions& global) {
  CLI::App* env = app.add_subcommand("env", "Environment maps: layouts, SH, irradiance, prefiltering, split-sum error");
  env->require_subcommand(1);
  const std::string inHelp = "Environment: .hdr/.exr/.pfm/.png (2:1 lat-long, 4:3 or 3:4 cross), a directory with "
                             "px/nx/py/ny/pz/nz images, or a pattern containing {face}";
  const auto layouts = CLI::IsMember({"latlong", "cube", "cross", "vcross"});
  const auto models = CLI::IsMember({"ggx", "blinn-phong"});

  auto convert = std::make_shared<ConvertOptions>();
  CLI::App* c = env->add_subcommand("convert", "Convert between lat-long, cube faces and cross layouts");
  c->add_option("IN", convert->input, inHelp)->required();
  c->add_option("-o,--output", convert->output,
                "Output: a file for latlong/cross/vcross; for cube a directory (gets px.hdr … nz.hdr) or a pattern "
                "containing {face}")
      ->required();
  c->add_option("--layout", convert->layout, "Output layout")->check(layouts)->capture_default_str();
  c->add_option("--size", convert->size, "Lat-long height or cube face size (0 = keep the angular resolution)")
      ->check(CLI::Range(0, kMaxMapSize))->capture_default_str();
  c->callback([convert, &global] { runConvert(*convert, global); });

  auto sh = std::make_shared<ShOptions>();
  CLI::App* s = env->add_subcommand("sh", "The 9 radiance SH coefficients per channel (double precision)");
  s->add_option("IN", sh->input, inHelp)->required();
  s->add_flag("--json", sh->json, "Print JSON instead of a table");
  s->callback([sh, &global] { runSh(*sh, global); });

  auto irr = std::make_shared<IrradianceOptions>();
  CLI::App* i = env->add_subcommand("irradiance", "Irradiance environment map by brute force and/or from SH");
  i->add_option("IN", irr->input, inHelp)->required();
  i->add_option("-o,--output", irr->output,
                "Output map; with --method both this is the brute-force map and NAME.sh.EXT the SH one")
      ->required();
  i->add_option("--method", irr->method, "sh, brute or both (both also reports their difference)")
      ->check(CLI::IsMember({"sh", "brute", "both"}))->capture_default_str();
  i->add_option("--layout", irr->layout, "Output layout")->check(layouts)->capture_default_str();
  i->add_option("--size", irr->size, "Output lat-long height (width 2×) or cube face size")
      ->check(CLI::Range(1, 4096))->capture_default_str();
  i->add_option("--source-size", irr->sourceHeight,
                "Brute force integrates over the input resampled to this lat-long height (cube: face size half of it); "
                "0 = full resolution")
      ->check(CLI::Range(0, kMaxMapSize))->capture_default_str();
  i->callback([irr, &global] { runIrradiance(*irr, global); });

  auto pre = std::make_shared<PrefilterCliOptions>();
  CLI::App* p = env->add_subcommand("prefilter", "Prefiltered specular maps per roughness and the split-sum table");
  p->add_option("IN", pre->input, inHelp)->required();
  p->add_option("-o,--output", pre->output,
                "NAME.EXT: writes NAME.level<k>.EXT for roughness k/(levels-1) and NAME.dfg.EXT (the table)")
      ->required();
  p->add_option("--model", pre->model, "BRDF model")->check(models)->capture_default_str();
  p->add_option("--levels", pre->levels, "Number of roughness levels")->check(CLI::Range(1, 32))->capture_default_str();
  p->add_option("--size", pre->size, "Lat-long height of level 0 (halved per level, not below 16)")
      ->check(CLI::Range(4, kMaxMapSize))->capture_default_str();
  p->add_option("--samples", pre->samples, "BSDF samples per texel")->check(CLI::Range(1, kMaxSamples))->capture_default_str();
  p->add_option("--layout", pre->layout, "latlong, cross or vcross")->check(layouts)->capture_default_str();
  p->add_option("--lut-size", pre->lutSize, "Split-sum table size")->check(CLI::Range(2, 4096))->capture_default_str();
  p->add_option("--lut-samples", pre->lutSamples, "Samples per table entry")
      ->check(CLI::Range(1, kMaxSamples))->capture_default_str();
  p->callback([pre, &global] { runPrefilter(*pre, global); });

  auto err = std::make_shared<SplitSumCliOptions>();
  CLI::App* e = env->add_subcommand("splitsum-error", "Split-sum approximation against the exact ∫ f L cos dω");
  e->add_option("IN", err->input, inHelp)->required();
  e->add_flag("--json", err->json, "Print JSON instead of a table");
  e->add_option("--plot", err->plot, "Write a heat map of the mean |relative error| (.png)");
  e->add_option("--model", err->model, "BRDF model")->check(models)->capture_default_str();
  e->add_option("--f0", err->f0, "Fresnel reflectance at normal incidence")->check(CLI::Range(0.0f, 1.0f))->capture_default_str();
  e->add_option("--normals", err->normals, "Surface normals (Fibonacci sphere)")->check(CLI::Range(1, 4096))->capture_default_str();
  e->add_option("--samples", err->samples, "MIS samples per strategy per integral")
      ->check(CLI::Range(2, kMaxSamples))->capture_default_str();
  e->add_option("--roughness", err->roughness, "Roughness values, comma separated, in (0, 1]")->delimiter(',');
  e->add_option("--view", err->viewDegrees, "View angles from the normal in degrees, comma separated, in [0, 90)")
      ->delimiter(',');
  e->callback([err, &global] { runSplitSum(*err, global); });
}

}  // namespace pl
