# Bad input raises rvr.BadInput, a ValueError, whose text is the command line's error line
# without "error: ", for the same input.
import json

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


def test_unknown_renderer(run_cli, tmp_path):
    expected = cli_message(run_cli, "render", "builtin:cornell", "-r", "nonesuch", "-q",
                           "-o", str(tmp_path / "out.png"))
    with pytest.raises(rvr.BadInput) as caught:
        rvr.render(rvr.Scene("builtin:cornell", width=8, height=8), "nonesuch")
    assert str(caught.value) == expected


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
    with pytest.raises(rvr.BadInput, match="^accel: expected one of bvh, bvh2, none"):
        rvr.render(scene, "raytrace", accel="kd")
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
