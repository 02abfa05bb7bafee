"""Smoke test of the worked examples in examples/ (ctest `python_examples`): each runs at a tiny
size, with the draft preset, and writes what its docstring promises. PLENOPTIC_EXAMPLES names
the examples directory (default: found from this file's place in the repository)."""
import os
import shutil
import subprocess
import sys

import pytest

import plenoptic

EXAMPLES = os.environ.get("PLENOPTIC_EXAMPLES") or os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..",
                                                                "..", "examples")


def run_example(name, tmp_path, *arguments):
    out = tmp_path / "out"
    result = subprocess.run([sys.executable, os.path.join(EXAMPLES, name), "--out", str(out), *arguments],
                            cwd=tmp_path, capture_output=True, text=True, timeout=600)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "\r" not in result.stderr  # no progress bars in captured output
    return out, result.stdout


def test_trace_vs_bake(tmp_path):
    out, stdout = run_example("trace_vs_bake.py", tmp_path, "--size", "24", "--spp", "8", "--preset", "draft",
                              "--samples", "2", "--threads", "2")
    assert "relMSE" in stdout
    assert plenoptic.read_image(str(out / "trace.exr")).shape == (24, 32, 3)
    assert plenoptic.read_image(str(out / "lightfield.exr")).shape == (24, 32, 3)
    try:
        import matplotlib  # noqa: F401
    except ImportError:
        assert "matplotlib not installed" in stdout
    else:
        assert (out / "trace_vs_bake.png").stat().st_size > 0


def test_relight_sweep(tmp_path):
    out, stdout = run_example("relight_sweep.py", tmp_path, "--steps", "2", "--size", "16", "--preset", "draft",
                              "--threads", "2")
    strip = plenoptic.read_image(str(out / "relight_sweep.png"))
    assert strip.shape == (16, 32, 3)
    # Warm light on the left, cool on the right: the red/blue balance turns over.
    left, right = strip[:, :16].reshape(-1, 3).mean(axis=0), strip[:, 16:].reshape(-1, 3).mean(axis=0)
    assert left[0] / left[2] > right[0] / right[2]
    assert (out / "cornell.plv").is_file()


def test_camera_path_video(tmp_path):
    out, stdout = run_example("camera_path_video.py", tmp_path, "--seconds", "0.2", "--fps", "10", "--width", "16",
                              "--height", "12", "--preset", "draft", "--threads", "2")
    assert "3 frames of 16x12" in stdout and (out / "walk.json").is_file()
    if shutil.which("ffmpeg"):
        assert (out / "walk.mp4").stat().st_size > 0
    else:
        assert sorted(os.listdir(out / "walk")) == ["0000.png", "0001.png", "0002.png"]


@pytest.mark.parametrize("name", ["trace_vs_bake.py", "relight_sweep.py", "camera_path_video.py", "preset_sweep.py"])
def test_examples_explain_themselves(name):
    result = subprocess.run([sys.executable, os.path.join(EXAMPLES, name), "--help"], capture_output=True, text=True)
    assert result.returncode == 0 and "usage:" in result.stdout
