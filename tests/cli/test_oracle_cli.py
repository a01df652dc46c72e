"""``semexplore oracle``: the static bound's JSON keys and one clear line for bad input."""

from __future__ import annotations

import json

import pytest

from semexplore_gym.cli import main
from semexplore_gym.cli.oracle import JSON_KEYS

pytest.importorskip("elkai")


def test_oracle_json_prints_the_documented_keys(capsys):
    assert main(["oracle", "maze:seed=1,size_m=5", "--start-seed", "3", "--json"]) == 0
    out = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert tuple(out) == JSON_KEYS
    assert out["start_seed"] == 3 and out["n_viewpoints"] >= 1
    assert out["covered_share"] >= 0.995
    assert out["time_at_top_speed_s"] == pytest.approx(out["tour_length_m"] / 0.22, rel=1e-3)
    # the certified lower bound sits below the tour (a feasible drive of the goal's share)
    assert 0 < out["lower_bound_m"] <= out["tour_length_m"]
    assert out["lower_bound_s"] == pytest.approx(out["lower_bound_m"] / 0.22, rel=1e-3)
    assert out["lower_bound_groups"] >= 1 and out["bound_planning_s"] >= 0
    # the bound is the larger of the route's and the branches'
    assert 0 < out["lower_bound_branch_m"] <= out["lower_bound_m"]


def test_no_bound_leaves_the_bound_keys_null(capsys):
    argv = ["oracle", "maze:seed=1,size_m=5", "--json", "--no-bound"]
    assert main(argv) == 0
    out = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert out["lower_bound_m"] is None and out["bound_planning_s"] is None
    assert out["tour_length_m"] > 0


def test_the_text_line_says_the_bound(capsys):
    assert main(["oracle", "maze:seed=1,size_m=5"]) == 0
    assert "lower bound:" in capsys.readouterr().out


@pytest.mark.parametrize(
    "argv, words",
    [
        (["oracle", "nosuch:seed=1"], "unknown world"),
        (["oracle", "maze1", "--env-set", "episode.start_pose=[0.0,0.0,0.0]"], "start pose"),
        (
            ["oracle", "maze:seed=1,size_m=5", "--env-set", "lidar.range_noise_std_m=0.01"],
            "noise-free LiDAR",
        ),
    ],
)
def test_bad_input_gets_one_clear_line(argv, words, capsys):
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and words in err[0]


def test_a_missing_solver_is_one_line_saying_what_to_install(monkeypatch, capsys):
    import sys

    from semexplore_gym.policies.registry import make_policy

    monkeypatch.setitem(sys.modules, "elkai", None)  # import elkai now raises ImportError
    assert main(["oracle", "maze:seed=1,size_m=5"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "pip install" in err[0] and "elkai" in err[0]
    with pytest.raises(ValueError, match="elkai"):
        make_policy("oracle")


def test_a_suite_without_the_solver_runs_without_the_oracle(monkeypatch, capsys, tmp_path):
    """The oracle is on by default with --suite: a plain install (no elkai) still runs the
    suite and says in one line why there is no regret; --oracle asked by name is an error."""
    import sys

    monkeypatch.setitem(sys.modules, "elkai", None)
    suite = tmp_path / "tiny.yaml"
    suite.write_text(
        "name: tiny\nversion: 1\ndescription: one small maze\nruns: 1\nrandom_start: true\n"
        "max_time_s: 30.0\nworlds:\n- maze:seed=1,size_m=4\n"
    )
    base = ["benchmark", "--suite", str(suite), "--policies", "nearest", "--no-progress"]
    assert main([*base, "--no-plots", "--out", str(tmp_path / "a")]) == 0
    err = capsys.readouterr().err
    assert "no oracle (regret) in this run" in err and "elkai" in err
    assert not (tmp_path / "a" / "regret.csv").exists()
    assert main([*base, "--oracle", "--no-plots", "--out", str(tmp_path / "b")]) == 2
    assert "elkai" in capsys.readouterr().err
