"""What the semantic expert's plan sources share: the :class:`PlanContext` of one replan, the
:class:`PlanSource` interface, and the helpers several sources use (see
:mod:`semexplore_gym.policies.expert.plan_sources` for the sources and their order)."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from semexplore_gym.policies.expert.counters import ExpertCounters
from semexplore_gym.policies.expert.goal_memory import GoalMemory
from semexplore_gym.policies.expert.params import SemanticExpertParams
from semexplore_gym.policies.expert.plan import Plan

from semexplore_gym.core.frontiers.detection import frontier_cell_mask
from semexplore_gym.core.frontiers.options import FrontierOptions, reachable_frontier_options
from semexplore_gym.core.frontiers.reachable import (
    FrontierFilter,
    ReachableFrontier,
    clearance_field_m,
    grid_path_to,
    known_free_clearance_m,
    nearest_reachable_frontier,
)
from semexplore_gym.core.grid import UNKNOWN, GridGeometry
from semexplore_gym.core.planning.graph_search import FrontierCandidate
from semexplore_gym.core.planning.potential_field import resample_polyline

__all__ = [
    "PlanContext",
    "PlanSource",
    "frontier_near",
    "goal_open",
    "path_clearance_along",
    "standable_prefix",
    "unknown_near",
]


def _box_cells(
    geometry: GridGeometry, xy: tuple[float, float], radius_m: float, rim: int
) -> tuple[int, int, int, int] | None:
    """Rows and columns ``(r0, c0, r1, c1)`` of the box of half-size ``radius_m`` round ``xy``;
    None when the box, widened by ``rim`` cells, reaches past the map's edge."""
    g = geometry
    # g.world_to_grid's arithmetic on scalars (called every step: no arrays)
    ox, oy, res = g.origin_x_m, g.origin_y_m, g.resolution_m
    c0 = math.floor((float(xy[0] - radius_m) - ox) / res)
    r0 = math.floor((float(xy[1] - radius_m) - oy) / res)
    c1 = math.floor((float(xy[0] + radius_m) - ox) / res)
    r1 = math.floor((float(xy[1] + radius_m) - oy) / res)
    if r0 < rim or c0 < rim or r1 >= g.height - rim or c1 >= g.width - rim:
        return None
    return r0, c0, r1, c1


def unknown_near(
    grid: np.ndarray, geometry: GridGeometry, xy: tuple[float, float], radius_m: float
) -> bool:
    """Whether an UNKNOWN cell lies in the box of half-size ``radius_m`` round ``xy`` (or the
    box reaches past the map's edge, beyond which all is unknown)."""
    box = _box_cells(geometry, xy, radius_m, 0)
    if box is None:
        return True
    r0, c0, r1, c1 = box
    return bool((grid[r0 : r1 + 1, c0 : c1 + 1] == UNKNOWN).any())


def frontier_near(
    grid: np.ndarray, geometry: GridGeometry, xy: tuple[float, float], radius_m: float
) -> bool:
    """Whether a frontier cell (UNKNOWN with a FREE 4-neighbour) lies in the box of half-size
    ``radius_m`` round ``xy`` (or the box reaches past the map's edge)."""
    box = _box_cells(geometry, xy, radius_m, 1)
    if box is None:
        return True
    r0, c0, r1, c1 = box
    # the box with a rim of one cell, so that its edge cells see all four neighbours
    window = grid[r0 - 1 : r1 + 2, c0 - 1 : c1 + 2]
    return bool(frontier_cell_mask(window)[1:-1, 1:-1].any())


def goal_open(
    grid: np.ndarray,
    geometry: GridGeometry,
    xy: tuple[float, float],
    radius_m: float,
    *,
    on_frontier: bool,
) -> bool:
    """Whether the frontier a goal at ``xy`` serves is still there: a frontier cell (with
    ``on_frontier``, the goal rule ``vanish_on_frontier``; else any UNKNOWN cell) within
    ``radius_m`` (``goal_check_radius_m``) of it."""
    near = frontier_near if on_frontier else unknown_near
    return near(grid, geometry, xy, radius_m)


