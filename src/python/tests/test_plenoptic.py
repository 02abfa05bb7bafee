"""pytest suite of the Python package `plenoptic`. ctest runs it twice: as `python_tests` on the
build tree's package (PYTHONPATH=build/python) and as part of `python_package` on the package
`pip install`ed into a fresh venv, from a directory outside the source and build trees.
Environment: PLENOPTIC_BINARY names the command-line program (the tests that compare with it
are skipped without it), PLENOPTIC_TEST_DATA the repository's tests/data (default: found from
this file's place in the repository), PLENOPTIC_EXPECT_PACKAGE_IN a directory the imported
package must lie in. Small sizes: every test runs in seconds."""
import ast
import json
import os
import pty
import re
import shutil
import subprocess
import sys

import numpy as np
import pytest

import plenoptic

BINARY = os.environ.get("PLENOPTIC_BINARY", "")
DATA = os.environ.get("PLENOPTIC_TEST_DATA") or os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..",
                                                             "..", "tests", "data")


@pytest.fixture(scope="module")
def cornell():
    return plenoptic.load_scene("cornell")


def test_scene_is_readable(cornell):
    assert cornell.source == "cornell"
    assert cornell.triangle_count == 32
    assert "light" in cornell.material_names and "white" in cornell.material_names
    assert "default" in cornell.camera_names
    assert cornell.light_count == 0
    assert cornell.emission("light") == pytest.approx([18.387, 13.9873, 6.75357], rel=1e-4)


def test_version_is_the_programs():
    # __version__ is the project version (PEP 440 "X.Y.Z"); build adds the git revision, as
    # `plenoptic --version` prints it.
    parts = plenoptic.__version__.split(".")
    assert len(parts) == 3 and all(p.isdigit() for p in parts)
    assert plenoptic.build.startswith(plenoptic.__version__)
    if BINARY:
        printed = subprocess.run([BINARY, "--version"], capture_output=True, text=True, check=True).stdout.strip()
        assert printed == "plenoptic " + plenoptic.build


def test_trace_returns_float32_radiance_and_the_stats_of_the_cli(cornell):
    image, stats = plenoptic.trace(cornell, width=24, height=16, spp=4, seed=1, threads=2)
    assert image.shape == (16, 24, 3) and image.dtype == np.float32
    assert np.isfinite(image).all() and image.mean() > 0.0
    assert stats["command"] == "trace" and stats["spp"] == 4 and stats["width"] == 24 and stats["threads"] == 2
    assert stats["paths"] == 24 * 16 * 4
    image2, _, variance = plenoptic.trace(cornell, width=24, height=16, spp=4, seed=1, variance=True)
    assert variance.shape == (16, 24, 3) and variance.dtype == np.float32 and (variance >= 0).all()
    # The image depends on the seed only, never on the thread count.
    assert np.array_equal(image, image2)


@pytest.mark.skipif(not BINARY, reason="PLENOPTIC_BINARY not set")
def test_trace_equals_the_command_line_bit_for_bit(cornell, tmp_path):
    out = tmp_path / "cli.pfm"  # PFM stores float32 as it is
    subprocess.run([BINARY, "trace", "cornell", "-o", str(out), "--width", "20", "--height", "12", "--spp", "8",
                    "--seed", "7", "--quiet"], check=True, capture_output=True)
    image, _ = plenoptic.trace(cornell, width=20, height=12, spp=8, seed=7)
    assert np.array_equal(plenoptic.read_image(str(out)), image)


def test_bake_save_load_and_render(cornell, tmp_path):
    lf = plenoptic.bake(cornell, preset="draft", seed=0)
    assert lf.stats["command"] == "bake" and lf.stats["preset"] == "draft" and lf.stats["tixels"] > 0
    frame = lf.render(width=32, height=24)
    assert frame.shape == (24, 32, 3) and frame.dtype == np.float32 and frame.mean() > 0.0
    path = tmp_path / "cornell.plf"
    lf.save(str(path), compress="lossless")
    loaded = plenoptic.load_light_field(str(path))
    assert np.array_equal(loaded.render(width=32, height=24), frame)
    reference = lf.render(width=32, height=24, spp=4, reference=True)
    assert reference.shape == (24, 32, 3)
    # samples, the former name of spp, is still accepted; both at once are refused.
    assert np.array_equal(lf.render(width=32, height=24, samples=4, reference=True), reference)
    with pytest.raises(plenoptic.UsageError, match="spp and samples"):
        lf.render(width=32, height=24, spp=4, samples=4)
    # The light field against the path tracer: close in mean (the bake's draft preset).
    traced, _ = plenoptic.trace(cornell, width=32, height=24, spp=64)
    assert plenoptic.compare(reference, traced)["mean_luminance_ratio"] == pytest.approx(1.0, abs=0.1)
    # The command line's --spp and --mirror-depth ranges hold for library callers too.
    for renderer in (False, True):
        with pytest.raises(plenoptic.UsageError, match="1000000000 samples per pixel is out of range"):
            lf.render(width=32, height=24, samples=10**9, reference=renderer)


def test_texture_lod_is_a_render_option(tmp_path):
    # A 2×2-texel checker quad under a white sky, seen from far enough that its texels are
    # smaller than a pixel: with texture LOD (the default) the renderers read the minified
    # level, with texture_lod=False the texels themselves, as `plenoptic render --texture-lod off`.
    quad = os.path.join(DATA, "scene", "textured", "quad.obj")
    (tmp_path / "lit.json").write_text(json.dumps({"meshes": [{"file": quad}], "environment": {"color": 1.0}}))
    scene = plenoptic.load_scene(str(tmp_path / "lit.json"))
    lf = plenoptic.bake(scene, preset="draft")
    far = plenoptic.Camera(eye=[0.5, 0.5, 30.0], target=[0.5, 0.5, 0.0], fov=20.0)  # the quad: 1.5 pixels
    for reference in (False, True):
        lod = lf.render(width=16, height=16, camera=far, reference=reference)
        assert np.array_equal(lod, lf.render(width=16, height=16, camera=far, reference=reference, texture_lod=True))
        full = lf.render(width=16, height=16, camera=far, reference=reference, texture_lod=False)
        assert lod.mean() > 0.0 and full.mean() > 0.0
        assert not np.array_equal(lod, full)
    frames = lf.render_path([far], width=16, height=16, texture_lod=False)
    assert np.array_equal(frames[0], lf.render(width=16, height=16, camera=far, texture_lod=False))


