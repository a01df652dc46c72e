"""The path decomposition: its parts add up to the path for every kind of policy; switched-away
goals, the tail, looks and recoveries land in their parts; detour ratios; the benchmark's columns."""

from __future__ import annotations

import math

import gymnasium as gym
import numpy as np
import pytest
from semexplore_gym.policies.base import DriveIntent
from semexplore_gym.policies.registry import make_policy

from semexplore_gym.core.grid import FREE, OCCUPIED, UNKNOWN, GridGeometry
from semexplore_gym.evaluation.path_decomposition import (
    DECOMPOSITION_COLUMNS,
    PART_COLUMNS,
    PathLedger,
)
from semexplore_gym.evaluation.rollout import map_observation_for, run_mission

RES = 0.05


def _room(size_m: float = 4.0) -> tuple[np.ndarray, GridGeometry]:
    n = round(size_m / RES)
    grid = np.full((n, n), FREE, dtype=np.uint8)
    grid[[0, -1], :] = OCCUPIED
    grid[:, [0, -1]] = OCCUPIED
    return grid, GridGeometry(RES, 0.0, 0.0, n, n)


def _drive(grid, geo, start, legs, areas=None):
    """Run a ledger from ``start`` over ``legs``: ``(intent, waypoints)``, each waypoint one step
    of the robot. ``areas``: free area after each step (default: always growing)."""
    steps = [(intent, np.asarray(p, dtype=float)) for intent, pts in legs for p in pts]
    areas = areas if areas is not None else [1.0 + i for i in range(len(steps))]
    info0 = {
        "map_geometry": geo.to_dict(),
        "robot": {"radius_m": 0.2},
        "path_length_m": 0.0,
        "explored_area_m2": 0.5,
    }
    pose = np.array([*start, 0.0])
    ledger = PathLedger.for_mission({"pose": pose, "map": grid}, info0)
    path = 0.0
    for (intent, p), area in zip(steps, areas, strict=True):
        ledger.before_step(intent, {"pose": pose, "map": grid})
        path += math.dist(pose[:2], p)
        pose = np.array([*p, 0.0])
        ledger.after_step(
            {"pose": pose, "map": grid}, {"path_length_m": path, "explored_area_m2": area}
        )
    return ledger.finish(), path


def _line(a, b, n):
    a, b = np.asarray(a, float), np.asarray(b, float)
    return [a + (b - a) * (i + 1) / n for i in range(n)]


def test_a_goal_switched_away_from_is_abandoned_and_a_reached_one_cleared() -> None:
    grid, geo = _room()
    grid[60:75, 60:75] = UNKNOWN  # round goal A at (3.3, 3.3): never mapped
    goal_a, goal_b = (3.3, 3.3), (1.0, 3.0)
    legs = [
        (DriveIntent(goal_a, "semantic"), _line((0.6, 1.0), (1.6, 2.0), 10)),
        (DriveIntent(goal_b, "fallback"), _line((1.6, 2.0), (1.0, 3.0), 10)),
    ]
    parts, path = _drive(grid, geo, (0.6, 1.0), legs)
    assert [(g.cleared, g.reached) for g in parts.goals] == [(False, False), (True, True)]
    assert parts.parts_m["path_to_abandoned_goals_m"] == pytest.approx(math.hypot(1.0, 1.0))
    assert parts.parts_m["path_to_cleared_goals_m"] == pytest.approx(math.hypot(0.6, 1.0))
    assert parts.path_length_m == pytest.approx(path, abs=1e-9)
    cols = parts.columns()
    assert set(cols) == set(DECOMPOSITION_COLUMNS)
    assert (cols["goals_cleared"], cols["goals_abandoned"]) == (1, 1)


