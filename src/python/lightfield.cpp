// bake, plenoptic.LightField (save, render, render_path) and load_light_field (bindings.h).

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "bindings.h"
#include "bake/parameterisation.h"
#include "bake/relight.h"
#include "bake/visibility.h"
#include "camera/camera_path.h"
#include "core/error.h"
#include "core/memory.h"
#include "plf/compression.h"
#include "plf/plf_file.h"

namespace pl::python {
namespace {

/// What relighting a light field needs (bake/relight.h), shared by the light fields relit
/// from one bake or file: the bake's parameterisation and visibility field until the first
/// relight() makes the Relighter of them, or the .plv path a loaded file relights from.
struct RelightSource {
  std::optional<Parameterisation> param;
  std::optional<VisibilityShard> visibility;
  std::string visibilityPath;
  std::shared_ptr<Relighter> relighter;
};

/// A baked or loaded light field, shared by the Python objects that refer to it.
struct PyLightField {
  std::shared_ptr<const LightField> lightField;
  py::dict stats;  ///< the bake's --stats JSON (empty for a loaded file); relight()'s for a relit one
  std::shared_ptr<RelightSource> relight;
};

/// The Relighter of `lf`, made on first use.
Relighter& relighterOf(const PyLightField& lf) {
  RelightSource& source = *lf.relight;
  if (source.relighter) return *source.relighter;
  if (source.visibility) {
    source.relighter = std::make_shared<Relighter>(*lf.lightField, std::move(*source.visibility), std::move(*source.param));
    source.visibility.reset();
    source.param.reset();
  } else if (!source.visibilityPath.empty()) {
    source.relighter = std::make_shared<Relighter>(*lf.lightField, source.visibilityPath);
  } else {
    throw UsageError(fmt::format("{}: relight needs the visibility field, which this light field no longer holds: bake "
                                 "with keep_visibility=True, or save it and load it with its .plv",
                                 lf.lightField->scene.sourcePath));
  }
  return *source.relighter;
}

py::dict relightStatsDict(const RelightStats& s) {
  py::dict d;
  d["iterations"] = s.iterations;
  d["residual"] = s.residual;
  d["converged"] = s.converged;
  d["seconds"] = s.seconds;
  d["first_frame_seconds"] = s.firstFrameSeconds;
  d["sun_mask_seconds"] = s.sunMaskSeconds;
  d["first_shot_seconds"] = s.firstShotSeconds;
  d["lights_shot"] = s.lightsShot;
  d["sun_masks_traced"] = s.sunMasksTraced;
  d["emitters_shot"] = s.emittersShot;
  return d;
}

/// Camera samples per pixel from the `spp` keyword or its former name `samples` (still
/// accepted); 0 = automatic when neither is given.
int sppKeyword(std::optional<int> spp, std::optional<int> samples) {
  if (spp && samples) throw UsageError("spp and samples are the same setting (samples is its former name): give one");
  return spp ? *spp : samples.value_or(0);
}

/// The options of one light-field render (`plenoptic render`'s flags).
RenderJobOptions renderOptions(const ViewSettings& view, int samples, uint64_t seed, bool reference, int threads,
                               bool textureLod) {
  RenderJobOptions options;
  options.render.samplesPerPixel = samples;
  options.render.seed = seed;
  options.render.textureLod = textureLod;
  options.reference = reference;
  options.view = view;
  options.threads = threads;
  return options;
}

/// The frames' cameras of render_path: a list of Cameras as they are, or a camera path file's
/// frames (camera/camera_path.h: frame k at t0 + k/fps) posed on the base camera of `view`
/// (its lens, and its fov where the path has none).
std::vector<CameraDesc> pathCameras(const py::object& path, const ViewSettings& view, const Scene& scene) {
  std::vector<CameraDesc> cameras;
  if (py::isinstance<py::str>(path)) {
    const CameraPath cameraPath = loadCameraPath(path.cast<std::string>());
    const CameraDesc baseCamera = view.resolveCamera(scene);
    for (int frame = 0; frame < cameraPath.frameCount(); ++frame)
      cameras.push_back(applyPose(baseCamera, cameraPath.at(cameraPath.frameTime(frame))));
    return cameras;
  }
  for (const py::handle item : py::iter(path)) {
    if (!py::isinstance<CameraDesc>(item))
      throw py::value_error("render_path: expected a camera path file name (str) or a list of plenoptic.Camera");
    cameras.push_back(item.cast<CameraDesc>());
  }
  if (cameras.empty()) throw UsageError("render_path: the list of cameras is empty");
  return cameras;
}

}  // namespace

void bindLightField(py::module_& m) {
  py::class_<PyLightField>(m, "LightField", "A baked light field.")
      .def_readonly("stats", &PyLightField::stats, "The bake's --stats JSON as a dict (empty for a loaded file)")
      .def(
          "save",
          [](const PyLightField& lf, const std::string& path, const std::string& compress) {
            const ValuesCodec codec = parseValuesCodec(compress);
            runInterruptible([&] { writeLightField(path, *lf.lightField, codec); });
          },
          py::arg("path"), py::arg("compress") = std::string(valuesCodecName(kDefaultValuesCodec)),
          "Writes the .plf file (compress: none, lossless, bc1, hdr; hdr, the default, is lossy within a relMSE of "
          "1e-6 in renders, none keeps the float32 values bit for bit).")
      .def(
          "render",
          [](const PyLightField& lf, int width, int height, std::optional<int> spp, const py::object& camera,
             uint64_t seed, bool reference, int threads, bool textureLod, std::optional<int> samples) {
            const RenderJob job(renderOptions(viewSettings(width, height, camera), sppKeyword(spp, samples), seed,
                                              reference, threads, textureLod));
            return toArray(runInterruptible([&] { return job.run(*lf.lightField).image; }));
          },
          py::arg("width") = 640, py::arg("height") = 480, py::arg("spp") = py::none(), py::arg("camera") = py::none(),
          py::arg("seed") = 0, py::arg("reference") = false, py::arg("threads") = 0, py::arg("texture_lod") = true,
          py::kw_only(), py::arg("samples") = py::none(),
          "Renders the light field (what `plenoptic render` does): float32 (height, width, 3), W/(sr m^2).\n"
          "spp (or its former name samples): camera samples per pixel; none or 0: 1 for a pinhole camera, 16 for a\n"
          "thin lens. reference=True: the reference renderer.\n"
          "texture_lod=False: albedo textures at full resolution (`--texture-lod off`).\n"
          "camera: a Camera, or a camera name of the scene (default: its first, else automatic).")
      .def(
          "render_path",
          [](const PyLightField& lf, const py::object& path, int width, int height, std::optional<int> spp,
             const py::object& camera, uint64_t seed, bool reference, int threads, bool textureLod,
             std::optional<int> samples) {
            const int samplesPerPixel = sppKeyword(spp, samples);
            const ViewSettings base = viewSettings(width, height, camera);
            const std::vector<CameraDesc> cameras = pathCameras(path, base, lf.lightField->scene);
            const std::vector<Image> frames = runInterruptible([&] {
              std::vector<Image> images;
              for (const CameraDesc& frameCamera : cameras) {
                RenderJobOptions options = renderOptions(base, samplesPerPixel, seed, reference, threads, textureLod);
                options.view.cameraDesc = frameCamera;
                images.push_back(RenderJob(std::move(options)).run(*lf.lightField).image);
              }
              return images;
            });
            py::list arrays;
            for (const Image& frame : frames) arrays.append(toArray(frame));
            return arrays;
          },
          py::arg("path"), py::arg("width") = 640, py::arg("height") = 480, py::arg("spp") = py::none(),
          py::arg("camera") = py::none(), py::arg("seed") = 0, py::arg("reference") = false, py::arg("threads") = 0,
          py::arg("texture_lod") = true, py::kw_only(), py::arg("samples") = py::none(),
          "Renders a walk-through: path is a camera path JSON file (what `plenoptic render --path` renders, frame k at\n"
          "t0 + k/fps, posed on `camera`) or a list of Cameras. Returns a list of float32 (height, width, 3) frames.")
      .def(
          "relight",
          [](const PyLightField& lf, const Scene& scene) {
            PyLightField out;
            out.relight = lf.relight;
            const RelightStats stats = runInterruptible([&] {
              Relighter& relighter = relighterOf(lf);
              relighter.setScene(scene);
              const RelightStats result = relighter.relight();
              out.lightField = std::make_shared<const LightField>(relighter.lightField());
              return result;
            });
            out.stats = relightStatsDict(stats);
            return out;
          },
          py::arg("scene"),
          "The light field relit for `scene` — the Scene it was baked from, edited with set_light_color,\n"
          "set_light_direction, set_emission or set_albedo — from the visibility field in memory (kept by bake, or the\n"
          ".plv beside a loaded .plf), warm-started from the last relit solution. Refused (plenoptic.Error, with the\n"
          "command that re-bakes) for changes the stored field cannot serve: geometry, a material's model, a light\n"
          "added, removed or of another type. stats: iterations, residual, converged, seconds, first_frame_seconds, ….")
      .def("__repr__", [](const PyLightField& lf) {
        const LightField& field = *lf.lightField;
        uint64_t tixels = 0;
        for (const Chart& c : field.charts) tixels += c.tixelCount();
        return fmt::format("<plenoptic.LightField of '{}': {} charts, {} tixels, {} sun-mask lights>",
                           field.scene.sourcePath, field.charts.size(), tixels, field.sunMaskLightCount);
      });

  m.def(
      "bake",
      [](const Scene& scene, const std::string& preset, uint64_t seed, int threads, std::optional<std::string> visibility,
         bool reuseVisibility, bool sunMasks, bool punctualHighlights, std::optional<int64_t> causticPhotons,
         std::optional<std::string> maxMemory, bool keepVisibility, bool fresh, std::optional<int64_t> subsurfaceWalks,
         const std::string& visibilityPrecision, const std::string& visibilityMemory) {
        BakeJobOptions options;
        if (maxMemory) options.maxMemory = parseMemorySize(*maxMemory, "max_memory");
        auto relight = std::make_shared<RelightSource>();
        if (keepVisibility) {
          relight->param.emplace();
          relight->visibility.emplace();
          options.keepParameterisation = &*relight->param;
          options.keepVisibility = &*relight->visibility;
        }
        options.sunMasks = sunMasks;
        options.punctualHighlights = punctualHighlights;
        if (visibilityPrecision != "compact" && visibilityPrecision != "exact")
          throw py::value_error(fmt::format("visibility_precision must be 'compact' or 'exact' (got '{}')", visibilityPrecision));
        options.exactVisibility = visibilityPrecision == "exact";
        if (visibilityMemory != "auto" && visibilityMemory != "held" && visibilityMemory != "streamed")
          throw py::value_error(
              fmt::format("visibility_memory must be 'auto', 'held' or 'streamed' (got '{}')", visibilityMemory));
        options.visibilityMemory = visibilityMemory;
        if (causticPhotons) {
          if (*causticPhotons < 0 || *causticPhotons > (int64_t(1) << 32))
            throw py::value_error(fmt::format("caustic_photons must be in [0, 2^32] (got {})", *causticPhotons));
          options.causticPhotons = *causticPhotons;
        }
        if (subsurfaceWalks) {
          if (*subsurfaceWalks < 1 || *subsurfaceWalks > 65536)  // `--subsurface-walks`'s range
            throw py::value_error(fmt::format("subsurface_walks must be in [1, 65536] (got {})", *subsurfaceWalks));
          options.subsurfaceWalks = uint32_t(*subsurfaceWalks);
        }
        options.sceneName = scene.sourcePath;
        options.preset = preset;
        options.seed = seed;
        options.threads = threads;
        if (visibility) options.visibilityPath = *visibility;
        options.reuseVisibility = reuseVisibility;
        options.fresh = fresh;
        const BakeJob job(std::move(options));
        BakeJobResult result = runInterruptible([&] {
          // The bake keeps its scene (in the light field); a copy must be finalized again to
          // get the vertex padding Embree reads (scene.h), which also checks the edits.
          Scene copy = scene;
          copy.finalize();
          return job.run(std::move(copy));
        });
        PyLightField lf;
        lf.stats = statsDict(result.stats.toJson());
        lf.lightField = std::make_shared<const LightField>(std::move(result.lightField));
        lf.relight = std::move(relight);
        return lf;
      },
      py::arg("scene"), py::arg("preset") = "default", py::arg("seed") = 0, py::arg("threads") = 0,
      py::arg("visibility") = py::none(), py::arg("reuse_visibility") = false, py::arg("sun_masks") = true,
      py::arg("punctual_highlights") = true, py::arg("caustic_photons") = py::none(), py::arg("max_memory") = py::none(),
      py::arg("keep_visibility") = true, py::arg("fresh") = false, py::arg("subsurface_walks") = py::none(),
      py::arg("visibility_precision") = "compact", py::arg("visibility_memory") = "auto",
      "Bakes `scene`'s light field (what `plenoptic bake` does). visibility: a .plv path where the visibility field\n"
      "is saved; with reuse_visibility=True it is read back when the geometry and settings match (so a bake after\n"
      "editing only lights or emission re-runs the propagation alone). sun_masks=False: `--sun-masks off`;\n"
      "punctual_highlights=False: `--punctual-highlights off`; caustic_photons=N: `--caustic-photons N` (None:\n"
      "the preset's); max_memory=\"12G\": `--max-memory 12G` (the bake is refused, before it starts, when its\n"
      "memory estimate exceeds it). keep_visibility=True keeps the visibility field in memory for LightField.relight\n"
      "(False frees it). With a visibility path, a bake that was interrupted resumes from what it saved there\n"
      "(docs/user-guide.md, Resuming an interrupted bake); fresh=True: `--fresh` (start afresh). subsurface_walks=N:\n"
      "`--subsurface-walks N` (random walks per tixel area through subsurface objects; None: the preset's).\n"
      "visibility_precision=\"exact\": `--visibility-precision exact` (the visibility field's fractions kept whole).\n"
      "visibility_memory=\"streamed\": `--visibility-memory streamed` (the field read from its .plv a block at a time;\n"
      "\"auto\" streams only when holding it does not fit; needs a visibility path).");

  m.def(
      "load_light_field",
      [](const std::string& path, std::optional<std::string> visibility) {
        PyLightField lf;
        lf.lightField = runInterruptible([&] { return std::make_shared<const LightField>(readLightField(path)); });
        lf.relight = std::make_shared<RelightSource>();
        lf.relight->visibilityPath = visibility ? *visibility : visibilityPathFor(path);
        return lf;
      },
      py::arg("path"), py::arg("visibility") = py::none(),
      "Reads a .plf file. visibility: the .plv that relight() reads (default: the .plf's X.plv), when first needed.");
}

}  // namespace pl::python
