"""pytest suite of the Python module (run by ctest as `python_tests`, with PYTHONPATH=build/python
and PLENOPTIC_BINARY naming the command-line program). Small sizes: every test runs in seconds."""
import json
import os
import subprocess

import numpy as np
import pytest

import plenoptic

BINARY = os.environ.get("PLENOPTIC_BINARY", "")


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
    reference = lf.render(width=32, height=24, samples=4, reference=True)
    assert reference.shape == (24, 32, 3)
    # The light field against the path tracer: close in mean (the bake's draft preset).
    traced, _ = plenoptic.trace(cornell, width=32, height=24, spp=64)
    assert plenoptic.compare(reference, traced)["mean_luminance_ratio"] == pytest.approx(1.0, abs=0.1)


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


def test_image_round_trip_and_compare(tmp_path):
    rng = np.random.default_rng(3)
    image = rng.random((5, 7, 3), dtype=np.float32)
    path = str(tmp_path / "x.pfm")
    plenoptic.write_image(path, image)
    assert np.array_equal(plenoptic.read_image(path), image)
    same = plenoptic.compare(image, image)
    assert same["rel_mse"] == 0.0 and same["mean_ratio_rgb"] == [1.0, 1.0, 1.0]
    assert plenoptic.compare(image * 2, image)["mean_luminance_ratio"] == pytest.approx(2.0)


def test_arrays_of_the_wrong_shape_or_dtype_are_refused(tmp_path):
    path = str(tmp_path / "x.pfm")
    with pytest.raises(ValueError, match="float32"):
        plenoptic.write_image(path, np.zeros((4, 4, 3), dtype=np.float64))
    with pytest.raises(ValueError, match="shape"):
        plenoptic.write_image(path, np.zeros((4, 4), dtype=np.float32))
    with pytest.raises(ValueError, match="shape"):
        plenoptic.compare(np.zeros((4, 4, 4), dtype=np.float32), np.zeros((4, 4, 3), dtype=np.float32))
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
    with pytest.raises(plenoptic.UsageError, match="no material"):
        cornell.set_emission("nothing", [1.0, 1.0, 1.0])
    with pytest.raises(plenoptic.UsageError, match="light 0 does not exist"):
        cornell.set_light_color(0, [1.0, 1.0, 1.0])
    with pytest.raises(plenoptic.UsageError, match="non-negative"):
        cornell.set_emission("light", [-1.0, 0.0, 0.0])
    with pytest.raises(plenoptic.Error, match="missing.plf: cannot open light field"):
        plenoptic.load_light_field(str(tmp_path / "missing.plf"))
