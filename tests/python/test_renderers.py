# Every renderer of the table renders through the module; rvr.compare gives metrics.json's
# keys and figures as `rvr compare` writes them for the same scene.
import json
import re

import numpy as np

import rvr

# The table as renderers/include/rvr/renderers/registry.h documents it, in order.
DOCUMENTED = ["raster", "softraster", "raytrace", "embree", "hybrid", "hybrid_soft"]
LOOP_ORDERS = {"raster": "triangle-major", "softraster": "triangle-major",
               "raytrace": "pixel-major", "embree": "pixel-major",
               "hybrid": "hybrid", "hybrid_soft": "hybrid"}


def test_the_table_is_the_documented_one():
    table = rvr.renderers()
    assert [r["name"] for r in table] == DOCUMENTED
    assert {r["name"]: r["loop_order"] for r in table} == LOOP_ORDERS
    assert all(r["description"] for r in table)


def test_every_renderer_renders():
    scene = rvr.Scene("builtin:cornell", width=40, height=30)
    for info in rvr.renderers():
        r = rvr.render(scene, info["name"], threads=1)
        assert r.color.shape == (30, 40, 3) and r.color.dtype == np.float32
        assert r.normal.shape == (30, 40, 3) and r.normal.dtype == np.float32
        for a, dtype in [(r.depth, np.float32), (r.cost, np.float32),
                         (r.object_id, np.int32), (r.primitive_id, np.int32)]:
            assert a.shape == (30, 40) and a.dtype == dtype
        background = r.object_id == -1
        # The cornell box's walls fill most of the frame; background is +inf depth and no id.
        assert (~background).sum() > 600, info["name"]
        assert np.all(np.isinf(r.depth[background])) and np.all(np.isfinite(r.depth[~background]))
        assert np.all(r.primitive_id[background] == -1)
        assert r.stats["renderer"] == info["name"] and r.stats["width"] == 40
        assert r._repr_png_()[:8] == b"\x89PNG\r\n\x1a\n"


def test_compare_is_metrics_json(run_cli, tmp_path):
    done = run_cli("compare", "builtin:cornell", "-r", "raster,raytrace", "--width", "64",
                   "--height", "48", "--threads", "2", "-q", "-o", str(tmp_path))
    assert done.returncode in (0, 1), done.stderr
    expected = json.loads((tmp_path / "metrics.json").read_text())
    scene = rvr.Scene("builtin:cornell", width=64, height=48)
    got = rvr.compare(rvr.render(scene, "raster", threads=2), rvr.render(scene, "raytrace", threads=2))
    assert list(got) == list(expected)
    for key in ["format", "scene", "width", "height", "mode", "warnings", "visibility", "depth",
                "color", "compared", "files", "edge_tolerance_px", "heat_map_scale",
                "depth_diff_scale"]:
        assert got[key] == expected[key], key
    assert len(got["pairs"]) == 1 and got["pairs"][0]["visibility"] == expected["pairs"][0]["visibility"]
    for name in ["raster", "raytrace"]:
        for key in ["info", "depth_format", "image"]:
            assert got["renderers"][name][key] == expected["renderers"][name][key]
        # The same warnings, an option named as each front end spells it (--threads, threads).
        assert got["renderers"][name]["warnings"] == [
            re.sub(r"--([a-z-]+)", lambda m: m.group(1).replace("-", "_"), w)
            for w in expected["renderers"][name]["warnings"]]
    assert got["renderers"]["raster"]["warnings"] == ["option threads is not read by raster"]


def test_compare_classes_depth_outliers_as_the_command_line(run_cli, tmp_path):
    # Coarse polygon spheres: the z-buffer's depth strays from the tracer's analytic spheres
    # inside their outlines, which rvr compare classes as expected (on analytic spheres), not
    # as disagreements (elsewhere); rvr.compare must be given the same sphere settings.
    done = run_cli("compare", "builtin:spheres", "-r", "raster,raytrace", "--width", "64",
                   "--height", "48", "--sphere-segments", "8", "--threads", "2", "-q",
                   "-o", str(tmp_path))
    assert done.returncode in (0, 1), done.stderr
    expected = json.loads((tmp_path / "metrics.json").read_text())["pairs"][0]["depth"]
    assert expected["outliers_on_analytic_spheres"] > 0 and expected["outliers_elsewhere"] == 0
    scene = rvr.Scene("builtin:spheres", width=64, height=48)
    a = rvr.render(scene, "raster", threads=2, sphere_segments=8)
    b = rvr.render(scene, "raytrace", threads=2, sphere_segments=8)
    assert rvr.compare(a, b)["pairs"][0]["depth"] == expected


def test_changing_a_scene_leaves_earlier_renders_alone():
    scene = rvr.Scene("builtin:cornell", width=32, height=24)
    first = rvr.render(scene, "raytrace", threads=1)
    before = first.depth.copy()
    scene.width = 16
    scene.camera = {"fov": 20}
    second = rvr.render(scene, "raytrace", threads=1)
    assert first.color.shape == (24, 32, 3) and second.color.shape == (24, 16, 3)
    assert first.stats["width"] == 32 and second.stats["width"] == 16
    assert np.array_equal(first.depth, before)
    assert scene.camera["fov"] == 20


def test_to_json_of_a_scene_of_single_triangles():
    # builtin:occluders has no mesh of more than one triangle: rvr-scene/1 holds it inline.
    scene = rvr.Scene("builtin:occluders:3", width=20, height=10)
    document = json.loads(scene.to_json())
    assert document["format"] == "rvr-scene/1"
    assert document["image"]["width"] == 20 and document["image"]["height"] == 10
