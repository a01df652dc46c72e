"""The env's SLAM mapping mode: preset, info, determinism, errors and a mission against odometry."""

from __future__ import annotations

import json
import math
import sys
from typing import Any

import gymnasium as gym
import numpy as np
import pytest

import semexplore_gym  # noqa: F401  (registers the env ids)
from semexplore_gym.cli import main
from semexplore_gym.config.builder import ConfigError
from semexplore_gym.core.grid import UNKNOWN
from semexplore_gym.core.slam.pose_graph import GTSAM_HINT
from semexplore_gym.envs.slam_mode import SLAM_INFO_KEYS

pytest.importorskip("gtsam")

WORLD = "maze:seed=3,size_m=5"


def _drive(env: gym.Env, n_steps: int, seed: int) -> tuple[list[np.ndarray], list[dict]]:
    """Seeded random actions; the maps and infos after every step."""
    obs, info = env.reset(seed=seed)
    rng = np.random.default_rng(seed)
    maps, infos = [obs["map"].copy()], [info]
    for _ in range(n_steps):
        action = np.array([0.9, rng.uniform(-1.0, 1.0)], dtype=np.float32)
        obs, _, _, _, info = env.step(action)
        maps.append(obs["map"].copy())
        infos.append(info)
    return maps, infos


def test_the_slam_preset_gives_slams_map_pose_and_info() -> None:
    env = gym.make("SemanticExplore-v0", world=WORLD, config="slam")
    u = env.unwrapped
    assert u.config.slam.enabled and u.config.odometry.rot_from_rot == 0.02
    obs, info = env.reset(seed=0)
    assert set(SLAM_INFO_KEYS) <= set(info)
    for _ in range(60):
        obs, _, _, _, info = env.step(np.array([0.8, 0.3], dtype=np.float32))
    # The observed map is the SLAM map, the pose its estimate; the truth is only in info.
    assert np.array_equal(obs["map"], u.slam.grid.encoded)
    assert not np.array_equal(obs["map"], u.grid.encoded)
    assert np.allclose(obs["pose"][:2], info["slam_pose"][:2], atol=1e-5)
    true_xy = u.sim.pose[:2]
    err = math.hypot(info["slam_pose"][0] - true_xy[0], info["slam_pose"][1] - true_xy[1])
    assert info["slam_pose_error_m"] == pytest.approx(err)
    assert isinstance(info["loop_closures"], int) and isinstance(info["slam_lost"], bool)
    plain = gym.make("SemanticExplore-v0", world=WORLD)
    assert not set(SLAM_INFO_KEYS) & set(plain.reset(seed=0)[1])


def test_known_when_seen_from_the_command_line_leaves_no_seen_cell_unknown(capsys) -> None:
    """``--env-set slam.known_when_seen=true`` reaches the back end: after a mission no cell
    with evidence either way is unknown in the SLAM map (by default some are, at walls seen
    twice); only cells whose hits and misses cancel to within 1e-4 may be."""
    counts = {}
    for value in ("false", "true"):
        ov = [f"slam.known_when_seen={value}"]
        env = gym.make("SemanticExplore-v0", world=WORLD, config="slam", overrides=ov)
        _drive(env, 150, seed=2)
        grid = env.unwrapped.slam.grid
        counts[value] = int(
            np.count_nonzero((np.abs(grid.log_odds) > 1e-4) & (grid.encoded == UNKNOWN))
        )
    assert counts["false"] > 0 and counts["true"] == 0
    code = main(
        ["explore", "--world", WORLD, "--env-config", "slam", "--env-set",
         "slam.known_when_seen=true", "--max-time-s", "20", "--json", "--no-progress"]
    )  # fmt: skip
    assert code == 0 and "ate_m" in json.loads(capsys.readouterr().out)


def test_same_seed_same_slam_map_bit_for_bit() -> None:
    a_maps, a_infos = _drive(gym.make("SemanticExplore-v0", world=WORLD, config="slam"), 120, 5)
    b_maps, b_infos = _drive(gym.make("SemanticExplore-v0", world=WORLD, config="slam"), 120, 5)
    assert all(np.array_equal(a, b) for a, b in zip(a_maps, b_maps, strict=True))
    assert [i["slam_pose"] for i in a_infos] == [i["slam_pose"] for i in b_infos]


@pytest.mark.parametrize(
    ("override", "named"),
    [
        ("slam.search_xy_m=-1", "slam.search_xy_m"),
        ("slam.loop_score_threshold=2", "slam.loop_score_threshold"),
        ("slam.submap_keyframes=2.5", "slam.submap_keyframes"),
        ("slam.enabled=maybe", "slam.enabled"),
        ("slam.loop_max_residual_m=-0.01", "slam.loop_max_residual_m"),
        ("slam.backface_margin_m=-1", "slam.backface_margin_m"),
        ("slam.known_when_seen=2", "slam.known_when_seen"),
    ],
)
def test_a_bad_slam_value_is_one_line_naming_it(override: str, named: str, capsys) -> None:
    with pytest.raises(ConfigError) as e:
        gym.make("SemanticExplore-v0", world=WORLD, config="slam", overrides=[override])
    assert named in str(e.value) and "\n" not in str(e.value)
    code = main(["explore", "--world", WORLD, "--env-config", "slam", "--env-set", override])
    err = capsys.readouterr().err
    assert code == 2 and named in err and len(err.strip().splitlines()) == 1