def test_a_goal_whose_unknown_was_mapped_is_cleared_though_not_reached() -> None:
    grid, geo = _room()
    grid[60:75, 60:75] = UNKNOWN
    goal = (3.3, 3.3)
    legs = [(DriveIntent(goal), _line((0.6, 1.0), (1.6, 2.0), 5))]
    parts_kept, _ = _drive(grid, geo, (0.6, 1.0), legs)
    # The same drive, but the unknown round the goal is mapped before it ends.
    grid2, _ = _room()
    grid2[60:75, 60:75] = UNKNOWN
    ledger_steps = _line((0.6, 1.0), (1.6, 2.0), 5)
    info0 = {"map_geometry": geo.to_dict(), "robot": {"radius_m": 0.2}, "explored_area_m2": 0.0}
    ledger = PathLedger.for_mission({"pose": np.array([0.5, 1.0, 0.0]), "map": grid2}, info0)
    pose, path = np.array([0.5, 1.0, 0.0]), 0.0
    for i, p in enumerate(ledger_steps):
        ledger.before_step(DriveIntent(goal), {"pose": pose, "map": grid2})
        if i == 3:
            grid2[60:75, 60:75] = FREE
        path += math.dist(pose[:2], p)
        pose = np.array([*p, 0.0])
        ledger.after_step(
            {"pose": pose, "map": grid2}, {"path_length_m": path, "explored_area_m2": i}
        )
    ledger.before_step(DriveIntent(None), {"pose": pose, "map": grid2})
    parts = ledger.finish()
    assert not parts_kept.goals[0].cleared
    assert parts.goals[0].cleared and not parts.goals[0].reached


def test_the_tail_after_the_last_new_cell_is_counted() -> None:
    grid, geo = _room()
    pts = _line((0.6, 1.0), (2.6, 1.0), 20)  # 0.1 m a step
    areas = [1.0, 2.0, 3.0] + [3.0] * 17  # nothing new after the third step
    parts, path = _drive(grid, geo, (0.6, 1.0), [(DriveIntent((2.6, 1.0)), pts)], areas)
    assert parts.tail_start_step == 3
    assert parts.parts_m["path_after_last_new_cell_m"] == pytest.approx(1.7)
    assert parts.parts_m["path_to_cleared_goals_m"] == pytest.approx(0.3)
    assert parts.path_length_m == pytest.approx(path, abs=1e-9)


def test_looks_recoveries_and_steps_without_a_goal_have_their_parts() -> None:
    grid, geo = _room()
    goal = (3.0, 1.0)
    legs = [
        (DriveIntent(goal, "goal"), _line((0.6, 1.0), (1.0, 1.0), 4)),
        (DriveIntent(goal, "recovery"), _line((1.0, 1.0), (0.8, 1.0), 2)),
        (DriveIntent(goal, "goal"), _line((0.8, 1.0), (3.0, 1.0), 22)),
        (DriveIntent((1.0, 3.0), "look"), _line((3.0, 1.0), (3.0, 1.5), 5)),
        (None, _line((3.0, 1.5), (3.0, 2.0), 5)),
    ]
    parts, path = _drive(grid, geo, (0.6, 1.0), legs)
    p = parts.parts_m
    assert p["path_looks_recoveries_m"] == pytest.approx(0.2 + 0.5)
    assert p["path_without_goal_m"] == pytest.approx(0.5)
    assert p["path_to_cleared_goals_m"] == pytest.approx(0.4 + 2.2)
    # A recovery toward the same goal does not end it: one goal, driven 2.8 m for 2.4 m.
    assert len(parts.goals) == 1 and parts.goals[0].driven_m == pytest.approx(2.8)
    assert parts.path_length_m == pytest.approx(path, abs=1e-9)


def test_detour_ratio_is_one_for_a_straight_drive_and_more_for_a_detour() -> None:
    corridor, geo = _room(size_m=4.0)
    corridor[: round(1.2 / RES), :] = OCCUPIED
    corridor[round(2.0 / RES) :, :] = OCCUPIED  # an empty corridor: FREE for 1.2 m < y < 2.0 m
    legs = [(DriveIntent((3.5, 1.6)), _line((0.5, 1.6), (3.5, 1.6), 30))]
    straight, _ = _drive(corridor, geo, (0.5, 1.6), legs)
    assert straight.columns()["median_goal_detour_ratio"] == pytest.approx(1.0, abs=0.03)
    # In an open room, out to (2, 2.5) and back down to (3, 1): 3.61 m for a 2 m shortest path.
    room, _ = _room(size_m=4.0)
    via = _line((1.0, 1.0), (2.0, 2.5), 15) + _line((2.0, 2.5), (3.0, 1.0), 15)
    detour, path = _drive(room, geo, (1.0, 1.0), [(DriveIntent((3.0, 1.0)), via)])
    assert detour.columns()["median_goal_detour_ratio"] == pytest.approx(path / 2.0, rel=0.03)
    assert detour.columns()["goal_detour_excess_m"] == pytest.approx(path - 2.0, abs=0.06)


