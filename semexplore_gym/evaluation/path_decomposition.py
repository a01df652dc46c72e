"""Where a mission's path went: its length split into parts that add up to it, and each goal's
driven path against the shortest path at the robot's clearance.

Any policy: :func:`~semexplore_gym.evaluation.rollout.run_mission` keeps a :class:`PathLedger`
that records, every step, the path driven in it (the env's ``path_length_m`` increment) and
what the policy said it was doing (:meth:`Policy.drive_intent
<semexplore_gym.policies.base.Policy.drive_intent>`: a goal and a mode). At the end,
:meth:`PathLedger.finish` splits the path into (:data:`PART_COLUMNS`):

``path_after_last_new_cell_m``
    Everything driven after the last step that mapped new free area (the tail), whatever the
    policy was doing.
``path_looks_recoveries_m``
    Before the tail, steps whose mode is ``"look"`` or ``"recovery"``.
``path_to_cleared_goals_m``
    Before the tail, steps driving toward a goal that was *cleared*: the robot came within
    ``reach_m`` of it; or when the policy let it go at most ``cleared_fraction`` (half) of the
    UNKNOWN cells within ``clear_radius_m`` of it when it was set were still unknown (the
    frontier it served had been mapped; a goal whose frontier vanished has none left); or the
    goal was itself a frontier point (an UNKNOWN cell among its eight neighbours when set, as
    nearest frontier's targets are) and has been seen (no UNKNOWN neighbour left).
``path_to_abandoned_goals_m``
    Before the tail, steps driving toward a goal the policy dropped or switched away from,
    unreached, while most of the unknown round it still stood (a goal still open when the
    mission ends is judged the same way).
``path_without_goal_m``
    Before the tail, steps in which the policy reported no goal (waiting, or a policy that does
    not say: a learned agent's whole path is here).

A *goal* lasts while the reported goal stays within ``same_goal_m`` of the last one (goals
that drift as their frontier is mapped are one goal); a goal farther away, or none, ends it.
Look and recovery steps neither start nor continue a goal, but a recovery toward the same goal
does not end it.

Detour ratio: for each cleared goal, the path driven while it was the goal (recoveries and
escapes included) divided by the shortest path at the robot's clearance, on the mission's final
map, from where the robot was when the goal was set to where it was when the goal ended
(:func:`~semexplore_gym.core.planning.clearance_path.shortest_clear_path_m`; one A* per goal).
Goals whose shortest path is under ``min_detour_base_m`` are left out (a few centimetres of
wobble would dominate). ``median_goal_detour_ratio`` is their median, ``goal_detour_excess_m``
the sum of driven minus shortest over them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from semexplore_gym.core.grid import UNKNOWN, GridGeometry
from semexplore_gym.core.planning.clearance_path import clear_cells, shortest_clear_path_m
from semexplore_gym.policies.base import LOOK_RECOVERY_MODES, DriveIntent

__all__ = [
    "DECOMPOSITION_COLUMNS",
    "PART_COLUMNS",
    "GoalRecord",
    "LedgerParams",
    "PathDecomposition",
    "PathLedger",
    "decomposition_table",
]

#: The parts of the path, in metres; they add up to ``path_length_m``.
PART_COLUMNS: tuple[str, ...] = (
    "path_to_cleared_goals_m",
    "path_to_abandoned_goals_m",
    "path_looks_recoveries_m",
    "path_without_goal_m",
    "path_after_last_new_cell_m",
)

#: Every column the decomposition adds to ``runs.csv``.
DECOMPOSITION_COLUMNS: tuple[str, ...] = (
    *PART_COLUMNS,
    "goals_cleared",
    "goals_abandoned",
    "median_goal_detour_ratio",
    "goal_detour_excess_m",
)

# Per-step labels besides a goal's index.
_LOOK_RECOVERY = -1
_NO_GOAL = -2


@dataclass(frozen=True)
class LedgerParams:
    """How the ledger tells goals apart and judges them (metres).

    Attributes:
        same_goal_m: A reported goal within this of the last one is the same goal (the
            expert's commitment radius and frontier_exploration's goal aliasing).
        reach_m: A goal the robot came this close to was reached.
        clear_radius_m: The neighbourhood of a goal whose UNKNOWN cells are counted when it is
            set and when it ends (the expert's goal check radius).
        cleared_fraction: A goal that ended with at most this share of those cells still
            UNKNOWN was cleared.
        min_detour_base_m: Goals whose shortest path is shorter get no detour ratio.
    """

    same_goal_m: float = 1.0
    reach_m: float = 0.5
    clear_radius_m: float = 0.5
    cleared_fraction: float = 0.5
    min_detour_base_m: float = 1.0


@dataclass
class GoalRecord:
    """One goal of a mission: where and when it began and ended, and how.

    Attributes:
        goal_xy_m: The goal as last reported.
        start_xy_m: The robot's position when the goal was set.
        end_xy_m: The robot's position when it ended (None while open).
        first_step: Index of its first step.
        last_step: Index of its last step (inclusive).
        reached: The robot came within ``reach_m`` of it.
        cleared: Reached, or the unknown round it had been mapped when it ended.
        unknown_cells: UNKNOWN cells within ``clear_radius_m`` of it when it was set.
        frontier_point: It was itself a frontier point when set (an UNKNOWN neighbour).
        driven_m: Path driven while it was the goal (every step from first to last).
        shortest_m: Shortest path at the robot's clearance from start to end (None: none).
    """

    goal_xy_m: tuple[float, float]
    start_xy_m: tuple[float, float]
    first_step: int
    last_step: int
    end_xy_m: tuple[float, float] | None = None
    reached: bool = False
    cleared: bool = False
    driven_m: float = 0.0
    shortest_m: float | None = None
    unknown_cells: int = 0
    frontier_point: bool = False

    @property
    def detour_ratio(self) -> float | None:
        """``driven_m / shortest_m`` (None without a shortest path)."""
        if self.shortest_m is None or self.shortest_m <= 0:
            return None
        return self.driven_m / self.shortest_m


@dataclass
class PathDecomposition:
    """The split of one mission's path (see the module docstring).

    Attributes:
        parts_m: Part name (:data:`PART_COLUMNS`) -> metres; they add up to the path length.
        goals: Every goal of the mission, in order.
        tail_start_step: Index of the first step of the tail.
        min_detour_base_m: Goals whose shortest path is shorter get no detour ratio.
    """

    parts_m: dict[str, float]
    goals: list[GoalRecord] = field(default_factory=list)
    tail_start_step: int = 0
    min_detour_base_m: float = 1.0

    @property
    def path_length_m(self) -> float:
        return float(sum(self.parts_m.values()))

    def measured_goals(self) -> list[GoalRecord]:
        """The cleared goals with a shortest path of at least ``min_detour_base_m``."""
        return [
            g
            for g in self.goals
            if g.cleared and g.shortest_m is not None and g.shortest_m >= self.min_detour_base_m
        ]

    def detour_ratios(self) -> list[float]:
        """Detour ratios of :meth:`measured_goals`."""
        return [g.driven_m / g.shortest_m for g in self.measured_goals() if g.shortest_m]

    def columns(self) -> dict[str, Any]:
        """The ``runs.csv`` cells (:data:`DECOMPOSITION_COLUMNS`)."""
        ratios = self.detour_ratios()
        excess = [g.driven_m - (g.shortest_m or 0.0) for g in self.measured_goals()]
        out: dict[str, Any] = {k: round(self.parts_m[k], 3) for k in PART_COLUMNS}
        out["goals_cleared"] = sum(1 for g in self.goals if g.cleared)
        out["goals_abandoned"] = sum(1 for g in self.goals if not g.cleared)
        out["median_goal_detour_ratio"] = round(float(np.median(ratios)), 4) if ratios else None
        out["goal_detour_excess_m"] = round(float(sum(excess)), 3) if excess else None
        return out


class PathLedger:
    """Step-by-step bookkeeping of a mission for :class:`PathDecomposition`.

    Call :meth:`before_step` after the policy's ``act`` (with its
    :meth:`~semexplore_gym.policies.base.Policy.drive_intent`, the position and the map the
    policy saw), :meth:`after_step` after each env step, and :meth:`finish` once at the end.

    Args:
        geometry: Frame of the map observation.
        robot_radius_m: The clearance of the shortest paths.
        path_length_m: The env's ``path_length_m`` after reset.
        explored_area_m2: The env's ``explored_area_m2`` after reset.
        params: Thresholds (:class:`LedgerParams`).
    """

    def __init__(
        self,
        geometry: GridGeometry,
        robot_radius_m: float,
        path_length_m: float = 0.0,
        explored_area_m2: float = 0.0,
        params: LedgerParams | None = None,
    ) -> None:
        self.geometry = geometry
        self.robot_radius_m = float(robot_radius_m)
        self.params = params if params is not None else LedgerParams()
        self._path0 = self._path = float(path_length_m)
        self._areas = [float(explored_area_m2)]
        self._increments: list[float] = []
        self._labels: list[int] = []
        self.goals: list[GoalRecord] = []
        self._open: GoalRecord | None = None
        self._xy_m: tuple[float, float] | None = None
        self._grid: np.ndarray | None = None

    @classmethod
    def for_mission(cls, obs: dict[str, Any], info: dict[str, Any]) -> PathLedger:
        """A ledger for the mission that ``env.reset`` began with ``obs`` and ``info``."""
        ledger = cls(
            GridGeometry.from_dict(info["map_geometry"]),
            float(info["robot"]["radius_m"]),
            float(info.get("path_length_m", 0.0)),
            float(info.get("explored_area_m2", 0.0)),
        )
        ledger._seen(obs)
        return ledger

    def _seen(self, obs: dict[str, Any]) -> None:
        p = obs["pose"]
        self._xy_m = (float(p[0]), float(p[1]))
        self._grid = obs["map"]

    def before_step(self, intent: DriveIntent | None, obs: dict[str, Any]) -> None:
        """Label the coming step with the policy's ``intent`` (``obs``: what it acted on)."""
        self._seen(obs)
        xy = self._xy_m
        assert xy is not None
        step = len(self._labels)
        goal = None if intent is None else intent.goal_xy_m
        looking = intent is not None and intent.mode in LOOK_RECOVERY_MODES
        g = self._open
        if g is not None and (
            goal is None or math.dist(goal, g.goal_xy_m) > self.params.same_goal_m
        ):
            self._close(g)
            g = None
        if g is None and goal is not None and not looking:
            g = self._open = GoalRecord((goal[0], goal[1]), xy, step, step)
            g.unknown_cells = self._unknown_near(g.goal_xy_m)
            g.frontier_point = self._unknown_near(g.goal_xy_m, cells=1) > 0
            self.goals.append(g)
        if g is not None and goal is not None:
            g.goal_xy_m = (float(goal[0]), float(goal[1]))
            g.last_step = step
            g.reached |= math.dist(xy, g.goal_xy_m) <= self.params.reach_m
        if looking:
            self._labels.append(_LOOK_RECOVERY)
        elif g is not None:
            self._labels.append(len(self.goals) - 1)
        else:
            self._labels.append(_NO_GOAL)

    def after_step(self, obs: dict[str, Any], info: dict[str, Any]) -> None:
        """Record the path and free area of the step just taken."""
        if len(self._increments) >= len(self._labels):
            self._labels.append(_NO_GOAL)  # a step no before_step labelled
        path = float(info["path_length_m"])
        self._increments.append(path - self._path)
        self._path = path
        self._areas.append(float(info["explored_area_m2"]))
        self._seen(obs)
        g = self._open
        if g is not None and self._xy_m is not None:
            g.reached |= math.dist(self._xy_m, g.goal_xy_m) <= self.params.reach_m

    def _close(self, g: GoalRecord) -> None:
        g.end_xy_m = self._xy_m
        left = self._unknown_near(g.goal_xy_m)
        g.cleared = (
            g.reached
            or left <= self.params.cleared_fraction * g.unknown_cells
            or (g.frontier_point and self._unknown_near(g.goal_xy_m, cells=1) == 0)
        )
        self._open = None

    def _unknown_near(self, xy_m: tuple[float, float], cells: int = 0) -> int:
        """UNKNOWN cells within ``clear_radius_m`` of ``xy_m`` in the last map seen (within
        ``cells`` cells, its ``2 cells + 1`` square, when ``cells > 0``)."""
        grid = self._grid
        if grid is None:
            return 0
        geo = self.geometry
        r_a, c_a = geo.world_to_grid(xy_m[0], xy_m[1])
        r, c = int(r_a), int(c_a)
        k = cells if cells > 0 else int(math.ceil(self.params.clear_radius_m / geo.resolution_m))
        h, w = grid.shape
        r0, r1, c0, c1 = max(r - k, 0), min(r + k + 1, h), max(c - k, 0), min(c + k + 1, w)
        if r0 >= r1 or c0 >= c1:
            return 0
        rr, cc = np.mgrid[r0:r1, c0:c1]
        near = ((rr - r) ** 2 + (cc - c) ** 2 <= k * k) | (cells > 0)
        return int(np.count_nonzero(grid[r0:r1, c0:c1][near] == UNKNOWN))

    def tail_start_step(self) -> int:
        """Index of the first step after the last one that mapped new free area."""
        cell_m2 = self.geometry.resolution_m**2
        best, last = self._areas[0], 0
        for i, a in enumerate(self._areas[1:], start=1):
            if a > best + 0.5 * cell_m2:
                best, last = a, i
        return last

    def finish(self) -> PathDecomposition:
        """Close the open goal, split the path and measure the cleared goals' shortest paths."""
        if self._open is not None:
            self._close(self._open)
        n = len(self._increments)
        labels = self._labels[:n]
        tail = self.tail_start_step()
        parts = dict.fromkeys(PART_COLUMNS, 0.0)
        inc = np.asarray(self._increments, dtype=np.float64)
        for g in self.goals:
            g.driven_m = float(inc[g.first_step : g.last_step + 1].sum())
        for i in range(n):
            d = self._increments[i]
            if i >= tail:
                parts["path_after_last_new_cell_m"] += d
            elif labels[i] == _LOOK_RECOVERY:
                parts["path_looks_recoveries_m"] += d
            elif labels[i] == _NO_GOAL:
                parts["path_without_goal_m"] += d
            elif self.goals[labels[i]].cleared:
                parts["path_to_cleared_goals_m"] += d
            else:
                parts["path_to_abandoned_goals_m"] += d
        # The path before the first step (nothing, after a reset) has no goal.
        parts["path_without_goal_m"] += self._path0
        self._measure_detours()
        return PathDecomposition(parts, list(self.goals), tail, self.params.min_detour_base_m)

    def _measure_detours(self) -> None:
        measured = [g for g in self.goals if g.cleared and g.end_xy_m is not None]
        if self._grid is None or not measured:
            return
        mask = clear_cells(self._grid, self.geometry, self.robot_radius_m)
        snap_m = self.robot_radius_m + 2 * self.geometry.resolution_m
        for g in measured:
            if g.driven_m < self.params.min_detour_base_m:
                continue  # too short for a ratio: its shortest path is no longer
            assert g.end_xy_m is not None
            g.shortest_m = shortest_clear_path_m(
                mask, self.geometry, g.start_xy_m, g.end_xy_m, snap_m
            )