def test_without_gtsam_the_slam_mode_fails_with_one_line(monkeypatch, capsys) -> None:
    monkeypatch.setitem(sys.modules, "gtsam", None)  # import gtsam raises ImportError
    with pytest.raises(ImportError) as e:
        gym.make("SemanticExplore-v0", world=WORLD, config="slam")
    assert str(e.value) == GTSAM_HINT
    assert "pip install 'semexplore-gym[slam]'" in GTSAM_HINT and "\n" not in GTSAM_HINT
    code = main(["explore", "--world", WORLD, "--env-config", "slam", "--no-progress"])
    err = capsys.readouterr().err
    assert code == 2 and err.strip().splitlines() == [f"semexplore explore: error: {GTSAM_HINT}"]
    # Without the slam mode nothing needs gtsam.
    gym.make("SemanticExplore-v0", world=WORLD, config="default").reset(seed=0)


@pytest.mark.slow
def test_slam_mission_ends_closer_to_the_truth_than_odometry_alone(capsys) -> None:
    from semexplore_gym.policies.registry import make_policy

    from semexplore_gym.evaluation.rollout import run_mission

    errors, results = {}, {}
    for slam_on in (True, False):
        overrides = ["episode.max_time_s=400", f"slam.enabled={str(slam_on).lower()}"]
        env = gym.make("SemanticExplore-v0", world=WORLD, config="slam", overrides=overrides)
        result = run_mission(env, make_policy("semantic"), seed=0, ignore_terminated=True)
        u = env.unwrapped
        est, true = u._pose_values(), u.sim.pose
        errors[slam_on] = math.hypot(est[0] - true[0], est[1] - true[1])
        results[slam_on] = result.summary()
    assert errors[True] < errors[False]
    assert errors[True] < 0.1
    on, off = results[True], results[False]
    assert {"ate_m", "rpe_m", "map_error", "loop_closures", "slam_lost"} <= set(on)
    assert "ate_m" not in off
    assert on["ate_m"] < 0.1 and 0 <= on["map_error"] < 0.2
    assert on["odom_ate_m"] > 3 * on["ate_m"]  # the goal: at least 3x below odometry alone
    assert 0 <= on["rpe_m"] < 0.1  # 400 s of the expert: far more than 1 m of travel
    assert on["collisions"] == 0
    # explore --json carries the SLAM figures when the env runs SLAM.
    args = ["explore", "--world", WORLD, "--env-config", "slam", "--max-time-s", "20"]
    assert main([*args, "--json", "--no-progress"]) == 0
    out = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert {"ate_m", "rpe_m", "map_error", "loop_closures", "slam_lost"} <= set(out)
    assert {"odom_ate_m", "slam_false_stop", "slam_stop_artefact"} <= set(out)
    assert out["odom_ate_m"] > out["ate_m"]


def test_the_odometry_ate_sits_beside_slams_and_is_zero_without_drift() -> None:
    from semexplore_gym.evaluation.rollout import slam_metrics

    drifting = gym.make("SemanticExplore-v0", world=WORLD, config="slam")
    _drive(drifting, 150, 2)
    figures = slam_metrics(drifting)
    assert figures["odom_ate_m"] > 0.0 and figures["ate_m"] >= 0.0
    alphas = ("rot_from_rot", "rot_from_trans", "trans_from_trans", "trans_from_rot")
    exact = gym.make(
        "SemanticExplore-v0",
        world=WORLD,
        config="slam",
        overrides=[f"odometry.{a}=0" for a in alphas],
    )
    _drive(exact, 150, 2)
    assert slam_metrics(exact)["odom_ate_m"] == 0.0


def test_a_stop_short_on_a_map_that_closed_every_gap_is_a_false_stop() -> None:
    from semexplore_gym.evaluation.rollout import slam_metrics

    env = gym.make("SemanticExplore-v0", world=WORLD, config="slam")
    _drive(env, 40, 1)
    u: Any = env.unwrapped
    assert u.grid.n_free_in_mask < u.grid.n_mask_cells  # short of the goal on the truth
    honest = slam_metrics(env, self_stopped=True)
    assert slam_metrics(env)["slam_false_stop"] is False  # not stopped: nothing to explain
    # SLAM's map, with every cell it has not seen turned into wall: no frontier left.
    closed = u.slam.grid.log_odds.copy()
    closed[u.slam.grid.encoded == 128] = 5.0
    u.slam.grid.load_log_odds(closed)
    figures = slam_metrics(env, self_stopped=True)
    assert figures["slam_false_stop"] is True
    assert figures["slam_stop_artefact"] == "lost_frontier"
    assert honest["slam_stop_artefact"] != "lost_frontier"


def test_render_draws_the_slam_map_beside_the_truth() -> None:
    slam = gym.make("SemanticExplore-v0", world=WORLD, config="slam", render_mode="rgb_array")
    plain = gym.make("SemanticExplore-v0", world=WORLD, render_mode="rgb_array")
    slam.reset(seed=0)
    plain.reset(seed=0)
    for _ in range(30):
        slam.step(np.array([0.8, 0.2], dtype=np.float32))
    frame, one = slam.render(), plain.render()
    assert frame.shape == (one.shape[0], 2 * one.shape[1] + 6, 3) and frame.dtype == np.uint8
    left, right = frame[:, : one.shape[1]], frame[:, one.shape[1] + 6 :]
    assert not np.array_equal(left, right)  # two different maps