@pytest.mark.parametrize("spec", ["semantic", "nearest", "frontier", "oracle", "random"])
def test_the_parts_add_up_to_the_path_for_every_kind_of_policy(spec: str) -> None:
    if spec == "oracle":
        pytest.importorskip("elkai")
    policy = make_policy(spec)
    env = gym.make(
        "SemanticExplore-v0",
        world="maze:seed=3,size_m=5",
        overrides=["episode.random_start=true"],
        **map_observation_for(policy),
    )
    try:
        res = run_mission(env, policy, seed=1, max_time_s=25.0, ignore_terminated=True)
    finally:
        env.close()
    parts = res.path_decomposition
    assert parts is not None and res.path_length_m > 0.5
    assert sum(parts.parts_m.values()) == pytest.approx(res.path_length_m, abs=1e-6)
    assert all(v >= -1e-9 for v in parts.parts_m.values())
    if spec == "random":  # says nothing: all of its path is without a goal (or the tail)
        assert parts.parts_m["path_to_cleared_goals_m"] == 0.0 and not parts.goals
    else:
        assert parts.goals


@pytest.mark.slow
def test_the_benchmark_writes_the_decomposition_columns(tmp_path) -> None:
    from semexplore_gym.cli import main
    from semexplore_gym.evaluation.harness import read_runs

    out = tmp_path / "bench"
    argv = [
        "benchmark",
        "--worlds",
        "maze:seed=3,size_m=5",
        "--policies",
        "nearest,frontier",
        "--runs",
        "1",
        "--max-time-s",
        "20",
        "--out",
        str(out),
        "--no-progress",
        "--no-plots",
        "--no-oracle",
    ]
    assert main(argv) == 0
    header = (out / "runs.csv").read_text().splitlines()[0].split(",")
    assert set(DECOMPOSITION_COLUMNS) <= set(header)
    for r in read_runs(out / "runs.csv"):
        total = sum(r[k] for k in PART_COLUMNS)
        assert total == pytest.approx(r["path_length_m"], abs=0.01)  # cells rounded to mm
    summary = (out / "summary.md").read_text()
    assert "## Path decomposition" in summary and "to abandoned goals" in summary


def test_a_frontier_point_goal_is_cleared_once_it_is_seen() -> None:
    """Nearest frontier's targets are frontier cells: seeing the cell serves the goal, though
    the frontier (and most unknown round it) goes on."""
    grid, geo = _room()
    grid[40:79, 41:79] = UNKNOWN  # unknown from x = 2.05 m on
    goal = geo.grid_to_world(60, 40)  # a FREE cell next to the unknown
    info0 = {"map_geometry": geo.to_dict(), "robot": {"radius_m": 0.2}, "explored_area_m2": 0.0}
    pose = np.array([0.6, 3.0, 0.0])
    ledger = PathLedger.for_mission({"pose": pose, "map": grid}, info0)
    for i, p in enumerate(_line((0.6, 3.0), (1.0, 3.0), 4)):
        ledger.before_step(
            DriveIntent((float(goal[0]), float(goal[1]))), {"pose": pose, "map": grid}
        )
        if i == 2:
            grid[58:63, 41:43] = FREE  # the target's unknown neighbours are seen
        pose = np.array([*p, 0.0])
        ledger.after_step(
            {"pose": pose, "map": grid}, {"path_length_m": 0.1 * (i + 1), "explored_area_m2": i}
        )
    ledger.before_step(DriveIntent((0.5, 0.5)), {"pose": pose, "map": grid})
    parts = ledger.finish()
    first = parts.goals[0]
    assert first.frontier_point and first.cleared and not first.reached


def test_resuming_a_run_from_before_the_columns_adds_them(tmp_path) -> None:
    import csv

    from semexplore_gym.evaluation.run_row import CSV_COLUMNS, read_runs
    from semexplore_gym.evaluation.run_writer import ResultWriter

    old = [c for c in CSV_COLUMNS if c not in DECOMPOSITION_COLUMNS]
    row = dict.fromkeys(old, "1")
    row.update(world="maze1", policy="nearest", self_stopped="True", stop_reason="done")
    row.update({k: "False" for k in ("slam_lost", "slam_false_stop") if k in row})  # bool columns
    with (tmp_path / "runs.csv").open("w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=old)
        w.writeheader()
        w.writerow(row)
    ResultWriter(tmp_path).close()
    with (tmp_path / "runs.csv").open(newline="") as f:
        assert tuple(next(csv.reader(f))) == CSV_COLUMNS
    (parsed,) = read_runs(tmp_path / "runs.csv")
    assert parsed["path_length_m"] == 1.0 and parsed["path_to_cleared_goals_m"] is None
