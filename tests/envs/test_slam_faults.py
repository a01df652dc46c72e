"""SLAM faults are reported, never silent: a featureless corridor (degenerate matches) and a
kidnapped robot (``reset(options={"kidnap_to": ...})``)."""

from __future__ import annotations

import math
from typing import Any

import gymnasium as gym
import numpy as np
import pytest

import semexplore_gym  # noqa: F401  (registers the env ids)
from semexplore_gym.core.slam.matcher import build_likelihood_field, match_scan
from semexplore_gym.core.worlds.build import world_from_segments
from semexplore_gym.evaluation.rollout import run_mission, slam_metrics

pytest.importorskip("gtsam")

CORRIDOR_M = 24.0
WIDTH_M = 1.2


def _corridor():
    walls = [
        (0.0, 0.0, CORRIDOR_M, 0.0),
        (0.0, WIDTH_M, CORRIDOR_M, WIDTH_M),
        (0.0, 0.0, 0.0, WIDTH_M),
        (CORRIDOR_M, 0.0, CORRIDOR_M, WIDTH_M),
    ]
    return world_from_segments(
        "corridor", walls, [(1.0, WIDTH_M / 2)], start_pose=(1.0, WIDTH_M / 2, 0.0)
    )


def test_two_parallel_walls_leave_the_match_loose_along_them_only() -> None:
    xs = np.arange(-10.0, 10.0, 0.02)
    walls = np.concatenate([np.column_stack([xs, np.full_like(xs, y)]) for y in (-0.6, 0.6)])
    field = build_likelihood_field(walls, 0.025, 0.04)
    near = np.abs(walls[:, 0]) < 3.0  # what a 3.5 m LiDAR sees of them
    match = match_scan(field, walls[near], (0.0, 0.0, 0.0), 0.2, 0.3)
    sd_x, sd_y = np.sqrt(np.diag(match.covariance)[:2])
    assert sd_x > 0.08 > 0.04 > sd_y  # along the corridor: about the whole search window


def _drive_down_the_corridor(degenerate_sd_m: float) -> dict:
    env = gym.make(
        "SemanticExplore-v0",
        world=_corridor(),
        config="slam",
        overrides=[f"slam.degenerate_sd_m={degenerate_sd_m}"],
    )
    env.reset(seed=0)
    u: Any = env.unwrapped
    for _ in range(700):
        _, _, _, _, info = env.step(np.array([1.0, 0.0], dtype=np.float32))
    assert info["slam_degenerate_matches"] == u.slam.backend.degenerate_matches
    return {**slam_metrics(env), "info": info}


def test_a_featureless_corridor_is_reported_and_held_on_odometry_along_it() -> None:
    on = _drive_down_the_corridor(0.08)
    assert on["slam_degenerate_matches"] > 20  # counted in info and in the mission record
    assert on["info"]["slam_degenerate_matches"] == on["slam_degenerate_matches"]
    assert on["ate_m"] < 0.15
    # Taken at face value the flat matches pull the estimate metres behind the robot.
    off = _drive_down_the_corridor(10.0)
    assert off["slam_degenerate_matches"] == 0
    assert off["ate_m"] > 1.0


WORLD = "maze:seed=3,size_m=5"


def test_a_kidnapped_robot_is_noticed_and_reported_lost() -> None:
    env = gym.make("SemanticExplore-v0", world=WORLD, config="slam")
    u: Any = env.unwrapped
    from semexplore_gym.policies.registry import make_policy

    result = run_mission(env, make_policy("semantic"), seed=0, max_time_s=60.0)
    assert result.slam_metrics["ate_m"] < 0.1
    before = u.slam.backend.keyframe_poses[-1]
    trajectory = np.asarray(result.trajectory)
    far = trajectory[int(np.argmax(np.hypot(*(trajectory[:, :2] - before[:2]).T)))]
    # Facing a quarter turn away from the heading driven there: a view unlike the believed
    # one (a kidnap to a place that looks alike goes unnoticed, as docs/slam.md says).
    target = (float(far[0]), float(far[1]), float(far[2]) + math.pi / 2)
    obs, info = env.reset(options={"kidnap_to": target})
    assert u.sim.pose == pytest.approx(target)  # the robot is there...
    assert np.allclose(obs["pose"], before, atol=1e-5)  # ...SLAM still believes it is here
    assert len(u.slam.backend.keyframe_poses) > 1  # its map and keyframes are kept
    gap_m = math.hypot(target[0] - before[0], target[1] - before[1])
    assert info["slam_pose_error_m"] == pytest.approx(gap_m)
    lost = []
    for _ in range(30):
        _, _, _, _, info = env.step(np.array([0.0, 1.0], dtype=np.float32))
        lost.append(info["slam_lost"])
    assert info["slam_pose_error_m"] > 1.0
    # The back end notices at its first keyframe there (the scan jumped while the wheels
    # stood still, and its match collapsed) and stays lost: never silent.
    assert lost[0] and all(lost) and info["slam_lost_events"] == 1
    record = slam_metrics(env)
    assert record["ate_m"] > 0.5  # the mission record shows it too
    assert record["slam_lost"] is True and record["slam_lost_events"] == 1


@pytest.mark.parametrize(
    ("config", "options", "message"),
    [
        ("default", {"kidnap_to": (1.0, 1.0, 0.0)}, "kidnap_to needs the SLAM mode"),
        ("slam", {"kidnap_to": (1.0, 1.0, 0.0), "start_pose": (1.0, 1.0, 0.0)}, "exclude"),
    ],
)
def test_kidnap_to_misused_is_one_line(config: str, options: dict, message: str) -> None:
    env = gym.make("SemanticExplore-v0", world=WORLD, config=config)
    env.reset(seed=0)
    with pytest.raises(ValueError, match=message) as e:
        env.reset(options=options)
    assert "\n" not in str(e.value)
    fresh = gym.make("SemanticExplore-v0", world=WORLD, config="slam")
    with pytest.raises(ValueError, match="kidnap_to needs a first reset"):
        fresh.reset(options={"kidnap_to": (1.0, 1.0, 0.0)})