def test_max_memory_caps_the_bake_memory_guard(cornell):
    with pytest.raises(plenoptic.Error, match="exceeds --max-memory 0.00 GiB"):
        plenoptic.bake(cornell, preset="draft", max_memory="1M")
    with pytest.raises(plenoptic.UsageError, match="max_memory: 'lots' is not a memory size"):
        plenoptic.bake(cornell, preset="draft", max_memory="lots")
    assert plenoptic.bake(cornell, preset="draft", max_memory="4G").stats["tixels"] > 0


def test_visibility_precision_is_a_bake_option(cornell, tmp_path):
    # The compact field (the default) keeps the gather's bilinear fractions to 2 bits each: a .plv
    # about half the size of the exact one, and the same light field to within a hair.
    images, sizes = {}, {}
    for precision in ("compact", "exact"):
        plv = str(tmp_path / f"{precision}.plv")
        lf = plenoptic.bake(cornell, preset="draft", visibility=plv, visibility_precision=precision)
        images[precision] = lf.render(width=32, height=32)
        sizes[precision] = os.path.getsize(plv)
    assert sizes["compact"] < 0.7 * sizes["exact"]
    difference = images["compact"] - images["exact"]
    assert (difference ** 2).sum() < 1e-6 * (images["exact"] ** 2).sum()
    with pytest.raises(ValueError, match="visibility_precision must be 'compact' or 'exact'"):
        plenoptic.bake(cornell, preset="draft", visibility_precision="lossy")


def test_visibility_memory_is_a_bake_option(cornell, tmp_path):
    # Streamed from its .plv instead of held: the same light field bit for bit, and the kept
    # (streamed) field relights as a held one does.
    held = plenoptic.bake(cornell, preset="draft", visibility=str(tmp_path / "held.plv"), visibility_memory="held")
    streamed = plenoptic.bake(cornell, preset="draft", visibility=str(tmp_path / "streamed.plv"),
                              visibility_memory="streamed")
    assert held.stats["visibility_memory"] == "held"
    assert streamed.stats["visibility_memory"] == "streamed"
    assert np.array_equal(held.render(width=32, height=32), streamed.render(width=32, height=32))
    assert np.array_equal(held.relight(cornell).render(width=16, height=16),
                          streamed.relight(cornell).render(width=16, height=16))
    with pytest.raises(plenoptic.UsageError, match="streamed from its .plv, and this bake saves none"):
        plenoptic.bake(cornell, preset="draft", visibility_memory="streamed")
    with pytest.raises(ValueError, match="visibility_memory must be 'auto', 'held' or 'streamed'"):
        plenoptic.bake(cornell, preset="draft", visibility_memory="sometimes")


def test_sun_masks_are_a_bake_option(tmp_path):
    # A quad in the sun: with sun masks (the default) the directional light is stored as masks
    # and added back at render time, with sun_masks=False it stays in the values, as
    # `plenoptic bake --sun-masks off`; a wholly lit quad looks the same either way.
    quad = os.path.join(DATA, "scene", "textured", "quad.obj")
    (tmp_path / "sun.json").write_text(json.dumps({
        "meshes": [{"file": quad}],
        "lights": [{"type": "directional", "direction": [0.3, 0.2, -1.0], "irradiance": [2.0, 2.0, 2.0]}]}))
    scene = plenoptic.load_scene(str(tmp_path / "sun.json"))
    masked = plenoptic.bake(scene, preset="draft")
    plain = plenoptic.bake(scene, preset="draft", sun_masks=False)
    assert masked.stats["sun_mask_lights"] == 1 and plain.stats["sun_mask_lights"] == 0
    camera = plenoptic.Camera(eye=[0.5, 0.5, 2.0], target=[0.5, 0.5, 0.0], fov=30.0)
    a = masked.render(width=16, height=16, camera=camera)
    b = plain.render(width=16, height=16, camera=camera)
    assert a.mean() > 0.0
    # Only the rounding of taking the sun out of the stored irradiance and adding it back
    # (measured: 2 ulps).
    assert np.allclose(a, b, rtol=1e-6, atol=0.0)


def test_punctual_highlights_are_a_bake_option(tmp_path):
    # A glossy quad under a point light, seen from above: with punctual highlights (the
    # default) the renderers evaluate the light's reflection per pixel, with
    # punctual_highlights=False it stays in the glossy maps, smeared over a map texel. Against
    # the path tracer (measured at 32x32, 16 samples vs 256 spp: relMSE 0.00023 with them,
    # 0.052 without).
    quad = os.path.join(DATA, "scene", "textured", "quad.obj")
    (tmp_path / "lamp.json").write_text(json.dumps({
        "meshes": [{"file": quad, "material": "shiny"}],
        "materials": {"shiny": {"type": "ggx", "diffuse": 0.2, "f0": 0.04, "roughness": 0.1}},
        "lights": [{"type": "point", "position": [0.5, 0.5, 1.0], "intensity": [1.0, 1.0, 1.0]}]}))
    scene = plenoptic.load_scene(str(tmp_path / "lamp.json"))
    camera = plenoptic.Camera(eye=[0.5, 0.5, 2.0], target=[0.5, 0.5, 0.0], fov=30.0)
    reference, _ = plenoptic.trace(scene, width=32, height=32, spp=256, camera=camera)
    errors = []
    for highlights in (True, False):
        lf = plenoptic.bake(scene, preset="draft", punctual_highlights=highlights)
        image = lf.render(width=32, height=32, spp=16, camera=camera)
        errors.append(plenoptic.compare(image, reference)["relmse"])
    print("relMSE with and without punctual highlights:", errors)
    assert errors[0] < 0.005 and errors[1] > 10.0 * errors[0]


