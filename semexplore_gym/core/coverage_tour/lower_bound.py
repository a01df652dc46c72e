"""A certified lower bound on the drive (and time) any explorer needs to reach the coverage goal.

:func:`lower_bound` relaxes the exploration problem in steps, each of which can only lower the
optimum, so the result is below the path length of every explorer with this robot and LiDAR:

1. **Robot cells.** Pymunk keeps the robot's centre ``radius_m`` (circle of ``radius - skin``
   plus the wall's ``skin``) from every wall, less a penetration tolerance (0.01 m; the physics'
   collision slop is at most 0.005 m): clearance ``c_min``. A cell that holds such a point has
   its centre at least ``c_min - h/sqrt(2)`` from every wall, so the robot's centre only ever
   lies in cells meeting that test, 8-connected to the start's cell (the allowed cells).
2. **K-hop distances never exceed a real path.** Checkpoint a continuous path each time it first
   reaches Chebyshev distance K (cells) from the last checkpoint's cell: each piece stays in the
   previous checkpoint's ball, so a breadth-first search over allowed cells inside the ball
   finds it, and the piece is at least as long as the distance between the two cells' squares.
   The Dijkstra distance over such hops (the last hop may end inside a ball) is <= the length.
3. **Where a group can be seen from (a superset).** A scan marks a cell FREE only along a beam
   from the sensor that reaches a point of the cell's square within the LiDAR's range and
   crosses no wall first. For a rectangle A of cells, a robot cell U is excluded only when its
   square (widened by the LiDAR's mount offset) is farther than the range from A, or one wall
   (collinear touching walls merged) meets every segment from U to A: its line separates them
   strictly and the 16 corner-pair segments cross it inside the wall (the segments from U to A
   fill the convex hull of both, whose crossing with the line is spanned by the corner pairs).
4. **Route through must-see groups.** Groups are the coverage-mask cells of the blocks of a
   lattice. If the explorer never entered a group's region, none of its cells is FREE; the goal
   leaves at most ``budget`` mask cells unseen, so the explorer enters the regions of a set S
   of the chosen groups whose others hold at most ``budget`` cells, in order of first entry,
   each leg at least the K-hop distance between the regions. The bound is the least such route
   over every feasible S (Held-Karp, exact), with any choice of groups (disjoint regions only
   make it tighter); cells no allowed cell can see at all are taken off the budget first.

Time at top speed is ``distance_m / max_linear_speed_mps``. The bound assumes a noise-free
LiDAR fused at the true pose (the env's default: no range noise, no odometry drift).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np
from scipy import ndimage

from semexplore_gym.core.coverage_tour.lower_bound_kernels import (
    group_region,
    held_karp_route,
    khop_distances,
    region_stats,
)
from semexplore_gym.core.coverage_tour.problem import PrivilegedWorld
from semexplore_gym.core.grid import GridGeometry
from semexplore_gym.core.worlds.geometry import segment_distance_field

#: Selection orders the bound tries (each gives a valid bound; the larger wins).
SELECTIONS = ("region", "cells", "far")
_EIGHT = np.ones((3, 3), dtype=bool)
_VISIBILITY_TOL_M = 1e-6
_CLEARANCE_TOL_M = 1e-4


@dataclass(frozen=True)
class LowerBoundParams:
    """Knobs of :func:`lower_bound` (any values give a valid bound; they trade speed for tightness).

    Attributes:
        hop_cells: K of the K-hop metric (open space: about (K - 1) / K of the straight line).
        group_size_m: Side of the lattice blocks whose coverage-mask cells form a group.
        max_groups: Most groups in the exact route (Held-Karp is 2^n n^2).
        penetration_tolerance_m: How far the robot may press into a wall beyond its radius.
        mount_offset_m: LiDAR distance from the robot centre.
        coverage_share: Coverage to reach; None for the env's ``coverage_goal``.
        selections: Group selection orders to try (of :data:`SELECTIONS`).
    """

    hop_cells: int = 12
    group_size_m: float = 1.0
    max_groups: int = 13
    penetration_tolerance_m: float = 0.01
    mount_offset_m: float = 0.0
    coverage_share: float | None = None
    selections: tuple[str, ...] = SELECTIONS

    def __post_init__(self) -> None:
        if not (isinstance(self.hop_cells, int) and 1 <= self.hop_cells <= 64):
            raise ValueError(f"hop_cells must be an integer in 1..64, got {self.hop_cells!r}")
        if not (math.isfinite(self.group_size_m) and self.group_size_m > 0):
            raise ValueError(f"group_size_m must be positive, got {self.group_size_m!r}")
        if not (isinstance(self.max_groups, int) and 1 <= self.max_groups <= 18):
            raise ValueError(f"max_groups must be an integer in 1..18, got {self.max_groups!r}")
        for name in ("penetration_tolerance_m", "mount_offset_m"):
            v = getattr(self, name)
            if not (math.isfinite(v) and 0 <= v <= 0.5):
                raise ValueError(f"{name} must be in [0, 0.5] m, got {v!r}")
        share = self.coverage_share
        if share is not None and not (0 < share <= 1):
            raise ValueError(f"coverage_share must be in (0, 1], got {share!r}")
        bad = [s for s in self.selections if s not in SELECTIONS]
        if bad or not self.selections:
            raise ValueError(f"selections must be among {SELECTIONS}, got {self.selections!r}")


@dataclass(frozen=True)
class LowerBound:
    """A certified lower bound on the drive to the coverage goal, with what it is made of.

    Attributes:
        distance_m: No explorer reaches the goal after a shorter drive (inf: none can).
        time_s: ``distance_m`` at top speed.
        n_groups: Groups in the route's problem.
        group_cells: Coverage-mask cells of each group.
        group_centres_m: ``(x, y)`` centre of each group's block.
        route: Group indices in the order of the bound's route (the groups it visits).
        budget_cells: Mask cells the goal lets an explorer leave unseen.
        selection: The selection order that gave the bound.
        planning_s: Wall time spent.
    """

    distance_m: float
    time_s: float
    n_groups: int
    group_cells: tuple[int, ...]
    group_centres_m: tuple[tuple[float, float], ...]
    route: tuple[int, ...]
    budget_cells: int
    selection: str
    planning_s: float


def skip_budget_cells(n_cells: int, share: float) -> int:
    """Most of ``n_cells`` that may stay unseen with coverage ``count / n_cells >= share``."""
    need = min(n_cells, max(0, math.ceil(share * n_cells) - 1))
    while need < n_cells and need / n_cells < share:
        need += 1
    return n_cells - need


def allowed_cells(facts: PrivilegedWorld, tolerance_m: float) -> tuple[np.ndarray, tuple[int, int]]:
    """The cells the robot's centre can lie in (step 1) and the start's cell.

    Raises:
        ValueError: a start outside the grid or too close to a wall, or free space that reaches
            the edge of the grid (the map is larger than the grid holds).
    """
    geo = facts.geometry
    h = geo.resolution_m
    c_min = facts.radius_m - tolerance_m
    need = c_min - h / math.sqrt(2.0) - _CLEARANCE_TOL_M
    field = segment_distance_field(facts.world.segments_m, geo, max(need, 0.0) + h)
    ok = field >= need
    x, y = facts.start_pose[0], facts.start_pose[1]
    row, col = (int(v) for v in geo.world_to_grid(x, y))
    if not (0 <= row < geo.height and 0 <= col < geo.width):
        raise ValueError(f"start ({x:g}, {y:g}) lies outside the map grid")
    if not ok[row, col]:
        raise ValueError(
            f"start ({x:g}, {y:g}) is inside a wall: closer than the robot's radius "
            f"({facts.radius_m:g} m) to one"
        )
    labels, _ = ndimage.label(ok, structure=_EIGHT)
    allowed = labels == labels[row, col]
    if allowed[0, :].any() or allowed[-1, :].any() or allowed[:, 0].any() or allowed[:, -1].any():
        raise ValueError(
            "the free space around the start reaches the edge of the map grid: the world is "
            "larger than the grid holds (or not closed by walls)"
        )
    return allowed, (row, col)


def merge_walls(segments_m: np.ndarray, tol_m: float = 1e-9) -> np.ndarray:
    """Collinear walls that touch or overlap, merged into maximal segments ``(M, 4)``."""
    seg = np.asarray(segments_m, dtype=np.float64).reshape(-1, 4)
    d = seg[:, 2:] - seg[:, :2]
    length = np.hypot(d[:, 0], d[:, 1])
    keep = length > 0
    seg, d, length = seg[keep], d[keep], length[keep]
    u = d / length[:, None]
    flip = (u[:, 0] < -1e-12) | ((np.abs(u[:, 0]) <= 1e-12) & (u[:, 1] < 0))
    u[flip] *= -1.0
    offset = seg[:, 0] * -u[:, 1] + seg[:, 1] * u[:, 0]
    key = np.round(np.column_stack([u[:, 0], u[:, 1], offset]) * 1e9).astype(np.int64)
    out: list[np.ndarray] = []
    _, inverse = np.unique(key, axis=0, return_inverse=True)
    for g in np.unique(inverse):
        idx = np.flatnonzero(inverse == g)
        ug = u[idx[0]]
        base = seg[idx[0], :2]
        s0 = (seg[idx, :2] - base) @ ug
        s1 = (seg[idx, 2:] - base) @ ug
        lo, hi = np.minimum(s0, s1), np.maximum(s0, s1)
        order = np.argsort(lo)
        cur_lo, cur_hi = lo[order[0]], hi[order[0]]
        for i in order[1:]:
            if lo[i] <= cur_hi + tol_m:
                cur_hi = max(cur_hi, hi[i])
            else:
                out.append(np.concatenate([base + cur_lo * ug, base + cur_hi * ug]))
                cur_lo, cur_hi = lo[i], hi[i]
        out.append(np.concatenate([base + cur_lo * ug, base + cur_hi * ug]))
    return np.array(out, dtype=np.float64).reshape(-1, 4)


def mask_groups(
    mask: np.ndarray, geometry: GridGeometry, block_cells: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The mask cells of each ``block_cells`` lattice block: ``(rects, cells, centres)``:
    the bounding rectangle ``x0, y0, x1, y1`` of each non-empty group, its cell count and the
    centre of its block."""
    b = max(1, int(block_cells))
    rows, cols = np.nonzero(mask)
    block = (rows // b) * (-(-mask.shape[1] // b)) + cols // b
    ids, inverse, cells = np.unique(block, return_inverse=True, return_counts=True)
    n = ids.size
    rmin = np.full(n, np.iinfo(np.int64).max)
    rmax = np.full(n, -1)
    cmin = np.full(n, np.iinfo(np.int64).max)
    cmax = np.full(n, -1)
    np.minimum.at(rmin, inverse, rows)
    np.maximum.at(rmax, inverse, rows)
    np.minimum.at(cmin, inverse, cols)
    np.maximum.at(cmax, inverse, cols)
    h, x0, y0 = geometry.resolution_m, geometry.origin_x_m, geometry.origin_y_m
    rects = np.column_stack([x0 + cmin * h, y0 + rmin * h, x0 + (cmax + 1) * h, y0 + (rmax + 1) * h])
    nb = -(-mask.shape[1] // b)
    br, bc = ids // nb, ids % nb
    centres = np.column_stack([x0 + (bc + 0.5) * b * h, y0 + (br + 0.5) * b * h])
    return rects.astype(np.float64), cells.astype(np.int64), centres


@dataclass(frozen=True)
class _Problem:
    allowed: np.ndarray
    walls: np.ndarray
    geometry: GridGeometry
    reach_m: float
    widen_m: float
    hop_cells: int
    rects: np.ndarray

    def region(self, rect: np.ndarray) -> np.ndarray:
        g = self.geometry
        return group_region(
            self.allowed,
            rect,
            self.walls,
            g.origin_x_m,
            g.origin_y_m,
            g.resolution_m,
            self.reach_m,
            self.widen_m,
            _VISIBILITY_TOL_M,
        )

    def distances(self, sources: np.ndarray) -> np.ndarray:
        src = np.asarray(sources, dtype=np.int64)
        d = khop_distances(self.allowed, src, self.hop_cells, self.geometry.resolution_m)
        return d.reshape(-1)


def lower_bound(facts: PrivilegedWorld, params: LowerBoundParams | None = None) -> LowerBound:
    """A certified lower bound on the drive to the coverage goal from ``facts.start_pose``.

    Raises:
        ValueError: nothing reachable to cover, a start inside a wall or outside the grid, or a
            map larger than its grid.
    """
    p = params or LowerBoundParams()
    t0 = time.perf_counter()
    geo = facts.geometry
    mask = np.asarray(facts.reachable_mask, dtype=bool)
    n_mask = int(mask.sum())
    if n_mask == 0:
        raise ValueError("nothing to cover: the reachable mask has no cell")
    allowed, (sr, sc) = allowed_cells(facts, p.penetration_tolerance_m)
    block = max(1, int(round(p.group_size_m / geo.resolution_m)))
    rects, cells, centres = mask_groups(mask, geo, block)
    share = facts.coverage_goal if p.coverage_share is None else p.coverage_share
    budget = skip_budget_cells(n_mask, share)
    prob = _Problem(
        allowed=allowed,
        walls=merge_walls(facts.world.segments_m),
        geometry=geo,
        reach_m=facts.sensor.max_range_m + _VISIBILITY_TOL_M,
        widen_m=p.mount_offset_m + _VISIBILITY_TOL_M,
        hop_cells=p.hop_cells,
        rects=rects,
    )
    from_start = prob.distances(np.array([sr * geo.width + sc]))
    sizes, near = region_stats(
        allowed,
        rects,
        prob.walls,
        geo.origin_x_m,
        geo.origin_y_m,
        geo.resolution_m,
        prob.reach_m,
        prob.widen_m,
        _VISIBILITY_TOL_M,
        from_start.reshape(allowed.shape),
    )
    # Groups no allowed cell can see stay unseen: their cells come off the budget.
    budget_left = budget - int(cells[sizes == 0].sum())
    best = (0.0, (), "none", np.zeros(0, dtype=np.int64))
    if budget_left < 0:
        best = (math.inf, (), "unseeable", np.zeros(0, dtype=np.int64))
    else:
        useful = np.flatnonzero((sizes > 0) & (near > 0) & np.isfinite(near))
        legs_cache: dict[int, np.ndarray] = {}
        for how in p.selections:
            chosen = _select(prob, useful, how, sizes, cells, near, p.max_groups)
            if chosen.size == 0:
                continue
            length, order = _route(prob, chosen, near, cells, budget_left, legs_cache)
            if length > best[0]:
                best = (length, tuple(int(chosen[i]) for i in order), how, chosen)
    length, route_ids, how, chosen = best
    index = {int(g): i for i, g in enumerate(chosen)}
    return LowerBound(
        distance_m=float(length),
        time_s=float(length) / facts.max_linear_speed_mps,
        n_groups=int(chosen.size),
        group_cells=tuple(int(cells[g]) for g in chosen),
        group_centres_m=tuple((float(centres[g, 0]), float(centres[g, 1])) for g in chosen),
        route=tuple(index[g] for g in route_ids),
        budget_cells=budget,
        selection=how,
        planning_s=time.perf_counter() - t0,
    )


def _select(
    prob: _Problem,
    useful: np.ndarray,
    how: str,
    sizes: np.ndarray,
    cells: np.ndarray,
    near: np.ndarray,
    cap: int,
) -> np.ndarray:
    """Groups with pairwise disjoint regions, greedily in the order ``how``; the ``cap``
    farthest from the start if more."""
    if how == "region":
        order = useful[np.lexsort((-cells[useful], sizes[useful]))]
    elif how == "cells":
        order = useful[np.lexsort((sizes[useful], -cells[useful]))]
    else:
        order = useful[np.lexsort((sizes[useful], -near[useful]))]
    taken = np.zeros(prob.allowed.size, dtype=bool)
    chosen: list[int] = []
    for g in order:
        region = prob.region(prob.rects[g])
        if taken[region].any():
            continue
        taken[region] = True
        chosen.append(int(g))
    out = np.array(chosen, dtype=np.int64)
    if out.size > cap:
        out = out[np.argsort(-near[out], kind="stable")[:cap]]
    return out


def _route(
    prob: _Problem,
    chosen: np.ndarray,
    near: np.ndarray,
    cells: np.ndarray,
    budget: int,
    cache: dict[int, np.ndarray],
) -> tuple[float, np.ndarray]:
    """Held-Karp over the chosen groups: start legs ``near``, legs by K-hop distance fields."""
    m = chosen.size
    regions = [prob.region(prob.rects[g]) for g in chosen]
    legs = np.zeros((m, m), dtype=np.float64)
    for i, g in enumerate(chosen):
        if int(g) not in cache:
            cache[int(g)] = prob.distances(regions[i])
        field = cache[int(g)]
        for j in range(m):
            if j != i:
                legs[i, j] = float(field[regions[j]].min()) if regions[j].size else math.inf
    length, order = held_karp_route(
        near[chosen].astype(np.float64), legs, cells[chosen].astype(np.int64), int(budget)
    )
    return float(length), order
