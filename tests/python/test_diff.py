# rvr.diff on two EXR files written by OpenImageIO's own binding, against closed forms: one
# channel of one pixel differs by 0.5 in a 4x4 RGB image; and the verdict `rvr diff` gives. The
# same pixels as arrays, and a render, are compared as their files are.
import math

import numpy as np
import OpenImageIO as oiio
import pytest

import rvr


def write_exr(path, pixels):
    spec = oiio.ImageSpec(pixels.shape[1], pixels.shape[0], pixels.shape[2], oiio.FLOAT)
    out = oiio.ImageOutput.create(str(path))
    assert out.open(str(path), spec) and out.write_image(pixels) and out.close()


def test_diff_of_one_changed_channel(run_cli, tmp_path):
    a = np.full((4, 4, 3), 0.25, dtype=np.float32)
    b = a.copy()
    b[2, 3, 1] += 0.5  # row 2, column 3, green
    write_exr(tmp_path / "a.exr", a)
    write_exr(tmp_path / "b.exr", b)
    d = rvr.diff(str(tmp_path / "a.exr"), str(tmp_path / "b.exr"))
    assert d["pixels"] == 16 and d["fail_pixels"] == 1 and d["warn_pixels"] == 1
    assert d["max_error"] == 0.5 and d["max_at"] == (3, 2, 1)
    assert math.isclose(d["mean_error"], 0.5 / 48, rel_tol=1e-12)
    assert math.isclose(d["rms_error"], math.sqrt(0.25 / 48), rel_tol=1e-12)
    assert d["verdict"] == "FAILURE"
    assert rvr.diff(str(tmp_path / "a.exr"), str(tmp_path / "b.exr"), fail=0.6,
                    warn=0.6)["verdict"] == "PASS"
    assert rvr.diff(str(tmp_path / "a.exr"), str(tmp_path / "b.exr"), fail=0.6, warn=0.6,
                    fail_above=0.01)["verdict"] == "FAILURE"
    done = run_cli("diff", str(tmp_path / "a.exr"), str(tmp_path / "b.exr"))
    assert done.returncode == 1 and done.stdout.strip().endswith("FAILURE")


def test_diff_of_arrays_and_renders_is_the_diff_of_their_files(tmp_path):
    # Arrays (H x W x C or H x W) and renders are compared as the EXR files of them are.
    a = np.full((4, 4, 3), 0.25, dtype=np.float32)
    b = a.copy()
    b[2, 3, 1] += 0.5
    write_exr(tmp_path / "a.exr", a)
    write_exr(tmp_path / "b.exr", b)
    files = rvr.diff(tmp_path / "a.exr", tmp_path / "b.exr")
    assert rvr.diff(a, b) == files
    assert rvr.diff(a.astype(np.float64).tolist(), b) == files
    assert rvr.diff(str(tmp_path / "a.exr"), b) == files
    grey = rvr.diff(a[:, :, 0], b[:, :, 1])
    assert grey["pixels"] == 16 and grey["max_at"] == (3, 2, 0) and grey["max_error"] == 0.5

    render = rvr.render(rvr.Scene("builtin:cornell", width=16, height=12), "raytrace")
    render.save(tmp_path / "render.exr")
    assert rvr.diff(render, tmp_path / "render.exr")["max_error"] == 0.0
    assert rvr.diff(render, render.color)["verdict"] == "PASS"
    with pytest.raises(rvr.BadInput, match=r"^a: expected an image file, an H x W or H x W x C "
                                           r"array or an rvr.Render, got an array of shape \(4,\)"):
        rvr.diff(np.zeros(4), b)
    with pytest.raises(rvr.BadInput, match="^b: expected an image file, .* got dict"):
        rvr.diff(a, {})