def test_caustic_photons_is_a_bake_option():
    # McGuire's mirror box: its lamp's light through the mirrors is shot as photons (the
    # count is in the stats), or left to the gather with caustic_photons=0.
    scene = plenoptic.load_scene(os.path.join(DATA, "cornell-mcguire", "CornellBox-Mirror.obj"))
    shot = plenoptic.bake(scene, preset="draft", caustic_photons=1 << 14)
    assert shot.stats["caustic_photons"] == 1 << 14
    assert 0 < shot.stats["caustic_photons_landed"] < 1 << 14
    assert plenoptic.bake(scene, preset="draft", caustic_photons=0).stats["caustic_photons"] == 0
    with pytest.raises(ValueError, match="caustic_photons"):
        plenoptic.bake(scene, preset="draft", caustic_photons=-1)


def test_subsurface_walks_is_a_bake_option(tmp_path):
    # The repository's subsurface furnace (a sphere and a slab under a white sky): the walks per
    # tixel area are recorded in the saved light field's settings (META), as `--subsurface-walks`
    # records them; out of [1, 65536] raises before anything is baked.
    scene = plenoptic.load_scene(os.path.join(DATA, "..", "..", "bench", "scenes", "sss-furnace.json"))
    path = str(tmp_path / "walks.plf")
    plenoptic.bake(scene, preset="draft", subsurface_walks=3).save(path)
    with open(path, "rb") as f:
        assert re.search(rb'"subsurface_walks":\s*3\b', f.read())
    for bad in (0, 65537):
        with pytest.raises(ValueError, match="subsurface_walks"):
            plenoptic.bake(scene, preset="draft", subsurface_walks=bad)


def test_editing_emission_and_rebaking_with_the_reused_visibility_equals_a_full_bake(tmp_path):
    scene = plenoptic.load_scene("cornell")
    visibility = str(tmp_path / "cornell.plv")
    plenoptic.bake(scene, preset="draft", visibility=visibility)
    scene.set_emission("light", [30.0, 20.0, 10.0])
    assert scene.emission("light") == [30.0, 20.0, 10.0]
    reused = plenoptic.bake(scene, preset="draft", visibility=visibility, reuse_visibility=True)
    assert reused.stats["reused_visibility"] is True
    full = plenoptic.bake(scene, preset="draft")
    assert full.stats["reused_visibility"] is False
    assert np.array_equal(reused.render(width=32, height=24), full.render(width=32, height=24))


def test_a_finished_bake_leaves_no_resume_files_and_fresh_starts_over(tmp_path):
    scene = plenoptic.load_scene("cornell")
    visibility = str(tmp_path / "cornell.plv")
    first = plenoptic.bake(scene, preset="draft", visibility=visibility)
    # The journal of the trace and the propagation checkpoint are gone once the bake is done.
    assert sorted(p.name for p in tmp_path.iterdir()) == ["cornell.pls", "cornell.plt", "cornell.plv"]
    again = plenoptic.bake(scene, preset="draft", visibility=visibility, fresh=True)
    assert np.array_equal(first.render(width=32, height=24), again.render(width=32, height=24))


def test_relight_equals_a_fresh_bake_of_the_edited_scene():
    scene = plenoptic.load_scene("cornell")
    lf = plenoptic.bake(scene, preset="draft")
    scene.set_emission("light", [30.0, 20.0, 10.0])
    scene.set_albedo("red", [0.2, 0.5, 0.7])
    relit = lf.relight(scene)
    assert relit.stats["converged"] is True and relit.stats["lights_shot"] == 0
    fresh = plenoptic.bake(scene, preset="draft")
    a, b = relit.render(width=32, height=24), fresh.render(width=32, height=24)
    # Both stop at the draft preset's tolerance (5e-3 of the total power).
    assert plenoptic.compare(a, b)["mean_luminance_ratio"] == pytest.approx(1.0, abs=5e-3)
    assert plenoptic.compare(a, lf.render(width=32, height=24))["relmse"] > 0.01  # the edit shows
    # Relighting again goes on from the relit solution; the original light field is unchanged.
    scene.set_emission("light", [10.0, 10.0, 10.0])
    again = relit.relight(scene)
    assert again.stats["converged"] is True
    assert np.array_equal(lf.render(width=8, height=6), plenoptic.bake(plenoptic.load_scene("cornell"),
                                                                       preset="draft").render(width=8, height=6))


def test_relight_moves_the_sun_of_a_loaded_light_field_from_its_plv(tmp_path):
    quad = os.path.join(DATA, "scene", "textured", "quad.obj")
    (tmp_path / "sun.json").write_text(json.dumps({
        "meshes": [{"file": quad}], "environment": {"color": [0.1, 0.1, 0.1]},
        "lights": [{"type": "directional", "direction": [0.3, 0.2, -1.0], "irradiance": [2.0, 2.0, 2.0]}]}))
    scene = plenoptic.load_scene(str(tmp_path / "sun.json"))
    plenoptic.bake(scene, preset="draft", visibility=str(tmp_path / "sun.plv")).save(str(tmp_path / "sun.plf"))
    loaded = plenoptic.load_light_field(str(tmp_path / "sun.plf"))
    scene.set_light_direction(0, [0.0, 0.0, -1.0])  # straight down: more light on the quad
    relit = loaded.relight(scene)
    assert relit.stats["sun_masks_traced"] == 1 and relit.stats["lights_shot"] == 1
    camera = plenoptic.Camera(eye=[0.5, 0.5, 2.0], target=[0.5, 0.5, 0.0], fov=30.0)
    fresh = plenoptic.bake(scene, preset="draft").render(width=16, height=16, camera=camera)
    assert np.allclose(relit.render(width=16, height=16, camera=camera), fresh, rtol=5e-3, atol=1e-6)
    with pytest.raises(plenoptic.UsageError, match="light 3 does not exist"):
        scene.set_light_direction(3, [0.0, 0.0, -1.0])


def test_relight_refuses_what_the_visibility_field_cannot_serve(tmp_path):
    scene = plenoptic.load_scene("cornell")
    lf = plenoptic.bake(scene, preset="draft")
    lf.save(str(tmp_path / "alone.plf"))
    # Loaded without its .plv: the message names the file it needs.
    with pytest.raises(plenoptic.Error, match="alone.plv"):
        plenoptic.load_light_field(str(tmp_path / "alone.plf")).relight(scene)
    with pytest.raises(plenoptic.Error, match="keep_visibility"):
        plenoptic.bake(scene, preset="draft", keep_visibility=False).relight(scene)
    other = plenoptic.load_scene(os.path.join(DATA, "cornell-mcguire", "CornellBox-Original.obj"))
    with pytest.raises(plenoptic.Error, match="cannot relight.*plenoptic bake"):
        lf.relight(other)
    with pytest.raises(plenoptic.UsageError, match="at most 1"):
        scene.set_albedo("red", [2.0, 0.0, 0.0])