@dataclass
class PlanContext:
    """What a plan source may read at one replan (built by the expert for each replan).

    Attributes:
        grid: The observed map.
        pose: The robot's ``(x_m, y_m, yaw_rad)``.
        geometry: The map's frame.
        params: The expert's parameters.
        clearance_m: The planners' clearance (robot radius plus ``clearance_margin_m``).
        robot_radius_m: The robot's radius.
        candidates: Algorithm 1's scored, non-blacklisted frontiers, cheapest ``C`` first.
        current: The plan followed so far (None: none).
        memory: The expert's goal memory (drops, retries, the commanded goal, the trail).
        counts: The expert's counters.
        choose_goal: The expert's goal choice among ``candidates``.
        log: Records an event ``(name, detail)`` in the expert's event log.
        lidar_range_m: The LiDAR's ``(min_range_m, max_range_m)``.
        time_s: The expert's clock at this replan (seconds).
    """

    grid: np.ndarray
    pose: tuple[float, float, float]
    geometry: GridGeometry
    params: SemanticExpertParams
    clearance_m: float
    robot_radius_m: float
    candidates: list[FrontierCandidate]
    current: Plan | None
    memory: GoalMemory
    counts: ExpertCounters
    choose_goal: Callable[[list[FrontierCandidate]], FrontierCandidate]
    log: Callable[[str, str], None]
    lidar_range_m: tuple[float, float] = (0.0, 3.5)
    time_s: float = 0.0
    clearance_cache: np.ndarray | None = field(default=None, repr=False)
    known_clearance_cache: np.ndarray | None = field(default=None, repr=False)

    @property
    def xy_m(self) -> tuple[float, float]:
        """The robot's position."""
        return (self.pose[0], self.pose[1])

    def clearance_field(self) -> np.ndarray:
        """The grid's clearance field (computed once per replan, on first use)."""
        if self.clearance_cache is None:
            self.clearance_cache = clearance_field_m(self.grid, self.geometry.resolution_m)
        return self.clearance_cache

    def known_clearance_field(self) -> np.ndarray:
        """Clearance to the nearest cell not mapped FREE (unseen walls count), once per replan:
        what a passage narrower than the planners' clearance is measured with."""
        if self.known_clearance_cache is None:
            self.known_clearance_cache = known_free_clearance_m(
                self.grid, self.geometry.resolution_m
            )
        return self.known_clearance_cache

    def nearest_grid_frontier(self) -> ReachableFrontier | None:
        """The nearest frontier the grid fallback's search reaches from the robot (its filters,
        the goal memory's drops). The whole map's clearance field is used only when a source
        already computed it this replan: the search computes the same values within the window
        of the known cells, much cheaper on a large map."""
        return nearest_reachable_frontier(
            self.grid,
            self.geometry,
            self.xy_m,
            self.clearance_m,
            frontiers=self.fallback_filter(),
            clearance_field=self.clearance_cache,
        )

    def frontier_beyond(self, way_m: np.ndarray) -> ReachableFrontier | None:
        """The nearest frontier the grid fallback's search reaches (at the planners'
        clearance) from the end of ``way_m``, a way out of where the robot stands (a pocket,
        through a gap): the second leg of such a plan."""
        return nearest_reachable_frontier(
            self.grid,
            self.geometry,
            (float(way_m[-1, 0]), float(way_m[-1, 1])),
            self.clearance_m,
            frontiers=self.fallback_filter(),
            clearance_field=self.clearance_field(),
        )

    def resampled(self, path_m: np.ndarray) -> np.ndarray:
        """``path_m`` resampled at the map's resolution (what the path follower expects)."""
        return resample_polyline(path_m, self.geometry.resolution_m)

    def grid_frontier_options(self) -> FrontierOptions:
        """Every frontier the grid fallback's search reaches from the robot (its filters, the
        goal memory's drops), each with its goal and path (the frontier student's options)."""
        return reachable_frontier_options(
            self.grid,
            self.geometry,
            self.xy_m,
            self.clearance_m,
            frontiers=self.fallback_filter(),
            clearance_field=self.clearance_cache,
        )

    def grid_route(self, goal_xy_m: tuple[float, float]) -> np.ndarray | None:
        """A clearance-aware grid path from the robot to ``goal_xy_m`` (None: none). As for
        :meth:`nearest_grid_frontier`, the whole map's clearance field is used only when a
        source already computed it this replan; else the search computes it within the known
        cells' window (the same values)."""
        return grid_path_to(
            self.grid,
            self.geometry,
            self.xy_m,
            goal_xy_m,
            self.clearance_m,
            clearance_field=self.clearance_cache,
        )

    def narrow_clearance_m(self) -> float:
        """The graded clearance's thinnest: the robot radius plus ``narrow_clearance_margin_m``."""
        return self.robot_radius_m + self.params.narrow_clearance_margin_m

    def narrow_route(self, goal_xy_m: tuple[float, float]) -> np.ndarray | None:
        """A grid path to ``goal_xy_m`` at :meth:`narrow_clearance_m` on the clearance to cells
        not mapped FREE (None: none)."""
        return grid_path_to(
            self.grid,
            self.geometry,
            self.xy_m,
            goal_xy_m,
            self.narrow_clearance_m(),
            clearance_field=self.known_clearance_field(),
        )

    def look_filter(self, min_frontier_cells: int) -> FrontierFilter:
        """Which frontiers the looks at narrow frontiers count: groups of at least
        ``min_frontier_cells`` with unknown space ``look_min_unknown_depth_m`` deep, not dropped."""
        prm = self.params
        return FrontierFilter(
            min_frontier_cells=min_frontier_cells,
            min_unknown_depth_cells=prm.look_min_unknown_depth_m / self.geometry.resolution_m,
            reach_m=prm.fallback_reach_m,
            excluded_xy_m=self.memory.dropped_points(),
            excluded_radius_m=prm.blacklist_radius_m,
        )

    def fallback_filter(self) -> FrontierFilter:
        """The grid fallback's :class:`FrontierFilter` (:meth:`fallback_search_kwargs`)."""
        return FrontierFilter(**self.fallback_search_kwargs())

    def fallback_search_kwargs(self) -> dict[str, Any]:
        """Which frontiers the grid fallback counts (the same for its every search)."""
        prm = self.params
        res_m = self.geometry.resolution_m
        return {
            "min_frontier_cells": max(1, math.ceil(prm.fallback_min_frontier_m / res_m - 1e-9)),
            "min_unknown_depth_cells": prm.fallback_min_unknown_depth_m / res_m,
            "reach_m": prm.fallback_reach_m,
            "excluded_xy_m": self.memory.dropped_points(),
            "excluded_radius_m": prm.blacklist_radius_m + prm.fallback_reach_m,
        }


