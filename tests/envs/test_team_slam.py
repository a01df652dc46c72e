"""SemanticExploreMulti-v0 with SLAM: each robot its own SLAM, the merged SLAM map observed."""

from __future__ import annotations

import json
from typing import Any

import gymnasium as gym
import numpy as np
import pytest

pytest.importorskip("pettingzoo")
pytest.importorskip("gtsam")

from semexplore_gym.cli import main  # noqa: E402
from semexplore_gym.core.mapping.map_merge import merged_log_odds  # noqa: E402
from semexplore_gym.envs.multi_robot import make_multi  # noqa: E402
from semexplore_gym.envs.slam_mode import SLAM_INFO_KEYS  # noqa: E402
from semexplore_gym.evaluation.team_benchmark import SLAM_COLUMNS  # noqa: E402

WORLD = "maze:seed=3,size_m=5"


def _step(env: Any, n_steps: int, seed: int) -> tuple[dict, dict]:
    rng = np.random.default_rng(seed)
    obs, infos = env.reset(seed=seed)
    for _ in range(n_steps):
        actions = {a: np.array([0.9, rng.uniform(-1, 1)], np.float32) for a in env.agents}
        obs, _, _, _, infos = env.step(actions)
    return obs, infos


def test_each_robot_runs_its_own_slam_and_sees_the_merged_slam_map() -> None:
    env = make_multi(world=WORLD, n_robots=2, config="slam")
    obs, infos = _step(env, 60, 0)
    a, b = env.slam.robots  # type: ignore[union-attr]
    assert a.backend is not b.backend and a.grid is not b.grid
    assert a.backend.keyframe_poses[0] != b.backend.keyframe_poses[0]  # own starts
    merged = env.slam.grid  # type: ignore[union-attr]
    expected = merged_log_odds([a.grid, b.grid])
    assert np.array_equal(merged.log_odds, expected)
    for i, agent in enumerate(env.possible_agents):
        assert set(SLAM_INFO_KEYS) <= set(infos[agent])
        assert np.array_equal(obs[agent]["map"], merged.encoded)  # the SLAM team map...
        assert np.allclose(obs[agent]["pose"][:2], infos[agent]["slam_pose"][:2], atol=1e-5)
        assert infos[agent]["slam_pose_error_m"] < 0.5  # random driving, bumps included
        est = env.slam.robots[i].backend.estimate  # type: ignore[union-attr]
        assert infos[agent]["slam_pose"] == est
    assert not np.array_equal(obs["robot_0"]["map"], env.grid.encoded)  # ...not the truth
    figures = env.slam.metrics(env.grid)  # type: ignore[union-attr]
    assert set(figures) == set(SLAM_COLUMNS)
    assert 0.0 <= figures["ate_m"] < figures["odom_ate_m"]


def test_one_robot_with_slam_is_the_single_envs_slam() -> None:
    team = make_multi(world=WORLD, n_robots=1, config="slam")
    single = gym.make("SemanticExplore-v0", world=WORLD, config="slam")
    rng = np.random.default_rng(4)
    obs_t, _ = team.reset(seed=4)
    obs_s, _ = single.reset(seed=4)
    for _ in range(50):
        action = np.array([0.9, rng.uniform(-1, 1)], np.float32)
        obs_t, _, _, _, info_t = team.step({"robot_0": action})
        obs_s, _, _, _, info_s = single.step(action)
    assert np.array_equal(obs_t["robot_0"]["map"], obs_s["map"])
    assert np.array_equal(obs_t["robot_0"]["pose"], obs_s["pose"])
    assert info_t["robot_0"]["slam_pose"] == info_s["slam_pose"]


def test_slam_with_range_sharing_is_refused_in_one_line() -> None:
    with pytest.raises(ValueError, match=r"slam.enabled needs team.map_sharing=team") as e:
        make_multi(world=WORLD, n_robots=2, config="slam", overrides=["team.map_sharing=range"])
    assert "\n" not in str(e.value)


def test_benchmark_robots_with_the_slam_config_writes_the_slam_columns(tmp_path, capsys) -> None:
    out = tmp_path / "team"
    argv = ["benchmark", "--worlds", WORLD, "--robots", "1,2", "--policies", "coordinated"]
    argv += ["--runs", "1", "--max-time-s", "15", "--env-config", "slam", "--out", str(out)]
    assert main([*argv, "--no-progress", "--no-plots", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["failed"] == 0
    import csv

    with (out / "runs.csv").open(newline="") as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == 2
    for r in rows:
        assert 0.0 <= float(r["ate_m"]) < 0.2 and float(r["odom_ate_m"]) > 0.0
        assert 0.0 <= float(r["map_error"]) <= 1.0
