# Every renderer of the table renders through the module; rvr.compare gives metrics.json's
# keys and figures as `rvr compare` writes them for the same scene.
import json

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
        for key in ["warnings", "info", "depth_format", "image"]:
            assert got["renderers"][name][key] == expected["renderers"][name][key]
