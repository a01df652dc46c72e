"""Costmap inflation and grid search: a Navfn-like global planner and geodesic distance fields.

**Costmap** (like ROS ``costmap_2d`` with a static layer and an ``InflationLayer``): values are
uint8 with the ROS meanings

==================  =====  ===================================================================
name                value  meaning
==================  =====  ===================================================================
FREE_COST           0      free and farther than ``inflation_radius_m`` from any obstacle
(decay)             1-252  ``252 * exp(-cost_scaling_factor * (d - inscribed_radius_m))``
INSCRIBED_COST      253    the robot centre here would make the robot touch an obstacle
LETHAL_COST         254    an occupied cell
NO_INFORMATION      255    unknown (only with ``track_unknown_space``; else unknown is free)
==================  =====  ===================================================================

where ``d`` is the distance between cell centres to the nearest occupied cell (stamped round
each occupied cell out to the inflation radius, as ``costmap_2d`` does). As in ROS, unknown cells keep 255 unless they are
within the inscribed radius of an obstacle (then 253/254), or ``inflate_unknown`` is set.

**Navfn-like planner**: ROS ``navfn`` turns the costmap into per-cell traversal costs
``neutral_cost + cost_factor * cost`` (50 + 0.8 c), makes INSCRIBED and LETHAL impassable and
unknown cells passable at the highest cost (253) when ``allow_unknown``. It then propagates a
potential from the goal and descends its gradient. We keep the cost model and solve it exactly
with an 8-connected Dijkstra / A* (step lengths 1 and sqrt(2) times the cost of the entered
cell; no diagonal step between two impassable cells), so paths are the optimal 8-connected
paths of the same cost field rather than navfn's interpolated ones.

**Geodesic distance** (:func:`geodesic_distance_m`): a plain Dijkstra over a boolean mask with
unit cell cost, giving the 8-connected path length in metres from the robot to every cell; used
to pick the nearest frontier by path length (Yamauchi).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from semexplore_gym.core.grid import OCCUPIED, UNKNOWN, GridGeometry
from semexplore_gym.core.planning.grid_scan import checked_encoded_grid
from semexplore_gym.core.planning.grid_search_kernels import (
    backtrack_cells,
    search_cells,
    stamp_costs,
)

__all__ = [
    "FREE_COST",
    "INSCRIBED_COST",
    "LETHAL_COST",
    "NO_INFORMATION",
    "CostmapParams",
    "GridPath",
    "NavfnParams",
    "cells_near_occupied",
    "distance_field",
    "extract_path",
    "geodesic_distance_m",
    "inflate_costmap",
    "inflation_cost",
    "navfn_cell_costs",
    "plan_path",
    "shortest_path_cells",
]

FREE_COST: int = 0
INSCRIBED_COST: int = 253
LETHAL_COST: int = 254
NO_INFORMATION: int = 255


@dataclass(frozen=True)
class CostmapParams:
    """How an occupancy grid becomes a costmap (ROS ``costmap_2d`` inflation).

    Attributes:
        inscribed_radius_m: Robot radius; cells closer than this to an obstacle are INSCRIBED.
        inflation_radius_m: Costs decay to this distance; farther cells are FREE_COST.
        cost_scaling_factor: Exponential decay rate of the cost beyond the inscribed radius, 1/m
            (ROS default 10).
        track_unknown_space: Keep unknown cells as NO_INFORMATION (255); if False they are free.
        inflate_unknown: Let inflation raise unknown cells too (ROS ``inflate_unknown``).
    """

    inscribed_radius_m: float = 0.105
    inflation_radius_m: float = 0.2
    cost_scaling_factor: float = 10.0
    track_unknown_space: bool = True
    inflate_unknown: bool = False

    def __post_init__(self) -> None:
        if not (math.isfinite(self.inscribed_radius_m) and self.inscribed_radius_m >= 0):
            raise ValueError(f"inscribed_radius_m must be >= 0, got {self.inscribed_radius_m!r}")
        if not (
            math.isfinite(self.inflation_radius_m)
            and self.inflation_radius_m >= self.inscribed_radius_m
        ):
            raise ValueError(
                f"inflation_radius_m must be >= inscribed_radius_m ({self.inscribed_radius_m}), got {self.inflation_radius_m!r}"
            )
        if not (math.isfinite(self.cost_scaling_factor) and self.cost_scaling_factor >= 0):
            raise ValueError(f"cost_scaling_factor must be >= 0, got {self.cost_scaling_factor!r}")


@dataclass(frozen=True)
class NavfnParams:
    """Cost model of the Navfn-like planner.

    Attributes:
        neutral_cost: Cost of a free cell (navfn ``COST_NEUTRAL`` 50).
        cost_factor: Weight of the costmap value (navfn ``COST_FACTOR`` 0.8).
        allow_unknown: Plan through unknown cells (at cost 253), as navfn does by default.
        goal_tolerance_m: If the goal cell cannot be reached, accept the reachable cell nearest
            to it within this distance (navfn ``default_tolerance``, 0 = exact goal only).
        escape_radius_m: Inscribed (not lethal) cells within this distance of the start are
            passable, so a robot that grazed a wall can still plan its way out. ROS navfn clears
            only the robot's own cell (0 here) and leaves the rest to recovery behaviours.
        use_astar: Stop at the goal with an octile heuristic (same optimal path, less work).
    """

    neutral_cost: float = 50.0
    cost_factor: float = 0.8
    allow_unknown: bool = True
    goal_tolerance_m: float = 0.0
    escape_radius_m: float = 0.0
    use_astar: bool = True

    def __post_init__(self) -> None:
        if not (math.isfinite(self.neutral_cost) and self.neutral_cost > 0):
            raise ValueError(f"neutral_cost must be > 0, got {self.neutral_cost!r}")
        if not (math.isfinite(self.cost_factor) and self.cost_factor >= 0):
            raise ValueError(f"cost_factor must be >= 0, got {self.cost_factor!r}")
        if not (math.isfinite(self.goal_tolerance_m) and self.goal_tolerance_m >= 0):
            raise ValueError(f"goal_tolerance_m must be >= 0, got {self.goal_tolerance_m!r}")
        if not (math.isfinite(self.escape_radius_m) and self.escape_radius_m >= 0):
            raise ValueError(f"escape_radius_m must be >= 0, got {self.escape_radius_m!r}")


@dataclass(frozen=True)
class GridPath:
    """A planned path.

    Attributes:
        cells: ``(K, 2)`` int64 ``(row, col)`` from start to goal.
        points_m: ``(K, 2)`` float64 world ``(x, y)`` of the cell centres, except that the first
            point is the exact start position.
        length_m: Polyline length of ``points_m``.
        cost: Accumulated planner cost (sum of step length in cells times entered cell cost).
    """

    cells: np.ndarray
    points_m: np.ndarray
    length_m: float
    cost: float


def inflation_cost(distance_m: npt.ArrayLike, params: CostmapParams) -> np.ndarray:
    """ROS inflation cost (uint8) of cells at ``distance_m`` from the nearest obstacle cell."""
    d = np.asarray(distance_m, dtype=np.float64)
    factor = np.exp(-params.cost_scaling_factor * (d - params.inscribed_radius_m))
    decay = np.floor((INSCRIBED_COST - 1) * factor)
    cost = np.where(d <= params.inflation_radius_m, decay, FREE_COST)
    cost = np.where(d <= params.inscribed_radius_m, INSCRIBED_COST, cost)
    cost = np.where(d <= 0.0, LETHAL_COST, cost)
    return cost.astype(np.uint8)


def inflate_costmap(
    grid: npt.ArrayLike, resolution_m: float, params: CostmapParams = CostmapParams()
) -> np.ndarray:
    """Costmap (uint8, ROS values) of an encoded occupancy grid.

    Args:
        grid: Encoded occupancy grid ``(H, W)`` uint8.
        resolution_m: Cell size in metres.
        params: Inflation parameters.

    Returns:
        ``(H, W)`` uint8 costmap; see the module docstring for the values.
    """
    a = checked_encoded_grid(grid)
    if not (math.isfinite(resolution_m) and resolution_m > 0):
        raise ValueError(f"resolution_m must be a positive number, got {resolution_m!r}")
    # Distances matter only out to the inflation radius (beyond it the cost is 0), so stamp a
    # disc round each occupied cell, as costmap_2d does, instead of a full distance transform:
    # the work scales with the number of obstacle cells, not with the map.
    # The cost falls with distance, so the highest stamped cost is the cost of the nearest one.
    k = int(math.floor(params.inflation_radius_m / resolution_m + 1e-9))
    dr, dc = np.mgrid[-k : k + 1, -k : k + 1]
    d_m = np.hypot(dr, dc).ravel() * resolution_m
    disc = d_m <= params.inflation_radius_m + 1e-12
    stamp_cost = inflation_cost(d_m[disc], params)
    offsets = np.column_stack([dr.ravel()[disc], dc.ravel()[disc]]).astype(np.int64)
    occ_r, occ_c = np.nonzero(a == OCCUPIED)
    cost = stamp_costs(a.shape[0], a.shape[1], occ_r, occ_c, offsets, stamp_cost)
    if params.track_unknown_space:
        unknown = a == UNKNOWN
        # ROS keeps NO_INFORMATION unless inflation makes the cell (nearly) lethal.
        keep = unknown & (
            (cost == FREE_COST) if params.inflate_unknown else (cost < INSCRIBED_COST)
        )
        cost[keep] = NO_INFORMATION
    return cost


def cells_near_occupied(
    grid: npt.ArrayLike, cells: npt.ArrayLike, radius_m: float, resolution_m: float
) -> np.ndarray:
    """Which of ``cells`` lie within ``radius_m`` (centre to centre) of an OCCUPIED cell.

    A cheap local test (no distance transform of the whole grid), e.g. to notice that a planned
    path or a goal has become blocked after a map update.

    Args:
        grid: Encoded occupancy grid ``(H, W)``.
        cells: ``(K, 2)`` ``(row, col)``; cells outside the grid count as blocked.
        radius_m: Test radius (the inscribed radius for "the robot cannot stand here").
        resolution_m: Cell size.

    Returns:
        ``(K,)`` bool.
    """
    a = np.asarray(grid)
    rc = np.asarray(cells, dtype=np.int64).reshape(-1, 2)
    k = int(math.floor(radius_m / resolution_m + 1e-9))
    dr, dc = np.mgrid[-k : k + 1, -k : k + 1]
    disk = (dr**2 + dc**2) * resolution_m**2 <= radius_m**2 + 1e-12
    dr, dc = dr[disk], dc[disk]
    rr = rc[:, 0:1] + dr[None, :]
    cc = rc[:, 1:2] + dc[None, :]
    h, w = a.shape
    inside = (rr >= 0) & (rr < h) & (cc >= 0) & (cc < w)
    occ = np.zeros(rr.shape, dtype=bool)
    occ[inside] = a[rr[inside], cc[inside]] == OCCUPIED
    out = occ.any(axis=1)
    out |= ~((rc[:, 0] >= 0) & (rc[:, 0] < h) & (rc[:, 1] >= 0) & (rc[:, 1] < w))
    return out


def navfn_cell_costs(costmap: npt.ArrayLike, params: NavfnParams = NavfnParams()) -> np.ndarray:
    """Per-cell traversal cost for the planner (float64, ``inf`` = impassable)."""
    c = np.asarray(costmap)
    if c.ndim != 2 or c.dtype != np.uint8:
        raise TypeError(f"costmap must be a 2-D uint8 array, got dtype {c.dtype} shape {c.shape}")
    out = params.neutral_cost + params.cost_factor * c.astype(np.float64)
    out = np.minimum(out, float(INSCRIBED_COST))
    out[(c == INSCRIBED_COST) | (c == LETHAL_COST)] = np.inf
    out[c == NO_INFORMATION] = float(INSCRIBED_COST) if params.allow_unknown else np.inf
    return out


def plan_path(
    costmap: npt.ArrayLike,
    geometry: GridGeometry,
    start_xy_m: npt.ArrayLike,
    goal_xy_m: npt.ArrayLike,
    params: NavfnParams = NavfnParams(),
) -> GridPath | None:
    """Plan a path on a costmap like ROS navfn (see the module docstring).

    Args:
        costmap: ``(H, W)`` uint8 costmap from :func:`inflate_costmap`.
        geometry: Frame of the costmap.
        start_xy_m: Start ``(x, y)`` in metres (the robot).
        goal_xy_m: Goal ``(x, y)`` in metres.
        params: Planner parameters.

    Returns:
        The path, or ``None`` if start or goal lie outside the grid or the goal (within
        ``goal_tolerance_m``) cannot be reached.
    """
    c = np.asarray(costmap)
    if c.shape != geometry.shape:
        raise ValueError(f"costmap shape {c.shape} does not match geometry shape {geometry.shape}")
    sx, sy = _xy(start_xy_m, "start_xy_m")
    gx, gy = _xy(goal_xy_m, "goal_xy_m")
    sr, sc = (int(v) for v in geometry.world_to_grid(sx, sy))
    gr, gc = (int(v) for v in geometry.world_to_grid(gx, gy))
    if not (geometry.contains(sr, sc) and geometry.contains(gr, gc)):
        return None
    cost = navfn_cell_costs(c, params)
    _open_start(cost, c, sr, sc, params, geometry.resolution_m)
    res = geometry.resolution_m
    tol_cells = params.goal_tolerance_m / res
    if np.isfinite(cost[gr, gc]) or tol_cells <= 0:
        found = shortest_path_cells(cost, (sr, sc), (gr, gc), use_astar=params.use_astar)
        if found is None and tol_cells <= 0:
            return None
    else:
        found = None
    if found is None:
        dist, parent = distance_field(cost, (sr, sc))
        goal = _nearest_reached(dist, gr, gc, tol_cells)
        if goal is None:
            return None
        found = (extract_path(parent, goal), float(dist[goal]))
    cells, total = found
    xs, ys = geometry.grid_to_world(cells[:, 0], cells[:, 1])
    pts = np.column_stack([xs, ys])
    pts[0] = (sx, sy)
    length = float(np.hypot(*np.diff(pts, axis=0).T).sum()) if len(pts) > 1 else 0.0
    return GridPath(cells=cells, points_m=pts, length_m=length, cost=total)


def shortest_path_cells(
    cell_cost: npt.ArrayLike,
    start_rc: tuple[int, int],
    goal_rc: tuple[int, int],
    use_astar: bool = True,
) -> tuple[np.ndarray, float] | None:
    """Least-cost 8-connected path between two cells.

    Args:
        cell_cost: ``(H, W)`` float cost of entering each cell; ``inf`` (or NaN) = impassable.
            The start cell may be impassable (the robot is already there).
        start_rc: ``(row, col)`` start.
        goal_rc: ``(row, col)`` goal.
        use_astar: Use an octile heuristic scaled by the smallest finite cell cost.

    Returns:
        ``(cells (K, 2) int64 from start to goal, total cost)``, or ``None`` if unreachable.
    """
    cost = _cost_array(cell_cost)
    h, w = cost.shape
    (sr, sc), (gr, gc) = _rc(start_rc, cost.shape, "start_rc"), _rc(goal_rc, cost.shape, "goal_rc")
    if not np.isfinite(cost[gr, gc]) and (sr, sc) != (gr, gc):
        return None
    finite = cost[np.isfinite(cost)]
    h_weight = float(finite.min()) if (use_astar and finite.size) else 0.0
    dist = np.full(h * w, np.inf)
    parent = np.full(h * w, -1, dtype=np.int64)
    search_cells(cost, np.array([sr * w + sc], dtype=np.int64), gr * w + gc, h_weight, dist, parent)
    total = dist[gr * w + gc]
    if not np.isfinite(total):
        return None
    return extract_path(parent.reshape(h, w), (gr, gc)), float(total)


def distance_field(
    cell_cost: npt.ArrayLike,
    start_rc: tuple[int, int] | npt.ArrayLike,
    start_cost: npt.ArrayLike | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Dijkstra from one cell (or several) to all cells.

    Args:
        cell_cost: ``(H, W)`` float cost of entering each cell; ``inf``/NaN = impassable.
        start_rc: ``(row, col)`` source, or a ``(K, 2)`` array of sources (K >= 1). Sources may
            themselves be impassable.
        start_cost: Optional ``(K,)`` initial distances of the sources (default 0), e.g. the
            sub-cell distance from a point to the centres of the cells round it.

    Returns:
        ``(dist, parent)``: ``(H, W)`` float64 least cost (``inf`` unreachable) and ``(H, W)``
        int64 flat index of each cell's predecessor (-1 for sources and unreached cells).
    """
    cost = _cost_array(cell_cost)
    h, w = cost.shape
    src = np.asarray(start_rc)
    if src.ndim == 2:
        if src.shape[0] < 1 or src.shape[1] != 2:
            raise ValueError(
                f"start_rc must be (row, col) or a (K, 2) array, got shape {src.shape}"
            )
        rcs = [_rc(tuple(p), cost.shape, "start_rc") for p in src.tolist()]
    else:
        rcs = [_rc(start_rc, cost.shape, "start_rc")]  # type: ignore[arg-type]
    starts = np.array([r * w + c for r, c in rcs], dtype=np.int64)
    dist = np.full(h * w, np.inf)
    if start_cost is not None:
        sc = np.asarray(start_cost, dtype=np.float64).ravel()
        if sc.shape[0] != len(starts) or not (np.isfinite(sc).all() and (sc >= 0).all()):
            raise ValueError(
                f"start_cost must be {len(starts)} finite values >= 0, got {start_cost!r}"
            )
        # The smallest initial cost wins for a repeated source.
        order = np.argsort(-sc)
        dist[starts[order]] = sc[order]
    parent = np.full(h * w, -1, dtype=np.int64)
    search_cells(cost, starts, -1, 0.0, dist, parent)
    return dist.reshape(h, w), parent.reshape(h, w)


