"""``semexplore explore``: arguments, JSON output, config files and overrides."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from semexplore_gym.cli import main
from semexplore_gym.cli.explore import JSON_KEYS

REPO = Path(__file__).resolve().parents[2]


def test_explore_json_prints_the_documented_keys(capsys):
    code = main(
        [
            "explore",
            "--world",
            "maze1",
            "--policy",
            "random",
            "--seed",
            "1",
            "--max-time-s",
            "3",
            "--json",
            "--no-progress",
        ]
    )
    assert code == 0
    out = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert tuple(out) == JSON_KEYS
    assert out["mission_time_s"] == pytest.approx(3.0)
    assert out["self_stopped"] is False and 0 < out["coverage"] <= 1


def test_explore_text_output_with_paper_config(capsys):
    cfg = REPO / "configs" / "expert" / "robust_paper_weights.yaml"
    code = main(
        [
            "explore",
            "--world",
            "maze1",
            "--policy-config",
            str(cfg),
            "--policy-set",
            "cost.w_v=2",
            "--max-time-s",
            "2",
            "--no-progress",
        ]
    )
    assert code == 0
    text = capsys.readouterr().out
    assert "coverage" in text and "stop_reason" in text and "stage split" in text


def test_explore_rejects_bad_keys_and_files(tmp_path, capsys):
    def explore(*extra: str) -> int:
        return main(["explore", "--world", "maze1", *extra, "--no-progress"])

    assert explore("--policy-set", "cost.w_x=2", "--max-time-s", "1") == 2
    assert "cost.w_x" in capsys.readouterr().err
    bad = tmp_path / "bad.yaml"
    bad.write_text("params:\n  potential_field:\n    f_q: 1\n")
    assert explore("--policy-config", str(bad), "--max-time-s", "1") == 2
    assert "potential_field.f_q" in capsys.readouterr().err
    top = tmp_path / "top.yaml"
    top.write_text("robot:\n  radius_m: 0.1\n")
    assert explore("--policy-config", str(top), "--max-time-s", "1") == 2
    assert "robot" in capsys.readouterr().err
    assert explore("--policy-config", str(tmp_path / "missing.yaml")) == 2


@pytest.mark.parametrize(("policy", "want"), [("semantic", "shared"), ("random", "copy")])
def test_explore_gives_the_shared_map_to_policies_that_declare_it(
    policy, want, monkeypatch, capsys
):
    # The semantic expert reads the map only within a step: explore hands it the env's live
    # map (no per-step copy); the random policy does not declare it and gets copies. Run with
    # the progress bar, as users do.
    from semexplore_gym.envs.semantic_explore import SemanticExploreEnv

    made: list[str] = []
    init = SemanticExploreEnv.__init__

    def spy(self, *args, **kwargs):
        init(self, *args, **kwargs)
        made.append(self.map_observation)

    monkeypatch.setattr(SemanticExploreEnv, "__init__", spy)
    args = ["explore", "--world", "maze1", "--policy", policy, "--max-time-s", "20", "--json"]
    assert main(args) == 0
    out = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert out["mission_time_s"] > 0
    assert made[0] == want  # the mission env (a warm-up env may follow)


@pytest.mark.slow
def test_explore_with_a_team_writes_a_team_gif(tmp_path, capsys):
    pytest.importorskip("pettingzoo")
    gif = tmp_path / "team.gif"
    argv = ["explore", "--world", "office:seed=304,size_m=8", "--robots", "2"]
    argv += ["--policy", "coordinated", "--max-time-s", "8", "--gif", str(gif), "--json"]
    assert main([*argv, "--no-progress"]) == 0
    row = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert row["n_robots"] == 2 and row["policy"] == "team_coordinated"
    assert row["mission_time_s"] == pytest.approx(8.0) and row["self_stopped"] is False
    assert gif.stat().st_size > 0
    assert main(["explore", "--robots", "2", "--policy", "frontier", "--no-progress"]) == 2
    assert "team policy" in capsys.readouterr().err


def test_explore_and_run_mission_give_one_answer_for_one_mission(capsys):
    """Same world, policy and seed: the CLI's JSON and ``run_mission`` with its defaults agree.
    On this world the env's coverage goal (99 %) comes before the expert stops itself: a
    run_mission that stopped at the env's goal would report less coverage and time."""
    import gymnasium as gym

    from semexplore_gym import make_policy, run_mission

    world = "maze:seed=3,size_m=4"
    argv = ["explore", "--world", world, "--policy", "semantic", "--seed", "0"]
    assert main([*argv, "--max-time-s", "300", "--json", "--no-progress"]) == 0
    cli = json.loads(capsys.readouterr().out)
    env = gym.make("SemanticExplore-v0", world=world)
    try:
        res = run_mission(env, make_policy("semantic"), seed=0, max_time_s=300.0)
    finally:
        env.close()
    assert cli["self_stopped"] and res.self_stopped
    assert res.coverage == pytest.approx(cli["coverage"], abs=1e-4)
    assert res.mission_time_s == pytest.approx(cli["mission_time_s"], abs=1e-6)
    assert res.stop_reason == cli["stop_reason"]