def test_image_round_trip_and_compare(tmp_path):
    rng = np.random.default_rng(3)
    image = rng.random((5, 7, 3), dtype=np.float32)
    path = str(tmp_path / "x.pfm")
    plenoptic.write_image(path, image)
    assert np.array_equal(plenoptic.read_image(path), image)
    same = plenoptic.compare(image, image)
    assert same["relmse"] == 0.0 and same["mean_ratio_rgb"] == [1.0, 1.0, 1.0]
    assert same["identical"] is True and same["psnr"] is None  # infinite: null in JSON
    # The same keys and values as `plenoptic compare --json` (which adds the file names).
    if BINARY:
        plenoptic.write_image(str(tmp_path / "b.pfm"), image * 1.5)
        cli = json.loads(subprocess.run([BINARY, "compare", str(tmp_path / "b.pfm"), path, "--json"],
                                        capture_output=True, text=True, check=True).stdout)
        assert {k: v for k, v in cli.items() if k not in ("a", "b")} == plenoptic.compare(image * 1.5, image)
    assert plenoptic.compare(image * 2, image)["mean_luminance_ratio"] == pytest.approx(2.0)


def test_arrays_of_any_float_dtype_and_layout_are_converted(tmp_path):
    # The same pixels as float32 C order, float64, float16, Fortran order, strided views: every
    # call sees the float32 values NumPy's cast gives.
    rng = np.random.default_rng(11)
    base = (rng.random((6, 8, 3)) * 4.0).astype(np.float16).astype(np.float32)  # exact in float16 too
    variants = {
        "float64": base.astype(np.float64),
        "float16": base.astype(np.float16),
        "fortran": np.asfortranarray(base),
        "strided": np.repeat(base, 2, axis=1)[:, ::2, :],
        "channel-last view": np.moveaxis(np.ascontiguousarray(np.moveaxis(base, 2, 0)), 0, 2),
    }
    assert not variants["fortran"].flags.c_contiguous and not variants["strided"].flags.c_contiguous
    assert not variants["channel-last view"].flags.c_contiguous
    reference = plenoptic.tone_map(base)
    for name, array in variants.items():
        assert np.array_equal(plenoptic.tone_map(array), reference), name
        assert plenoptic.compare(array, base)["identical"], name
        path = str(tmp_path / "x.pfm")
        plenoptic.write_image(path, array)
        assert np.array_equal(plenoptic.read_image(path), base), name
    # Negative strides: a flipped view is read in its own (flipped) order.
    assert np.array_equal(plenoptic.tone_map(base[::-1, ::-1]), reference[::-1, ::-1])
    # float64 values are rounded to the nearest float32.
    fine = np.full((2, 2, 3), 1.0 + 2.0 ** -30, dtype=np.float64)
    plenoptic.write_image(str(tmp_path / "fine.pfm"), fine)
    assert (plenoptic.read_image(str(tmp_path / "fine.pfm")) == np.float32(1.0)).all()
    env = np.ones((16, 32, 3), dtype=np.float64)
    assert np.allclose(plenoptic.sh9(np.asfortranarray(env)), plenoptic.sh9(env.astype(np.float32)), rtol=0, atol=0)
    # The input is not modified (a converted copy is read, never written).
    before = variants["float64"].copy()
    plenoptic.compare(variants["float64"], base)
    assert np.array_equal(before, variants["float64"])


def test_arrays_of_the_wrong_shape_or_kind_are_refused(tmp_path):
    path = str(tmp_path / "x.pfm")
    # An integer array is most likely an 8-bit picture, not radiance: refused, not converted.
    for dtype in (np.uint8, np.int32, np.bool_, np.complex64):
        with pytest.raises(ValueError, match="floating-point"):
            plenoptic.write_image(path, np.zeros((4, 4, 3), dtype=dtype))
    with pytest.raises(ValueError, match="shape"):
        plenoptic.write_image(path, np.zeros((4, 4), dtype=np.float32))
    with pytest.raises(ValueError, match="shape"):
        plenoptic.compare(np.zeros((4, 4, 4), dtype=np.float32), np.zeros((4, 4, 3), dtype=np.float32))
    with pytest.raises(ValueError, match="empty"):
        plenoptic.tone_map(np.zeros((0, 4, 3), dtype=np.float64))
    with pytest.raises(ValueError, match="NumPy"):
        plenoptic.write_image(path, [[1.0, 2.0, 3.0]])
    assert not os.path.exists(path)


def test_errors_are_plenoptic_exceptions_with_the_cli_messages(cornell, tmp_path):
    assert issubclass(plenoptic.UsageError, plenoptic.Error) and issubclass(plenoptic.UsageError, ValueError)
    with pytest.raises(plenoptic.Error, match="no such file"):
        plenoptic.load_scene(str(tmp_path / "missing.obj"))
    with pytest.raises(plenoptic.Error, match="preset"):
        plenoptic.bake(cornell, preset="best")
    with pytest.raises(plenoptic.Error, match="out of range"):
        plenoptic.trace(cornell, width=0, height=4, spp=1)
    with pytest.raises(plenoptic.UsageError, match="maximum depth 1000000000 is out of range"):
        plenoptic.trace(cornell, width=4, height=4, spp=1, max_depth=10**9)
    with pytest.raises(plenoptic.UsageError, match="no material"):
        cornell.set_emission("nothing", [1.0, 1.0, 1.0])
    with pytest.raises(plenoptic.UsageError, match="light 0 does not exist"):
        cornell.set_light_color(0, [1.0, 1.0, 1.0])
    with pytest.raises(plenoptic.UsageError, match="non-negative"):
        cornell.set_emission("light", [-1.0, 0.0, 0.0])
    with pytest.raises(plenoptic.Error, match="missing.plf: cannot open light field"):
        plenoptic.load_light_field(str(tmp_path / "missing.plf"))