_TABLE_PARTS: tuple[tuple[str, str], ...] = (
    ("path_to_cleared_goals_m", "to cleared goals"),
    ("path_to_abandoned_goals_m", "to abandoned goals"),
    ("path_looks_recoveries_m", "looks + recoveries"),
    ("path_without_goal_m", "no goal"),
    ("path_after_last_new_cell_m", "after last new cell"),
)


def decomposition_table(families: dict[str, dict[str, list[dict[str, Any]]]]) -> list[str]:
    """``summary.md`` lines: per family and policy, the medians of the path's parts (metres, and
    in brackets the median share of each mission's path), goal counts and detour ratios.

    Args:
        families: ``{family: {policy: [runs.csv rows]}}``.

    Returns:
        The section's lines; none when no row has the decomposition's columns.
    """
    if not any(
        r.get("path_to_cleared_goals_m") is not None
        for by_policy in families.values()
        for rs in by_policy.values()
        for r in rs
    ):
        return []
    head = " | ".join(label for _, label in _TABLE_PARTS)
    lines = [
        "## Path decomposition",
        "",
        "Medians per family and policy of where the path went (metres; in brackets the median "
        "share of each mission's path). Medians of parts need not add up to the median path. "
        "Detour ratio: a cleared goal's driven path ÷ the shortest path at the robot's "
        "clearance (median over each mission's goals, then over missions); excess: driven "
        "minus shortest, summed over a mission's cleared goals.",
        "",
        f"| family | policy | n | path (m) | {head} | goals cleared | goals abandoned | "
        "detour ratio | detour excess (m) |",
        "|---|---|---:|---:|" + "---:|" * (len(_TABLE_PARTS) + 4),
    ]
    for fam, by_policy in families.items():
        for policy, rs in by_policy.items():
            rs = [r for r in rs if r.get("path_to_cleared_goals_m") is not None]
            if not rs:
                continue
            cells = [_median_cell(rs, "path_length_m", "{:.1f}")]
            for key, _ in _TABLE_PARTS:
                shares = [
                    r[key] / r["path_length_m"] for r in rs if (r.get("path_length_m") or 0) > 0
                ]
                share = f" ({100 * float(np.median(shares)):.0f} %)" if shares else ""
                cells.append(_median_cell(rs, key, "{:.1f}") + share)
            cells += [
                _median_cell(rs, "goals_cleared", "{:.0f}"),
                _median_cell(rs, "goals_abandoned", "{:.0f}"),
                _median_cell(rs, "median_goal_detour_ratio", "{:.2f}"),
                _median_cell(rs, "goal_detour_excess_m", "{:.1f}"),
            ]
            lines.append(f"| {fam} | {policy} | {len(rs)} | " + " | ".join(cells) + " |")
    lines.append("")
    return lines


def _median_cell(rows: list[dict[str, Any]], key: str, fmt: str) -> str:
    v = [float(r[key]) for r in rows if r.get(key) is not None and math.isfinite(float(r[key]))]
    return fmt.format(float(np.median(v))) if v else "–"