class PlanSource:
    """One way to find the next plan: :meth:`propose` a plan, or pass with None.

    Subclasses set :attr:`name` (events and docs) and implement :meth:`propose`; they keep no
    state of their own (see the module docstring).
    """

    name: str = "source"

    def propose(self, ctx: PlanContext) -> Plan | None:
        """The plan this source offers at this replan, or None to pass to the next source."""
        raise NotImplementedError

    def __repr__(self) -> str:
        return f"{type(self).__name__}()"


def path_clearance_along(
    ctx: PlanContext, path_m: np.ndarray, clearance: np.ndarray | None = None
) -> np.ndarray:
    """The wall clearance (``clearance``, default the map's to OCCUPIED cells) at each point
    of ``path_m`` (``inf`` off the map)."""
    if clearance is None:
        clearance = ctx.clearance_field()
    rows, cols = ctx.geometry.world_to_grid(path_m[:, 0], path_m[:, 1])
    h, w = ctx.geometry.shape
    inside = (rows >= 0) & (rows < h) & (cols >= 0) & (cols < w)
    along = np.full(len(path_m), np.inf)
    along[inside] = clearance[rows[inside], cols[inside]]
    return along


def standable_prefix(
    ctx: PlanContext,
    path_m: np.ndarray,
    clearance_m: float | None = None,
    clearance_field: np.ndarray | None = None,
) -> np.ndarray:
    """The part of ``path_m`` from its start on which the robot's own clearance (or
    ``clearance_m``, on ``clearance_field``) holds."""
    need_m = ctx.clearance_m if clearance_m is None else clearance_m
    field_m = ctx.clearance_field() if clearance_field is None else clearance_field
    dense = ctx.resampled(path_m)
    rows, cols = ctx.geometry.world_to_grid(dense[:, 0], dense[:, 1])
    ok = field_m[rows, cols] >= need_m - 1e-9
    # The robot may start closer to a wall than its clearance: skip that first stretch.
    first = int(np.argmax(ok)) if ok.any() else len(ok)
    bad = np.flatnonzero(~ok[first:])
    return dense if len(bad) == 0 else dense[: first + int(bad[0])]