def test_file_errors_are_oserrors_naming_the_file_and_bad_arguments_are_valueerrors(cornell, tmp_path):
    assert issubclass(plenoptic.FileError, plenoptic.Error) and issubclass(plenoptic.FileError, OSError)
    assert not issubclass(plenoptic.FileError, ValueError)
    missing = str(tmp_path / "missing")
    cases = [(lambda: plenoptic.load_scene(missing + ".obj"), missing + ".obj"),
             (lambda: plenoptic.load_light_field(missing + ".plf"), missing + ".plf"),
             (lambda: plenoptic.read_image(missing + ".exr"), missing + ".exr"),
             (lambda: plenoptic.write_image(missing + "/x.pfm", np.zeros((2, 2, 3), np.float32)), missing + "/x.pfm")]
    for call, name in cases:
        with pytest.raises(OSError) as raised:
            call()
        assert raised.value.filename == name and name in str(raised.value)
        assert isinstance(raised.value, plenoptic.Error) and not isinstance(raised.value, ValueError)
    lf = plenoptic.bake(cornell, preset="draft")
    with pytest.raises(OSError) as raised:
        lf.render_path(missing + ".json", width=4, height=4)
    assert raised.value.filename == missing + ".json"
    # What is wrong with the request, not with a file, stays a ValueError and no OSError.
    with pytest.raises(ValueError) as raised:
        cornell.set_emission("nothing", [1.0, 1.0, 1.0])
    assert isinstance(raised.value, plenoptic.Error) and not isinstance(raised.value, OSError)
    # A file that exists but holds garbage is an Error about its content, not an OSError.
    garbage = tmp_path / "garbage.plf"
    garbage.write_bytes(b"not a light field")
    with pytest.raises(plenoptic.Error, match="garbage.plf") as raised:
        plenoptic.load_light_field(str(garbage))
    assert not isinstance(raised.value, OSError)


def test_a_python_camera_equals_the_same_camera_given_on_the_command_line(cornell):
    default = cornell.camera("default")
    camera = plenoptic.Camera(eye=default.eye, target=default.target, up=default.up, fov=default.fov)
    assert camera.fov == pytest.approx(default.fov) and camera.fstop == 0.0 and camera.eye == default.eye
    by_name, _ = plenoptic.trace(cornell, width=16, height=12, spp=2, seed=3, camera="default")
    by_camera, stats = plenoptic.trace(cornell, width=16, height=12, spp=2, seed=3, camera=camera)
    assert stats["camera"] == "python"
    assert np.array_equal(by_name, by_camera)
    # A camera looking elsewhere gives another picture; a narrower fov another again.
    moved = plenoptic.Camera(eye=[default.eye[0] + 100.0, default.eye[1], default.eye[2]], target=default.target,
                             fov=default.fov)
    assert not np.array_equal(plenoptic.trace(cornell, width=16, height=12, spp=2, seed=3, camera=moved)[0], by_name)


@pytest.mark.skipif(not BINARY, reason="PLENOPTIC_BINARY not set")
def test_a_python_thin_lens_camera_equals_the_command_line_flags(cornell, tmp_path):
    camera = plenoptic.Camera([278.0, 273.0, -600.0], [278.0, 273.0, 0.0], fov=35.0, fstop=2.0, focus_distance=700.0)
    out = tmp_path / "cli.pfm"
    subprocess.run([BINARY, "trace", "cornell", "-o", str(out), "--width", "16", "--height", "12", "--spp", "4",
                    "--eye", "278,273,-600", "--target", "278,273,0", "--up", "0,1,0", "--fov", "35",
                    "--aperture", "2", "--focus-distance", "700", "--quiet"], check=True, capture_output=True)
    image, _ = plenoptic.trace(cornell, width=16, height=12, spp=4, camera=camera)
    assert np.array_equal(plenoptic.read_image(str(out)), image)


def test_light_field_renders_with_a_python_camera_and_along_a_camera_path(cornell, tmp_path):
    lf = plenoptic.bake(cornell, preset="draft")
    default = cornell.camera("default")
    camera = plenoptic.Camera(default.eye, default.target, default.up, default.fov)
    frame = lf.render(width=24, height=16, camera=camera)
    assert np.array_equal(frame, lf.render(width=24, height=16, camera="default"))
    moved = plenoptic.Camera([default.eye[0] + 100.0, default.eye[1], default.eye[2]], default.target, fov=default.fov)
    frames = lf.render_path([camera, moved], width=24, height=16)
    assert len(frames) == 2 and frames[0].shape == (16, 24, 3) and frames[0].dtype == np.float32
    assert np.array_equal(frames[0], frame) and np.array_equal(frames[1], lf.render(width=24, height=16, camera=moved))
    # A path file of 0.1 s at 20 fps: 3 frames, the first on the first keyframe, the last on the last.
    path = tmp_path / "walk.json"
    path.write_text(json.dumps({"fps": 20, "keyframes": [
        {"time": 0.0, "eye": default.eye, "target": default.target, "fov": default.fov},
        {"time": 0.1, "eye": moved.eye, "target": default.target, "fov": default.fov}]}))
    walked = lf.render_path(str(path), width=24, height=16)
    assert len(walked) == 3
    assert np.array_equal(walked[0], frame) and np.array_equal(walked[2], frames[1])
    assert not np.array_equal(walked[1], walked[0]) and not np.array_equal(walked[1], walked[2])


def test_bad_cameras_and_camera_paths_raise(cornell, tmp_path):
    with pytest.raises(ValueError, match="coincide"):
        plenoptic.Camera([0.0, 0.0, 0.0], [0.0, 0.0, 0.0])
    with pytest.raises(ValueError, match="field of view"):
        plenoptic.Camera([0.0, 0.0, 1.0], [0.0, 0.0, 0.0], fov=180.0)
    with pytest.raises(ValueError, match="fstop"):
        plenoptic.Camera([0.0, 0.0, 1.0], [0.0, 0.0, 0.0], fstop=-1.0)
    with pytest.raises(ValueError, match="three numbers"):
        plenoptic.Camera([0.0, 1.0], [0.0, 0.0, 0.0])
    with pytest.raises(ValueError, match="camera"):
        plenoptic.trace(cornell, width=4, height=4, spp=1, camera=3)
    lf = plenoptic.bake(cornell, preset="draft")
    with pytest.raises(ValueError, match="empty"):
        lf.render_path([], width=4, height=4)
    with pytest.raises(ValueError, match="list of plenoptic.Camera"):
        lf.render_path(["default"], width=4, height=4)
    bad = tmp_path / "bad.json"
    bad.write_text('{"keyframes": [{"time": 0, "eye": [0, 0], "target": [0, 0, 0]}]}')
    with pytest.raises(plenoptic.Error, match="bad.json"):
        lf.render_path(str(bad), width=4, height=4)


