# Bad input raises rvr.BadInput, a ValueError, whose text is the command line's error line
# without "error: ", for the same input.
import json
import os
import pathlib

import pytest

import rvr


def cli_message(run_cli, *args):
    done = run_cli(*args)
    assert done.returncode == 2, done.stderr
    lines = done.stderr.strip().splitlines()
    assert lines[-1].startswith("error: "), done.stderr
    return lines[-1][len("error: "):]


def bad_scene(tmp_path):
    scene = {"format": "rvr-scene/1",
             "camera": {"eye": [0, 0, 5], "target": [0, 0, 0], "up": [0, 1, 0]},
             "objects": [{"type": "sphere", "center": [0, 0, 0], "radius": -1}]}
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(scene))
    return str(path)


def test_bad_scene_file(run_cli, tmp_path):
    path = bad_scene(tmp_path)
    expected = cli_message(run_cli, "render", path, "-r", "raytrace", "-q",
                           "-o", str(tmp_path / "out.png"))
    assert "radius" in expected
    with pytest.raises(rvr.BadInput) as caught:
        rvr.Scene(path)
    assert str(caught.value) == expected
    assert isinstance(caught.value, ValueError)


def test_unknown_builtin_scene(run_cli, tmp_path):
    expected = cli_message(run_cli, "render", "builtin:nonesuch", "-r", "raytrace", "-q",
                           "-o", str(tmp_path / "out.png"))
    with pytest.raises(rvr.BadInput, match="^" + expected.replace("(", r"\(").replace(")", r"\)") + "$"):
        rvr.Scene("builtin:nonesuch")


def test_missing_file(run_cli, tmp_path):
    path = str(tmp_path / "missing.json")
    expected = cli_message(run_cli, "render", path, "-r", "raytrace", "-q",
                           "-o", str(tmp_path / "out.png"))
    with pytest.raises(rvr.BadInput) as caught:
        rvr.Scene(path)
    assert str(caught.value) == expected


@pytest.mark.parametrize("name", ["nonesuch", "raytrac"])
def test_unknown_renderer(name, run_cli, tmp_path):
    # The command line's words for -r (with its "did you mean"), naming the argument instead.
    expected = cli_message(run_cli, "render", "builtin:cornell", "-r", name, "-q",
                           "-o", str(tmp_path / "out.png"))
    assert expected.startswith("--renderer: ")
    with pytest.raises(rvr.BadInput) as caught:
        rvr.render(rvr.Scene("builtin:cornell", width=8, height=8), name)
    assert str(caught.value) == "renderer: " + expected[len("--renderer: "):]


def test_limits(run_cli, tmp_path):
    expected = cli_message(run_cli, "render", "builtin:cornell", "-r", "raytrace", "-q",
                           "--width", "4096", "--height", "4096", "--spp", "128",
                           "-o", str(tmp_path / "out.png"))
    with pytest.raises(rvr.BadInput) as caught:
        rvr.Scene("builtin:cornell", width=4096, height=4096, spp=128)
    assert str(caught.value) == expected


def test_bad_options_name_what_is_wrong():
    scene = rvr.Scene("builtin:cornell", width=8, height=8)
    with pytest.raises(rvr.BadInput, match="^mode: "):
        rvr.render(scene, "raytrace", mode="fast")
    with pytest.raises(rvr.BadInput, match="^unknown option 'acel'"):
        rvr.render(scene, "raytrace", acel="bvh")
    with pytest.raises(rvr.BadInput, match="^accel: 'kd' is not one of bvh, bvh2, none$"):
        rvr.render(scene, "raytrace", accel="kd")
    with pytest.raises(rvr.BadInput,
                       match="^texture_lod: 'cone' is not one of cones, differentials, none: "
                             "did you mean 'cones'\\?$"):
        rvr.render(scene, "raytrace", texture_lod="cone")
    with pytest.raises(rvr.BadInput, match="^shadow_map_size: must be 16 to 8192, got 8$"):
        rvr.render(scene, "raster", shadow_map_size=8)
    with pytest.raises(rvr.BadInput, match="^shadow_bias: must be 0 to 10, got 10.5$"):
        rvr.render(scene, "raster", shadow_bias=10.5)
    with pytest.raises(rvr.BadInput, match="^width: must be 1 to 16384, got 0"):
        scene.width = 0
    with pytest.raises(rvr.BadInput, match="^camera: unknown key 'foo'"):
        scene.camera = {"foo": 1}


