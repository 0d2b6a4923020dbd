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
    # The warnings name an option as each front end spells it: --threads, threads (raster's
    # GL context has its own threads and does not read it).
    assert r.stats["info"] == cli["info"]
    assert r.stats["warnings"] == [w.replace("--threads", "threads") for w in cli["warnings"]]
    assert ("option threads is not read by raster" in r.stats["warnings"]) == (renderer == "raster")
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


def test_save_writes_the_command_lines_files(run_cli, tmp_path):
    # Render.save(path, aovs) writes the files `rvr render -o path --aov ...` writes, byte for
    # byte: colour (PNG and EXR) and every AOV, lod included, on the textured scene.
    args = ["builtin:textured", "--width", "48", "--height", "36", "--mode", "local",
            "--threads", "2", "-q"]
    aovs = ["depth", "id", "normal", "cost", "lod"]
    scene = rvr.Scene("builtin:textured", width=48, height=36)
    r = rvr.render(scene, "softraster", mode="local", threads=2)
    for ext in ("png", "exr"):
        cli_dir, py_dir = tmp_path / f"cli-{ext}", tmp_path / f"py-{ext}"
        cli_dir.mkdir()
        py_dir.mkdir()
        done = run_cli("render", *args, "-r", "softraster", "--aov", ",".join(aovs),
                       "-o", str(cli_dir / f"out.{ext}"))
        assert done.returncode == 0, done.stderr
        r.save(py_dir / f"out.{ext}", aovs)
        names = sorted(p.name for p in cli_dir.iterdir())
        assert sorted(p.name for p in py_dir.iterdir()) == names
        assert len(names) == 7  # the image, five AOVs, and the cost's colour-mapped PNG
        for name in names:
            assert (py_dir / name).read_bytes() == (cli_dir / name).read_bytes(), name


def test_lod_is_the_command_lines(run_cli, tmp_path):
    # Render.lod is the lod AOV: NaN off the textured surfaces, the same values on them.
    out = tmp_path / "render.exr"
    done = run_cli("render", "builtin:textured", "-r", "raytrace", "--mode", "local", "--width",
                   "48", "--height", "36", "--aov", "lod", "-q", "-o", str(out))
    assert done.returncode == 0, done.stderr
    r = rvr.render(rvr.Scene("builtin:textured", width=48, height=36), "raytrace", mode="local")
    lod = read_exr(tmp_path / "render.lod.exr")[:, :, 0]
    assert r.lod.shape == (36, 48) and r.lod.dtype == np.float32
    assert np.isfinite(r.lod).any() and np.isnan(r.lod).any()
    assert r.lod.tobytes() == np.ascontiguousarray(lod).tobytes()
    untextured = rvr.render(rvr.Scene(SCENE, width=8, height=6), "raytrace")
    assert untextured.lod.shape == (6, 8) and np.isnan(untextured.lod).all()


def test_a_dict_is_the_scene_file_of_its_json(run_cli, tmp_path):
    document = json.loads(rvr.Scene("builtin:spheres").to_json())
    path = tmp_path / "scene.json"
    path.write_text(json.dumps(document))
    out = tmp_path / "render.exr"
    done = run_cli("render", str(path), "-r", "raytrace", "--mode", "local", "--width", "40",
                   "--height", "30", "-q", "-o", str(out))
    assert done.returncode == 0, done.stderr
    scene = rvr.Scene(document, width=40, height=30)
    assert scene.source == "dict"
    r = rvr.render(scene, "raytrace", mode="local")
    assert r.color.tobytes() == np.ascontiguousarray(read_exr(out)).tobytes()


def write_ply(path, vertices, indices, colors=None):
    lines = ["ply", "format ascii 1.0", f"element vertex {len(vertices)}",
             "property float x", "property float y", "property float z"]
    if colors is not None:
        lines += ["property uchar red", "property uchar green", "property uchar blue"]
    lines += [f"element face {len(indices)}", "property list uchar int vertex_indices",
              "end_header"]
    for i, v in enumerate(vertices):
        row = " ".join(repr(float(x)) for x in v)
        if colors is not None:
            row += " " + " ".join(str(int(c)) for c in colors[i])
        lines.append(row)
    lines += ["3 " + " ".join(str(int(i)) for i in t) for t in indices]
    path.write_text("\n".join(lines) + "\n")


def test_a_mesh_from_arrays_is_the_model_file_of_it(run_cli, tmp_path):
    # Scene.from_mesh is a model file holding only that mesh: the same camera, lights and
    # exposure, so the same image as `rvr render mesh.ply` (a tetrahedron, Z up, flat).
    vertices = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0.3, 0.3, 0.8]], dtype=np.float32)
    indices = np.array([[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]], dtype=np.int64)
    path = tmp_path / "mesh.ply"
    write_ply(path, vertices, indices)
    out = tmp_path / "render.exr"
    done = run_cli("render", str(path), "-r", "raytrace", "--mode", "local", "--width", "40",
                   "--height", "30", "--up", "z", "--aov", "depth", "-q", "-o", str(out))
    assert done.returncode == 0, done.stderr
    scene = rvr.Scene.from_mesh(vertices, indices, width=40, height=30, up_axis="z")
    assert scene.source == "mesh" and scene.warnings == []
    r = rvr.render(scene, "raytrace", mode="local")
    assert (r.object_id == 0).any()
    assert r.color.tobytes() == np.ascontiguousarray(read_exr(out)).tobytes()
    depth = read_exr(tmp_path / "render.depth.exr")[:, :, 0]
    assert r.depth.tobytes() == np.ascontiguousarray(depth).tobytes()
    # A flat list of indices is the same mesh; vertex colours change the colour only.
    flat = rvr.render(rvr.Scene.from_mesh(vertices, indices.ravel(), width=40, height=30,
                                          up_axis="z"), "raytrace", mode="local")
    assert flat.color.tobytes() == r.color.tobytes()
    red = rvr.render(rvr.Scene.from_mesh(vertices, indices, colors=np.tile([1, 0, 0], (4, 1)),
                                         width=40, height=30, up_axis="z"),
                     "raytrace", mode="local")
    assert np.array_equal(red.object_id, r.object_id)
    seen = r.object_id == 0
    assert (red.color[seen][:, 1:] == 0).all() and (red.color[seen][:, 0] > 0).any()


def test_answer_names_each_z_buffer_technique(tmp_path):
    # Render.answer: on builtin:glass in full mode a z-buffer answers the pane (ior 1) by the view
    # behind it (2), the slab by a cube map bent at its first interface only (5), the ball by a
    # cube map through both interfaces (4), and nothing elsewhere (0); a tracer answers nothing.
    scene = rvr.Scene("builtin:glass", width=64, height=48)
    scene.save(tmp_path / "glass.json")
    names = [o["name"] for o in json.loads((tmp_path / "glass.json").read_text())["objects"]]
    want = {names.index("pane"): 2, names.index("slab"): 5, names.index("glass ball"): 4}
    r = rvr.render(scene, "softraster", mode="full", cube_map_size=16)
    assert r.answer.shape == (48, 64) and r.answer.dtype == np.uint8
    expected = np.zeros((48, 64), dtype=np.uint8)
    for index, code in want.items():
        expected[r.object_id == index] = code
    assert (r.answer == expected).all()
    assert set(np.unique(r.answer)) == {0, 2, 4, 5}
    traced = rvr.render(scene, "raytrace", mode="full")
    assert not traced.answer.any()