def test_exposure_scale_follows_the_closed_forms():
    assert plenoptic.exposure_scale() == 1.0
    assert plenoptic.exposure_scale(ev=1.0) == pytest.approx(2.0)
    assert plenoptic.exposure_scale(ev=-2.0) == pytest.approx(0.25)
    # ISO 12232 saturation exposure: 1 / (1.2 * 2^EV100), EV100 = log2(N^2/t * 100/S).
    ev100 = np.log2(16.0 ** 2 / 0.008 * 100.0 / 200.0)
    assert plenoptic.exposure_scale(fstop=16.0, shutter=0.008, iso=200.0) == pytest.approx(1.0 / (1.2 * 2.0 ** ev100),
                                                                                           rel=1e-5)
    with pytest.raises(ValueError, match="all three"):
        plenoptic.exposure_scale(fstop=16.0)
    with pytest.raises(ValueError, match="tonemap|reinhard"):
        plenoptic.exposure_scale(tonemap="filmic")


def test_tone_map_encodes_srgb_and_write_image_png_equals_the_command_line(tmp_path):
    # clamp keeps values in [0, 1]; the sRGB encoding of 0.5 is 0.7354 -> 188, of 0.0031308 -> 0.04045 -> 10.
    flat = np.full((2, 3, 3), 0.5, dtype=np.float32)
    flat[0, 0] = [0.0, 1.0, 0.0031308]
    mapped = plenoptic.tone_map(flat, tonemap="clamp")
    assert mapped.dtype == np.uint8 and mapped.shape == (2, 3, 3)
    assert (mapped[1] == 188).all() and mapped[0, 0].tolist() == [0, 255, 10]
    # Exposure scales before the curve: ev=1 on 0.25 is 0.5.
    assert np.array_equal(plenoptic.tone_map(flat * 0.5, tonemap="clamp", ev=1.0)[1], mapped[1])
    rng = np.random.default_rng(5)
    hdr = (rng.random((6, 8, 3), dtype=np.float32) * 4.0).astype(np.float32)
    png = str(tmp_path / "py.png")
    plenoptic.write_image(png, hdr, ev=0.5, tonemap="reinhard", white=3.0)
    decoded = plenoptic.read_image(png)  # sRGB-decoded back to linear
    bytes_ = plenoptic.tone_map(hdr, ev=0.5, tonemap="reinhard", white=3.0).astype(np.float64) / 255.0
    linear = np.where(bytes_ <= 0.04045, bytes_ / 12.92, ((bytes_ + 0.055) / 1.055) ** 2.4)
    assert np.allclose(decoded, linear, atol=1e-5)
    if BINARY:
        exr = str(tmp_path / "in.pfm")
        plenoptic.write_image(exr, hdr)
        cli = str(tmp_path / "cli.png")
        subprocess.run([BINARY, "tonemap", exr, "-o", cli, "--exposure", "0.5", "--tonemap", "reinhard", "--white", "3",
                        "--quiet"], check=True, capture_output=True)
        assert np.array_equal(plenoptic.read_image(cli), decoded)
    with pytest.raises(ValueError, match="expected a"):
        plenoptic.write_image(str(tmp_path / "x.tiff"), hdr)
    assert not os.path.exists(str(tmp_path / "x.tiff"))


def test_environment_tools_on_a_constant_environment_follow_the_closed_forms():
    # L = 1 everywhere: L00 = 4*pi*Y00 = 2*sqrt(pi), the other coefficients 0; E(n) = pi; every
    # prefiltered level is 1 (a normalised BRDF-weighted mean of a constant).
    env = np.ones((16, 32, 3), dtype=np.float32)
    sh = plenoptic.sh9(env)
    assert sh.shape == (9, 3) and sh.dtype == np.float64
    # The texel solid angles sum to 4*pi exactly, so the SH projection and the SH irradiance of a
    # constant are exact to rounding (measured: 0 and 1.6e-15); the brute-force sum evaluates
    # max(0, n.w) once per 16 x 32 texel, a quadrature error of 0.23 % here (measured).
    assert sh[0] == pytest.approx([2.0 * np.sqrt(np.pi)] * 3, rel=1e-6)
    assert np.abs(sh[1:]).max() < 1e-6
    for method, tolerance in (("sh", 1e-6), ("brute", 5e-3)):
        irradiance = plenoptic.irradiance(env, size=8, method=method)
        assert irradiance.shape == (8, 16, 3) and irradiance.dtype == np.float32
        assert np.allclose(irradiance, np.pi, rtol=tolerance)
    levels = plenoptic.prefilter(env, levels=3, height=16, samples=16)
    assert [roughness for roughness, _ in levels] == pytest.approx([0.0, 0.5, 1.0])
    assert levels[0][1].shape == (16, 32, 3) and levels[0][1].dtype == np.float32
    for _, level in levels:
        assert np.allclose(level, 1.0, rtol=1e-6)  # a normalised weighted mean: exact to rounding (measured 0)
    # A sky brighter above than below: upward irradiance exceeds downward (row 0 is +y, up).
    sky = np.ones((16, 32, 3), dtype=np.float32)
    sky[8:] = 0.1
    irradiance = plenoptic.irradiance(sky, size=8, method="brute")
    assert irradiance[0].mean() > 2.0 * irradiance[-1].mean()