def test_camera_errors_are_the_loaders():
    scene = rvr.Scene("builtin:cornell", width=8, height=8)
    with pytest.raises(rvr.BadInput, match=r"^camera: camera.up: must not be parallel"):
        scene.camera = {"eye": [0, 0, 5], "target": [0, 0, 0], "up": [0, 0, 1]}
    with pytest.raises(rvr.BadInput, match=r"^camera: camera.fov_y_deg: must be in \(0, 180\)"):
        scene.camera = {"fov": 180}
    assert scene.camera["fov"] != 180  # a refused camera leaves the scene's as it was


def test_compare_refuses_renders_of_different_scenes():
    # The command line compares renders of one scene: renders of different scenes, cameras or
    # modes are refused unless asked for, naming what differs.
    cornell = rvr.Scene("builtin:cornell", width=16, height=12)
    a = rvr.render(cornell, "raytrace")
    other = rvr.render(rvr.Scene("builtin:soup", width=16, height=12), "softraster")
    with pytest.raises(rvr.BadInput, match="^compare: the renders are of different scenes: "
                                           "builtin:cornell and builtin:soup"):
        rvr.compare(a, other)
    assert "visibility" in rvr.compare(a, other, allow_different=True)
    with pytest.raises(rvr.BadInput, match="^compare: the renders differ in mode: local and full"):
        rvr.compare(a, rvr.render(cornell, "softraster", mode="full"))
    turned = rvr.Scene("builtin:cornell", width=16, height=12, camera={"fov": 30})
    with pytest.raises(rvr.BadInput, match="^compare: the renders differ in camera"):
        rvr.compare(a, rvr.render(turned, "softraster"))
    brighter = rvr.Scene("builtin:cornell", width=16, height=12, exposure=1)
    with pytest.raises(rvr.BadInput, match="^compare: the renders differ in image settings"):
        rvr.compare(a, rvr.render(brighter, "softraster"))
    with pytest.raises(rvr.BadInput, match="^compare: the renders differ in how spheres were drawn"):
        rvr.compare(a, rvr.render(cornell, "softraster", sphere_segments=8))
    # One scene loaded twice is one scene.
    again = rvr.render(rvr.Scene("builtin:cornell", width=16, height=12), "softraster")
    assert rvr.compare(a, again)["visibility"]["id_agreement"] > 0.9


def test_study_takes_one_name_and_names_its_keywords(run_cli, tmp_path):
    # One scene family as a str, as the command line takes one; bad values name the keyword,
    # not the command line's option.
    done = run_cli("study", "builtin:nonesuch", "-q", "-o", str(tmp_path))
    expected = done.stderr.strip().splitlines()[-1][len("error: "):]
    with pytest.raises(rvr.BadInput) as caught:
        rvr.study("builtin:nonesuch")
    assert str(caught.value) == expected
    with pytest.raises(rvr.BadInput, match=r"^budget: must be > 0 seconds, got -1$"):
        rvr.study("builtin:tessphere", budget=-1)
    with pytest.raises(rvr.BadInput, match=r"^sessions: must be >= 3, got 1$"):
        rvr.study("builtin:tessphere", sessions=1)
    with pytest.raises(rvr.BadInput, match=r"^noise_threshold: must be in 0 \.\. 1"):
        rvr.study("builtin:tessphere", noise_threshold=2)
    with pytest.raises(rvr.BadInput, match=r"^scenes: expected a name or a sequence of names, "
                                           r"got int$"):
        rvr.study(3)


def test_scene_from_a_dict_errors_are_the_loaders(run_cli, tmp_path):
    # A dict is read as a scene file of its JSON: the same message, naming 'dict'.
    document = {"format": "rvr-scene/1",
                "camera": {"eye": [0, 0, 5], "target": [0, 0, 0], "up": [0, 1, 0]},
                "objects": [{"type": "sphere", "center": [0, 0, 0], "radius": -1}]}
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(document))
    expected = cli_message(run_cli, "render", str(path), "-r", "raytrace", "-q",
                           "-o", str(tmp_path / "out.png"))
    with pytest.raises(rvr.BadInput) as caught:
        rvr.Scene(document)
    assert str(caught.value) == expected.replace(str(path), "dict", 1)
    with pytest.raises(rvr.BadInput, match="^dict: a set is not a JSON value"):
        rvr.Scene({"format": "rvr-scene/1", "objects": {1, 2}})
    with pytest.raises(rvr.BadInput, match="^source: expected a path, 'builtin:NAME' or a dict, "
                                           "got int"):
        rvr.Scene(3)


