"""The move_base-like Navigator: goal tolerance and the way out of an unreachable goal."""

from __future__ import annotations

import math

import numpy as np
from semexplore_gym.policies.base import StepStats
from semexplore_gym.policies.navigation import MoveBaseParams, Navigator, NavStatus

from semexplore_gym.core.grid import FREE, OCCUPIED, UNKNOWN, GridGeometry

RES_M = 0.05
DT_S = 0.2
RADIUS_M = 0.105


def _room() -> tuple[np.ndarray, GridGeometry]:
    """A 1.6 m x 1.2 m room; its right part (x >= 1.15 m) not yet seen."""
    grid = np.full((24, 36), OCCUPIED, dtype=np.uint8)
    grid[1:23, 1:35] = FREE
    grid[1:23, 23:35] = UNKNOWN
    return grid, GridGeometry(RES_M, 0.0, 0.0, *grid.shape)


def _drive(
    nav: Navigator, grid: np.ndarray, geo: GridGeometry, pose: np.ndarray, t0_s: float, t1_s: float
) -> tuple[np.ndarray, float, float]:
    """Unicycle steps from ``t0_s`` until the goal ends or ``t1_s``; returns pose, time, closest."""
    t, closest = t0_s, math.inf
    assert nav.goal_xy_m is not None
    gx, gy = nav.goal_xy_m
    while t < t1_s and nav.status in (NavStatus.ACTIVE, NavStatus.RECOVERING):
        v, w = nav.step(t, pose, grid, geo, None, StepStats())
        pose = pose + DT_S * np.array([v * math.cos(pose[2]), v * math.sin(pose[2]), w])
        closest = min(closest, math.hypot(pose[0] - gx, pose[1] - gy))
        t += DT_S
    return pose, t, closest


def test_a_goal_inside_a_newly_seen_wall_is_aborted_instead_of_circled() -> None:
    # FE's travel point lay in unknown space; once seen, it is a wall the robot cannot get
    # closer to than ~0.45 m. ROS's DWA then fails (its goal flood cannot leave the goal),
    # move_base replans, the plan fails, and patience, two recoveries and the abort follow.
    grid, geo = _room()
    goal = (1.475, 0.625)
    for check in (True, False):
        nav = Navigator(MoveBaseParams(local_goal_check=check), RADIUS_M, (0.22, 2.84), DT_S)
        pose = np.array([0.5, 0.6, 0.0])
        nav.set_goal(goal, 0.0)
        pose, t, _ = _drive(nav, grid, geo, pose, 0.0, 1.0)  # plans through the unknown
        assert nav.path is not None
        seen = grid.copy()
        seen[1:23, 23:35] = OCCUPIED  # the wall the goal is in
        pose, t, closest = _drive(nav, seen, geo, pose, t, 300.0)
        assert closest > 0.4  # the robot never got near its goal
        if check:
            assert nav.status == NavStatus.ABORTED
            assert t < 60.0, f"aborted only after {t:.0f} s"
            assert nav.counters["unreachable_local_goal"] >= 1
            assert nav.counters["recoveries"] == MoveBaseParams().max_recoveries
        else:
            # Without the rule nothing ends the goal while the robot keeps moving.
            assert nav.status != NavStatus.SUCCEEDED


def test_goal_reached_within_the_xy_goal_tolerance() -> None:
    grid, geo = _room()
    grid[1:23, 23:35] = FREE
    nav = Navigator(MoveBaseParams(local_goal_check=True), RADIUS_M, (0.22, 2.84), DT_S)
    nav.set_goal((1.225, 0.625), 0.0)  # a cell centre (the path ends there)
    pose, t, closest = _drive(nav, grid, geo, np.array([0.5, 0.6, 0.0]), 0.0, 60.0)
    assert nav.status == NavStatus.SUCCEEDED
    assert closest <= MoveBaseParams().dwa.xy_goal_tolerance_m
    assert nav.counters["unreachable_local_goal"] == 0
