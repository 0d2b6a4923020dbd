# rvr.study gives the document `rvr study` writes as study.json: the same keys, the same
# renderers and families, points for pandas; bad input is the command line's message.
import json

import pytest

import rvr


def test_study_is_study_json(run_cli, tmp_path):
    # The command's sessions are processes: under the sanitizers on a busy machine 2 s of budget
    # measured no point at all (and so no point keys to compare); 6 s leaves room for some.
    args = ["builtin:tessphere", "--width", "32", "--budget", "6", "--repetitions", "5",
            "-q", "-o", str(tmp_path)]
    done = run_cli("study", *args)
    expected = json.loads((tmp_path / "study.json").read_text())
    # A study this short may conclude nothing: the command says why and exits 1.
    assert done.returncode == (1 if expected["no_conclusion"] else 0), done.stderr
    got = rvr.study(["builtin:tessphere"], width=32, budget=2, repetitions=5)
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