def test_mesh_errors_name_the_array():
    vertices = [[0, 0, 0], [1, 0, 0], [0, 1, 0]]
    with pytest.raises(rvr.BadInput, match=r"^mesh: indices\[1\]: vertex 3 is past the last of "
                                           r"the 3 vertices$"):
        rvr.Scene.from_mesh(vertices, [[0, 1, 2], [0, 2, 3]])
    with pytest.raises(rvr.BadInput, match=r"^mesh: indices\[0\]: vertex -1 is not a vertex"):
        rvr.Scene.from_mesh(vertices, [[0, 1, -1]])
    with pytest.raises(rvr.BadInput, match=r"^vertices: expected an N x 3 array, got shape "
                                           r"\(3, 2\)$"):
        rvr.Scene.from_mesh([[0, 0], [1, 0], [0, 1]], [[0, 1, 2]])
    with pytest.raises(rvr.BadInput, match=r"^mesh: vertices\[1\]: must be finite numbers$"):
        rvr.Scene.from_mesh([[0, 0, 0], [float("nan"), 0, 0], [0, 1, 0]], [0, 1, 2])
    with pytest.raises(rvr.BadInput, match=r"^mesh: normals: 2 normals for 3 vertices$"):
        rvr.Scene.from_mesh(vertices, [0, 1, 2], normals=[[0, 0, 1], [0, 0, 1]])
    with pytest.raises(rvr.BadInput, match=r"^mesh: all triangles are degenerate"):
        rvr.Scene.from_mesh([[0, 0, 0], [1, 0, 0], [2, 0, 0]], [0, 1, 2])
    with pytest.raises(rvr.BadInput, match=r"^indices: expected integers, got float64$"):
        rvr.Scene.from_mesh(vertices, [[0.0, 1.0, 2.5]])
    with pytest.raises(rvr.BadInput, match=r"^up_axis: expected y or z, got 'x'$"):
        rvr.Scene.from_mesh(vertices, [0, 1, 2], up_axis="x")


# Under make sanitize, python3 runs with ASan's runtime preloaded: its operator new comes before
# the module's in symbol lookup, so the module's counting operator new (the budget) never runs
# and the import is stopped by its CPU limit instead. The command line keeps its own operator
# new under ASan (an executable's symbols come first) and is checked there.
@pytest.mark.skipif("libasan" in os.environ.get("LD_PRELOAD", ""),
                    reason="ASan's preloaded operator new replaces the module's budget")
@pytest.mark.parametrize("name,ext", [("dae_triangle_count_past_the_file_oom", "dae"),
                                      ("off_vertex_count_past_the_file_oom", "off"),
                                      ("ply_ascii_vertex_count_past_the_file_oom", "ply")])
def test_model_files_that_overstate_their_size_are_refused_as_by_the_command_line(
        name, ext, run_cli, tmp_path):
    # The import's allocation budget (scene_io/src/allocation_budget.h) holds in the module as in
    # the command line: Assimp lives in the model-import plugin, whose operator new forwards
    # to the module's, where the budget is counted. The fuzzers' inputs, first byte dropped.
    source = pathlib.Path(os.environ["RVR_SOURCE_DIR"]) / "tests/fuzz/regressions/mesh" / name
    path = tmp_path / f"mesh.{ext}"
    path.write_bytes(source.read_bytes()[1:])
    expected = cli_message(run_cli, "render", str(path), "-r", "raytrace", "-q",
                           "-o", str(tmp_path / "out.png"))
    assert "declares more data than it holds" in expected
    with pytest.raises(rvr.BadInput) as caught:
        rvr.Scene(path)
    assert str(caught.value) == expected


def test_the_stub_lists_every_render_keyword():
    # rvr.render's docstring names the keywords the module takes (the render option table's
    # and gl), in the table's order: those an unknown keyword's error lists.
    with pytest.raises(rvr.BadInput) as caught:
        rvr.render(rvr.Scene("builtin:cornell", width=8, height=8), "raytrace", zzz=1)
    known = str(caught.value).split("(known: ")[1].rstrip(")")
    doc = " ".join(rvr.render.__doc__.split())
    listed = doc.split("of the same names: ")[1].split(". ")[0]
    assert listed == known


def test_options_the_renderer_does_not_read_are_warnings():
    scene = rvr.Scene("builtin:cornell", width=16, height=12)
    r = rvr.render(scene, "raytrace", shadow_map_size=512, accel="bvh2")
    assert r.warnings == ["option shadow_map_size is not read by raytrace"]
    assert r.stats["warnings"] == r.warnings
    r = rvr.render(scene, "softraster", accel="none", hiz=False, threads=1)
    assert r.warnings == ["option accel is not read by softraster"]
    assert rvr.render(scene, "raster", threads=2).warnings == [
        "option threads is not read by raster"]
