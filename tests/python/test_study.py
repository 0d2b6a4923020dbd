# rvr.study gives the document `rvr study` writes as study.json: the same keys, the same
# renderers and families, points for pandas; bad input is the command line's message.
import json

import pytest

import rvr


def test_study_is_study_json(run_cli, study_budget, tmp_path):
    # The command's sessions are processes: under the sanitizers on a busy machine 2 s of budget
    # measured no point at all (and so no point keys to compare); 6 s leaves room for some.
    args = ["builtin:tessphere", "--width", "32", "--budget", f"{study_budget(6):g}",
            "--repetitions", "5",
            "-q", "-o", str(tmp_path)]
    done = run_cli("study", *args)
    expected = json.loads((tmp_path / "study.json").read_text())
    # A study this short may conclude nothing: the command says why and exits 1.
    assert done.returncode == (1 if expected["no_conclusion"] else 0), done.stderr
    got = rvr.study(["builtin:tessphere"], width=32, budget=study_budget(2), repetitions=5)
    assert list(got) == list(expected)
    assert list(got["renderers"]) == list(expected["renderers"])
    assert set(got["renderers"]) == {"softraster", "raytrace", "hybrid_soft"}
    assert got["machine"].keys() == expected["machine"].keys()
    assert got["points"] and all(p.keys() == got["points"][0].keys() for p in got["points"])
    assert expected["points"], "the command's study measured no point within its budget"
    assert got["points"][0].keys() == expected["points"][0].keys()
    assert {s["kind"] for s in got["sessions"]} == {"preparation"}
    assert {s["kind"] for s in expected["sessions"]} == {"process"}


def test_study_bad_input_is_the_command_lines(run_cli, tmp_path):
    done = run_cli("study", "builtin:nonesuch", "--width", "32", "--budget", "2", "-q",
                   "-o", str(tmp_path))
    assert done.returncode == 2
    expected = done.stderr.strip().splitlines()[-1][len("error: "):]
    with pytest.raises(rvr.BadInput) as caught:
        rvr.study(["builtin:nonesuch"], width=32, budget=2)
    assert str(caught.value) == expected


def test_full_mode_measures_each_technique_against_the_tracer(run_cli, study_budget,
                                                              tmp_path):
    # In full mode each renderer's first frame of a point is compared with raytrace's in each
    # effect's mask: the same numbers whether the point was prepared in a worker process (the
    # command line) or in this one, and the same as rvr.compare of the two renders made here.
    # Under the sanitizers softraster's full-mode frame takes 0.16 s: 6 s measured one point on an
    # idle machine and none with two other busy processes, hence the scaled budgets.
    args = ["builtin:effects", "--mode", "full", "--width", "32",
            "--budget", f"{study_budget(6):g}",
            "--repetitions", "3", "-q", "-o", str(tmp_path)]
    run_cli("study", *args)
    by_process = json.loads((tmp_path / "study.json").read_text())["points"]
    in_process = rvr.study(["builtin:effects"], mode="full", width=32, budget=study_budget(6),
                           repetitions=3)
    assert by_process and in_process["points"]
    for points in (by_process, in_process["points"]):
        for p in points:
            if p["renderer"] == "raytrace":
                assert "effect_errors" not in p
            else:
                # builtin:effects' flat mirror is seen at every N.
                assert [e["effect"] for e in p["effect_errors"]][:1] == ["reflection"], p
    # The hybrid traces what its z-buffer cannot answer: identical to the tracer (PSNR null).
    assert all(e["psnr_db"] is None for p in by_process if p["renderer"] == "hybrid_soft"
               for e in p["effect_errors"])
    key = lambda p: (p["renderer"], p["scene_n"], p["width"])
    here = {key(p): p for p in in_process["points"]}
    shared = [p for p in by_process if key(p) in here]
    assert shared, "no point measured by both studies"
    for p in shared:
        assert p.get("effect_errors") == here[key(p)].get("effect_errors"), key(p)
    # Independently: the point's renders here, compared as rvr compare compares them.
    p = next(p for p in by_process if p["renderer"] == "softraster")
    scene = rvr.Scene(f"builtin:effects:{int(p['scene_n'])}", width=p["width"],
                      height=p["height"])
    metrics = rvr.compare(rvr.render(scene, "raytrace", mode="full"),
                          rvr.render(scene, "softraster", mode="full"))
    expected = [{k: e[k] for k in ("effect", "pixels", "rmse", "psnr_db", "ssim")}
                for e in metrics["effects"]["by_effect"]]
    assert p["effect_errors"] == expected
    # rvr.compare splits each effect's mask by the z-buffer's answers, as the command does.
    assert metrics["effects"]["answers_from"] == "softraster"
    reflection = metrics["effects"]["by_effect"][0]
    assert [a["answer"] for a in reflection["answers"]] == ["reflected_view"]