def test_environment_tools_refuse_bad_arrays_and_arguments():
    env = np.ones((16, 32, 3), dtype=np.float32)
    with pytest.raises(ValueError, match="twice as wide"):
        plenoptic.sh9(np.ones((16, 16, 3), dtype=np.float32))
    with pytest.raises(ValueError, match="floating-point"):
        plenoptic.sh9(env.astype(np.uint8))
    with pytest.raises(ValueError, match="method"):
        plenoptic.irradiance(env, method="fast")
    with pytest.raises(ValueError, match="out of range"):
        plenoptic.irradiance(env, size=0)
    with pytest.raises(ValueError, match="out of range"):
        plenoptic.prefilter(env, levels=0)
    with pytest.raises(ValueError, match="model"):
        plenoptic.prefilter(env, model="phong")


def test_the_package_has_its_stubs_and_is_the_expected_one():
    # PEP 561: the stubs and the py.typed marker lie beside __init__.py, wherever the package is.
    package = os.path.dirname(os.path.abspath(plenoptic.__file__))
    for name in ("__init__.py", "__init__.pyi", "py.typed"):
        assert os.path.isfile(os.path.join(package, name)), name
    assert os.path.dirname(plenoptic._plenoptic.__file__) == package
    where = os.environ.get("PLENOPTIC_EXPECT_PACKAGE_IN")
    if where:  # the installed package, not the build or source tree
        assert os.path.realpath(package).startswith(os.path.realpath(where) + os.sep), package


def signature_parameters(function):
    """The parameter names of a pybind11 function, from the signature its docstring starts with
    ("name(a: int, b: List[float] = [0.0, 1.0]) -> None"), without self."""
    line = function.__doc__.split("\n", 1)[0]
    text = line[line.index("(") + 1:]
    parameters, depth, current = [], 0, ""
    for char in text:
        if char in "([{":
            depth += 1
        elif char in ")]}":
            if depth == 0:
                break
            depth -= 1
        if char == "," and depth == 0:
            parameters.append(current)
            current = ""
        else:
            current += char
    parameters.append(current)
    names = [p.split(":")[0].split("=")[0].strip() for p in parameters if p.strip()]
    return [name for name in names if name != "self"]


def stub_parameters(node):
    """The parameter names of a stub, keyword-only ones after a "*" as pybind11 writes them."""
    names = [a.arg for a in node.args.args if a.arg != "self"]
    if node.args.kwonlyargs:
        names += ["*"] + [a.arg for a in node.args.kwonlyargs]
    return names


def stub_members(body):
    members = {}
    for node in body:
        if isinstance(node, (ast.FunctionDef, ast.ClassDef)):
            members[node.name] = node
        elif isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
            members[node.target.id] = node
        elif isinstance(node, ast.Assign):
            members.update((target.id, node) for target in node.targets if isinstance(target, ast.Name))
    return members


def test_the_stubs_name_every_function_class_and_parameter():
    # __init__.pyi against the module itself, so that the two cannot drift apart: the same
    # public names, the same members of each class, and every function's and method's
    # parameter names in the same order.
    path = os.path.join(os.path.dirname(plenoptic.__file__), "__init__.pyi")
    with open(path) as stub_file:
        stub = stub_members(ast.parse(stub_file.read()).body)
    public = {name for name in stub if not name.startswith("_")}
    assert public == set(plenoptic.__all__)
    assert public == {name for name in dir(plenoptic) if not name.startswith("_")}
    assert "__version__" in stub
    for name in sorted(public):
        runtime, node = getattr(plenoptic, name), stub[name]
        if isinstance(node, ast.FunctionDef):
            assert callable(runtime), name
            assert stub_parameters(node) == signature_parameters(runtime), name
        elif isinstance(node, ast.ClassDef):
            assert isinstance(runtime, type), name
            assert [b.id for b in node.bases if isinstance(b, ast.Name)] == [
                b.__name__ for b in runtime.__bases__ if b.__name__ != "pybind11_object"], name
            if issubclass(runtime, BaseException):
                continue
            members = stub_members(node.body)
            # (A class made in Python only has pybind11's constructor that raises "No constructor
            # defined", whose docstring has no signature.)
            defined = {m for m in vars(runtime) if not m.startswith("_") or m == "__repr__"}
            if (vars(runtime)["__init__"].__doc__ or "").startswith("__init__("):
                defined.add("__init__")
            assert set(members) == defined, name
            for member, member_node in members.items():
                attribute = vars(runtime)[member]
                if isinstance(attribute, property):
                    assert any(isinstance(d, ast.Name) and d.id == "property" for d in member_node.decorator_list), \
                        f"{name}.{member}"
                elif isinstance(member_node, ast.FunctionDef):
                    assert stub_parameters(member_node) == signature_parameters(attribute), f"{name}.{member}"
        else:
            assert not callable(runtime), name


def test_every_class_has_a_repr_that_names_the_package(cornell):
    classes = [getattr(plenoptic, n) for n in plenoptic.__all__ if isinstance(getattr(plenoptic, n), type)]
    for cls in classes:
        assert cls.__module__ == "plenoptic", cls
        if not issubclass(cls, BaseException):
            assert "__repr__" in vars(cls), cls
    assert plenoptic.trace.__module__ == "plenoptic"
    assert repr(cornell) == "<plenoptic.Scene 'cornell': 32 triangles, 4 materials, 2 cameras, 0 lights>"
    camera = cornell.camera("default")
    assert repr(camera).startswith("plenoptic.Camera(eye=[278, 273, -800], target=[278, 273, 0], up=[0, 1, 0], fov=")
    # A Camera's repr is the call that makes it again.
    again = eval(repr(camera), {"plenoptic": plenoptic})
    assert (again.eye, again.target, again.up, again.fov, again.name) == (camera.eye, camera.target, camera.up,
                                                                          camera.fov, camera.name)
    lf = plenoptic.bake(cornell, preset="draft")
    assert re.fullmatch(r"<plenoptic\.LightField of 'cornell': \d+ charts, %d tixels, 0 sun-mask lights>"
                        % lf.stats["tixels"], repr(lf)), repr(lf)
    assert repr(plenoptic.UsageError("x")) == "UsageError('x')"


# Progress bars: only on a terminal unless set_progress says otherwise, and never a carriage
# return in captured output.
PROGRESS_SCRIPT = r"""
import contextlib, io, sys
import plenoptic
setting = {setting}
if setting != "default":
    plenoptic.set_progress(setting)
scene = plenoptic.load_scene("cornell")
if {redirect}:
    with contextlib.redirect_stderr(io.StringIO()):
        plenoptic.trace(scene, width=32, height=32, spp=4)
else:
    plenoptic.trace(scene, width=32, height=32, spp=4)
"""