def geodesic_distance_m(
    traversable: npt.ArrayLike, geometry: GridGeometry, start_xy_m: npt.ArrayLike
) -> np.ndarray:
    """8-connected path length in metres from a point to every cell through ``traversable``.

    Args:
        traversable: ``(H, W)`` bool, True where a path may go. The start cell always counts as
            traversable.
        geometry: Frame of the mask.
        start_xy_m: Source ``(x, y)`` in metres; must lie inside the grid.

    Returns:
        ``(H, W)`` float64 distances, ``inf`` where unreachable.
    """
    m = np.asarray(traversable)
    if m.dtype != np.bool_ or m.shape != geometry.shape:
        raise ValueError(
            f"traversable must be a bool array of shape {geometry.shape}, got {m.dtype} {m.shape}"
        )
    sx, sy = _xy(start_xy_m, "start_xy_m")
    sr, sc = (int(v) for v in geometry.world_to_grid(sx, sy))
    if not geometry.contains(sr, sc):
        raise ValueError(f"start ({sx:.3f}, {sy:.3f}) m is outside the grid")
    cost = np.where(m, geometry.resolution_m, np.inf)
    dist, _ = distance_field(cost, (sr, sc))
    return dist


def extract_path(parent: np.ndarray, goal_rc: tuple[int, int]) -> np.ndarray:
    """Follow predecessor links back from ``goal_rc``; returns ``(K, 2)`` cells start-to-goal."""
    h, w = parent.shape
    cells = backtrack_cells(parent.ravel(), int(goal_rc[0]) * w + int(goal_rc[1]))
    return np.column_stack([cells // w, cells % w])


def _open_start(
    cost: np.ndarray, costmap: np.ndarray, sr: int, sc: int, params: NavfnParams, res: float
) -> None:
    # The robot's own cell is always passable (navfn's clearRobotCell).
    if not np.isfinite(cost[sr, sc]):
        cost[sr, sc] = float(INSCRIBED_COST)
    k = int(params.escape_radius_m / res)
    if k <= 0:
        return
    h, w = cost.shape
    r0, r1, c0, c1 = max(sr - k, 0), min(sr + k + 1, h), max(sc - k, 0), min(sc + k + 1, w)
    rr, cc = np.mgrid[r0:r1, c0:c1]
    near = (rr - sr) ** 2 + (cc - sc) ** 2 <= k * k
    win = costmap[r0:r1, c0:c1]
    sub = cost[r0:r1, c0:c1]
    sub[near & (win == INSCRIBED_COST)] = float(INSCRIBED_COST)


def _nearest_reached(
    dist: np.ndarray, gr: int, gc: int, tol_cells: float
) -> tuple[int, int] | None:
    if tol_cells <= 0:
        return (gr, gc) if np.isfinite(dist[gr, gc]) else None
    k = int(math.floor(tol_cells))
    h, w = dist.shape
    r0, r1, c0, c1 = max(gr - k, 0), min(gr + k + 1, h), max(gc - k, 0), min(gc + k + 1, w)
    rr, cc = np.mgrid[r0:r1, c0:c1]
    d2 = ((rr - gr) ** 2 + (cc - gc) ** 2).astype(np.float64)
    ok = np.isfinite(dist[r0:r1, c0:c1]) & (d2 <= tol_cells * tol_cells)
    if not ok.any():
        return None
    d2[~ok] = np.inf
    i = int(np.argmin(d2))
    return (int(rr.ravel()[i]), int(cc.ravel()[i]))


def _cost_array(cell_cost: npt.ArrayLike) -> np.ndarray:
    cost = np.asarray(cell_cost, dtype=np.float64)
    if cost.ndim != 2 or cost.size == 0:
        raise ValueError(f"cell_cost must be a non-empty 2-D array, got shape {cost.shape}")
    if (cost[np.isfinite(cost)] <= 0).any():
        raise ValueError("cell_cost must be > 0 wherever it is finite")
    cost = np.where(np.isnan(cost), np.inf, cost)
    return np.ascontiguousarray(cost)


def _rc(rc: tuple[int, int], shape: tuple[int, ...], name: str) -> tuple[int, int]:
    try:
        r, c = int(rc[0]), int(rc[1])
    except (TypeError, ValueError, IndexError):
        raise ValueError(f"{name} must be a (row, col) pair, got {rc!r}") from None
    if not (0 <= r < shape[0] and 0 <= c < shape[1]):
        raise ValueError(f"{name} {(r, c)} is outside the grid of shape {tuple(shape)}")
    return r, c


def _xy(p: npt.ArrayLike, name: str) -> tuple[float, float]:
    arr = np.asarray(p, dtype=np.float64).ravel()
    if arr.shape[0] < 2 or not np.isfinite(arr[:2]).all():
        raise ValueError(f"{name} must be a finite (x, y), got {p!r}")
    return float(arr[0]), float(arr[1])
