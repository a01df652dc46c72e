"""Every frontier a disc robot can drive to, each with its nearest goal cell and path.

The grid fallback (:func:`~semexplore_gym.core.frontiers.reachable.nearest_reachable_frontier`)
stops at the first goal its search settles. A learned chooser needs all of them: this runs the
same search (same usable cells, step cost, frontier groups and filters) to the end, from the
robot over every usable cell, and returns one option per kept frontier group that a goal cell
serves: a usable cell within ``reach_m`` of the group (each such cell serves the group of the
frontier cell nearest it), the cheapest one by path cost.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
from scipy import ndimage

from semexplore_gym.core.frontiers.reachable import (
    FrontierFilter,
    StepCost,
    checked_search_inputs,
    clearance_field_m,
    drop_excluded,
    frontier_groups,
    known_window,
    search_start_cell,
    step_cost_field,
    usable_cells,
)
from semexplore_gym.core.grid import GridGeometry
from semexplore_gym.core.planning.grid_search import distance_field

__all__ = ["FrontierOptions", "reachable_frontier_options"]

_ALL_FRONTIERS = FrontierFilter()
_STEP_COST = StepCost()


@dataclass(frozen=True)
class FrontierOptions:
    """The reachable frontiers from one pose (``F`` of them, nearest by path cost first).

    Attributes:
        goal_xy_m: ``(F, 2)`` the goal cell of each (a usable cell next to its frontier).
        path_cost_m: ``(F,)`` search cost to the goal (metres, with the step cost's wall
            penalty; the plain length of the path is at most this).
        frontier_xy_m: ``(F, 2)`` centroid of each frontier group.
        frontier_cells: Each group's ``(K, 2)`` ``(row, col)`` cells of the full grid.
        start_xy_m: Where the paths start (the robot's position).
    """

    goal_xy_m: np.ndarray
    path_cost_m: np.ndarray
    frontier_xy_m: np.ndarray
    frontier_cells: tuple[np.ndarray, ...]
    start_xy_m: tuple[float, float]
    _parent: np.ndarray
    _cost: np.ndarray
    _goal_flat: np.ndarray
    _window: tuple[int, int, int, int]
    _geometry: GridGeometry

    def __len__(self) -> int:
        return len(self.path_cost_m)

    def pairwise_path_cost_m(self, first: int | None = None) -> np.ndarray:
        """``(n, n)`` path costs between the goals of the ``first`` nearest options (default:
        all), by the same search (symmetrised: the smaller of the two directions)."""
        n = len(self) if first is None else min(int(first), len(self))
        out = np.zeros((n, n))
        w = self._cost.shape[1]
        goals = self._goal_flat[:n]
        rows, cols = goals // w, goals % w
        for i in range(n):
            d, _ = distance_field(self._cost, (int(rows[i]), int(cols[i])))
            out[i] = d[rows, cols]
        out = np.minimum(out, out.T) * self._geometry.resolution_m
        np.fill_diagonal(out, 0.0)
        return out

    def path_m(self, i: int) -> np.ndarray:
        """``(K, 2)`` polyline from :attr:`start_xy_m` through cell centres to option ``i``'s goal."""
        r0, _, c0, c1 = self._window
        w = c1 - c0
        cells = []
        k = int(self._goal_flat[i])
        while k >= 0:
            cells.append(k)
            k = int(self._parent[k])
        idx = np.asarray(cells[::-1])
        xs, ys = self._geometry.grid_to_world(idx // w + r0, idx % w + c0)
        start = np.asarray(self.start_xy_m, dtype=np.float64)[None, :]
        return np.vstack([start, np.column_stack([xs, ys])])


def reachable_frontier_options(
    grid: npt.ArrayLike,
    geometry: GridGeometry,
    start_xy_m: tuple[float, float],
    clearance_m: float,
    frontiers: FrontierFilter = _ALL_FRONTIERS,
    clearance_field: np.ndarray | None = None,
    step_cost: StepCost = _STEP_COST,
) -> FrontierOptions:
    """Every kept frontier group a usable path reaches from ``start_xy_m`` (see the module).

    The arguments are those of
    :func:`~semexplore_gym.core.frontiers.reachable.nearest_reachable_frontier`; the nearest
    option's goal is that search's goal or a cell beside it (the two searches break ties in
    path cost differently).

    Raises:
        ValueError: on a malformed grid, a shape mismatch or negative distances.
    """
    g = checked_search_inputs(grid, geometry, clearance_m, frontiers)
    f = frontiers
    res = geometry.resolution_m
    start = (float(start_xy_m[0]), float(start_xy_m[1]))
    margin = int(math.ceil(0.5 / res)) + int(math.ceil(f.reach_m / res)) + 2
    window = known_window(g, geometry, start, margin)
    r0, r1, c0, c1 = window
    empty = _empty(start, window, geometry)
    if r0 >= r1 or c0 >= c1:
        return empty
    gw = np.ascontiguousarray(g[r0:r1, c0:c1])
    labels, n = frontier_groups(gw, f.min_frontier_cells, f.min_unknown_depth_cells)
    if n == 0 or (len(f.excluded_xy_m) and not drop_excluded(labels, geometry, f, (r0, c0))):
        return empty
    dist = (
        np.ascontiguousarray(clearance_field[r0:r1, c0:c1])
        if clearance_field is not None
        else clearance_field_m(gw, res)
    )
    usable = usable_cells(gw, dist, clearance_m)
    cell = search_start_cell(gw, geometry, usable, start, (r0, c0))
    if cell is None:
        return empty
    cost = step_cost_field(dist, usable, clearance_m, step_cost.wall_cost, step_cost.prefer_extra_m)
    cost = np.where(usable, cost, np.inf)
    d, parent = distance_field(cost, cell)
    best = _best_goal_per_group(d, labels, usable, f.reach_m / res)
    if best is None:
        return empty
    best_flat, best_grp, best_d = best
    w = c1 - c0
    gx, gy = geometry.grid_to_world(best_flat // w + r0, best_flat % w + c0)
    fr, fc = np.nonzero(labels)
    lab = labels[fr, fc]
    cells = tuple(np.column_stack([fr[lab == k] + r0, fc[lab == k] + c0]) for k in best_grp)
    cx, cy = geometry.grid_to_world(
        np.array([c[:, 0].mean() for c in cells]), np.array([c[:, 1].mean() for c in cells])
    )
    return FrontierOptions(
        goal_xy_m=np.column_stack([gx, gy]).astype(np.float64),
        path_cost_m=best_d.astype(np.float64) * res,  # the search counts cells
        frontier_xy_m=np.column_stack([cx, cy]).astype(np.float64),
        frontier_cells=cells,
        start_xy_m=start,
        _parent=parent.reshape(-1),
        _cost=cost,
        _goal_flat=best_flat,
        _window=window,
        _geometry=geometry,
    )


def _best_goal_per_group(
    d: np.ndarray, labels: np.ndarray, usable: np.ndarray, reach_cells: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """Per frontier group its cheapest goal cell (flat index), the group's label and the path
    cost (in cells), cheapest group first; None when no goal cell is reached."""
    # Each cell serves the group of the frontier cell nearest it (within reach).
    to_frontier, (ir, ic) = ndimage.distance_transform_edt(labels == 0, return_indices=True)
    served = labels[ir, ic]
    goal = usable & np.isfinite(d) & (to_frontier <= reach_cells + 1e-9) & (served > 0)
    flat = np.flatnonzero(goal)
    if len(flat) == 0:
        return None
    grp = served.reshape(-1)[flat]
    order = np.lexsort((flat, d.reshape(-1)[flat], grp))  # per group, cheapest (then lowest) first
    first = order[np.r_[True, grp[order][1:] != grp[order][:-1]]]
    best_flat, best_grp = flat[first], grp[first]
    best_d = d.reshape(-1)[best_flat]
    by_cost = np.lexsort((best_flat, best_d))
    return best_flat[by_cost], best_grp[by_cost], best_d[by_cost]


def _empty(
    start: tuple[float, float], window: tuple[int, int, int, int], geometry: GridGeometry
) -> FrontierOptions:
    z2 = np.zeros((0, 2))
    none = np.zeros(0, np.int64)
    return FrontierOptions(
        z2, np.zeros(0), z2, (), start, none, np.zeros((0, 0)), none, window, geometry
    )