def run_with_terminal_stderr(setting, redirect=False):
    """What a script writes to its stderr when that is a terminal (a pseudo-terminal here)."""
    master, slave = pty.openpty()
    code = PROGRESS_SCRIPT.replace("{setting}", setting).replace("{redirect}", str(redirect))
    process = subprocess.Popen([sys.executable, "-c", code], stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                               stderr=slave)
    os.close(slave)
    output = b""
    while True:
        try:
            chunk = os.read(master, 4096)
        except OSError:  # EIO: the child closed the terminal
            break
        if not chunk:
            break
        output += chunk
    os.close(master)
    assert process.wait(timeout=120) == 0, output
    return output.decode()


def test_progress_bars_only_on_a_terminal_by_default():
    assert plenoptic.get_progress() is None
    on_terminal = run_with_terminal_stderr('"default"')
    assert "tracing" in on_terminal and "\r" in on_terminal  # the bar redraws its line
    assert "tracing" not in run_with_terminal_stderr("False")
    # sys.stderr replaced (as pytest's capsys, Jupyter or redirect_stderr do): no bar either.
    assert "tracing" not in run_with_terminal_stderr('"default"', redirect=True)


def test_captured_output_holds_no_progress_and_never_a_carriage_return(cornell, capfd):
    try:
        plenoptic.trace(cornell, width=32, height=32, spp=4)
        assert capfd.readouterr().err == ""  # not a terminal: nothing by default
        plenoptic.set_progress(True)
        assert plenoptic.get_progress() is True
        plenoptic.trace(cornell, width=32, height=32, spp=4)
        err = capfd.readouterr().err
        assert "tracing" in err and "100.0%" in err and "\r" not in err  # one line per 10 %
        plenoptic.set_progress(False)
        plenoptic.trace(cornell, width=32, height=32, spp=4)
        assert capfd.readouterr().err == ""
    finally:
        plenoptic.set_progress(None)


def test_write_video_encodes_the_tone_mapped_frames(tmp_path):
    # Three flat frames of radiance 0.05, 0.2, 0.8 (clamp: sRGB 63, 124, 231): decoded back by
    # ffmpeg, each frame's pixels are within H.264's rounding of those bytes.
    levels = [0.05, 0.2, 0.8]
    frames = [np.full((16, 32, 3), level, dtype=np.float64) for level in levels]
    video = str(tmp_path / "walk.mp4")
    with pytest.raises(ValueError, match="mp4"):
        plenoptic.write_video(str(tmp_path / "walk.avi"), frames)
    with pytest.raises(ValueError, match="frame 1 is"):
        plenoptic.write_video(video, [frames[0], np.zeros((8, 8, 3))])
    with pytest.raises(ValueError, match="no frames"):
        plenoptic.write_video(video, [])
    if shutil.which("ffmpeg") is None:
        with pytest.raises(plenoptic.Error, match="ffmpeg"):
            plenoptic.write_video(video, frames)
        assert not os.path.exists(video)
        return
    with pytest.raises(plenoptic.Error, match="even width and height"):
        plenoptic.write_video(video, [np.zeros((15, 32, 3))])
    assert os.listdir(tmp_path) == []  # nothing half-written
    plenoptic.write_video(video, frames, fps=10, tonemap="clamp")
    decoded = subprocess.run(["ffmpeg", "-loglevel", "error", "-i", video, "-f", "rawvideo", "-pix_fmt", "rgb24", "-"],
                             check=True, capture_output=True).stdout
    pictures = np.frombuffer(decoded, dtype=np.uint8).reshape(-1, 16, 32, 3)
    assert len(pictures) == 3
    expected = [plenoptic.tone_map(frame, tonemap="clamp")[0, 0, 0] for frame in frames]
    assert [int(e) for e in expected] == [63, 124, 231]
    for picture, value in zip(pictures, expected):
        assert np.abs(picture.astype(int) - int(value)).max() <= 3


# Ctrl-C: each case runs in its own interpreter (a KeyboardInterrupt that landed outside the
# call would otherwise stop pytest itself), which sends itself SIGINT a second into a call that
# would run for hours. The subprocess's timeout only guards against a call that is never
# cancelled; a cancelled one returns within about a second.
INTERRUPT_SCRIPT = r"""
import os, signal, sys, threading
import plenoptic
scene = plenoptic.load_scene("cornell")
threading.Timer(1.0, lambda: os.kill(os.getpid(), signal.SIGINT)).start()
try:
    {call}
    print("not interrupted")
except KeyboardInterrupt:
    print("KeyboardInterrupt")
# The flag is cleared: the next call runs to its end.
image, _ = plenoptic.trace(scene, width=8, height=8, spp=1)
print("next call", image.shape)
"""


def run_interrupted(call, tmp_path):
    result = subprocess.run([sys.executable, "-c", INTERRUPT_SCRIPT.replace("{call}", call)], cwd=tmp_path,
                            env=dict(os.environ), capture_output=True, text=True, timeout=600)
    assert result.returncode == 0, result.stderr
    return result.stdout.split("\n")


def test_ctrl_c_interrupts_a_trace(tmp_path):
    lines = run_interrupted("plenoptic.trace(scene, width=1024, height=1024, spp=1000000)", tmp_path)
    assert lines[:2] == ["KeyboardInterrupt", "next call (8, 8, 3)"]


def test_ctrl_c_interrupts_a_bake_leaving_the_old_visibility_file_untouched(tmp_path):
    plv = tmp_path / "field.plv"
    plv.write_bytes(b"the previous file")
    lines = run_interrupted("plenoptic.bake(scene, preset='high', visibility='field.plv')", tmp_path)
    assert lines[:2] == ["KeyboardInterrupt", "next call (8, 8, 3)"]
    assert plv.read_bytes() == b"the previous file"
    # No temporary left behind; the journal of the blocks traced so far stays, for the next
    # bake to resume from (when the interrupt came while tracing).
    assert sorted(os.listdir(tmp_path)) in (["field.plv"], ["field.plv", "field.plv.partial"])
