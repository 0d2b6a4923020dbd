# The module renders what the command line renders, to the bit: colour, depth and ids of
# rvr.render against the EXR files `rvr render` writes for the same scene and options, read by
# OpenImageIO's own Python binding (not by rvr's reader).
import json

import numpy as np
import OpenImageIO as oiio
import pytest

import rvr

SCENE = "builtin:cornell"
WIDTH, HEIGHT = 96, 72


def read_exr(path):
    image = oiio.ImageBuf(str(path))
    assert not image.has_error, image.geterror()
    return image.get_pixels(oiio.FLOAT)


@pytest.mark.parametrize("renderer", ["raytrace", "softraster", "raster", "hybrid_soft"])
def test_render_matches_the_command_line(renderer, run_cli, tmp_path):
    out = tmp_path / "render.exr"
    done = run_cli("render", SCENE, "-r", renderer, "--mode", "local", "--width", str(WIDTH),
                   "--height", str(HEIGHT), "--threads", "2", "--aov", "depth,id", "-q",
                   "--stats", str(tmp_path / "stats.json"), "-o", str(out))
    assert done.returncode == 0, done.stderr

    r = rvr.render(rvr.Scene(SCENE, width=WIDTH, height=HEIGHT), renderer, mode="local",
                   threads=2)
    color = read_exr(out)
    depth = read_exr(tmp_path / "render.depth.exr")
    ids = read_exr(tmp_path / "render.id.exr")
    assert color.shape == (HEIGHT, WIDTH, 3)
    assert r.color.tobytes() == np.ascontiguousarray(color).tobytes()
    assert r.depth.tobytes() == np.ascontiguousarray(depth[:, :, 0]).tobytes()
    assert np.array_equal(r.object_id, ids[:, :, 0].astype(np.int32))
    assert np.array_equal(r.primitive_id, ids[:, :, 1].astype(np.int32))
    assert (r.object_id >= 0).any() and (r.object_id == -1).any()

    # The --stats document: the same fields; the same counters, times apart.
    cli = json.loads((tmp_path / "stats.json").read_text())
    assert list(r.stats) == list(cli)
    assert r.stats["info"] == cli["info"] and r.stats["warnings"] == cli["warnings"]
    counters = {k: v for k, v in cli["stats"].items() if "time." not in k}
    assert {k: r.stats["stats"][k] for k in counters} == counters
    assert r.stats["stats"].keys() == cli["stats"].keys()


def test_camera_settings_render_as_a_scene_file_of_them(run_cli, tmp_path):
    # The camera set from Python, written by save() and rendered by the command line from that
    # file: the same image as the module renders.
    scene = rvr.Scene(SCENE, width=48, height=36,
                      camera={"eye": [2.5, 3.0, -6.0], "target": [2.78, 2.0, 0.0], "fov": 50})
    scene.camera = {"up": [0.1, 1.0, 0.0]}
    path = tmp_path / "scene.json"
    scene.save(str(path))
    document = json.loads(path.read_text())
    assert document["camera"]["eye"] == [2.5, 3.0, -6.0]
    # Only up's direction counts: the loader keeps it at unit length, and so does the module.
    assert np.allclose(document["camera"]["up"], np.array([0.1, 1.0, 0.0]) / np.hypot(0.1, 1.0))
    assert document["camera"]["fov_y_deg"] == 50
    out = tmp_path / "render.exr"
    done = run_cli("render", str(path), "-r", "raytrace", "--mode", "local", "-q", "-o", str(out))
    assert done.returncode == 0, done.stderr
    r = rvr.render(scene, "raytrace", mode="local")
    assert r.color.tobytes() == np.ascontiguousarray(read_exr(out)).tobytes()
