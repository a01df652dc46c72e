"""The nearest frontier a disc robot can drive to, by breadth-first search on the grid.

The semantic expert's fallback: GRID-FAST-style segmentations have no frontier pathway until
the map holds an intersection (a single corridor gives no areas at all), and they seal small
frontiers. While the topometric map offers no frontier, the expert drives to the nearest
frontier found here; and it stops only when neither source has one.

A frontier cell is a FREE cell with an UNKNOWN 4-neighbour; frontier cells are grouped
8-connected and groups smaller than ``min_frontier_cells`` are ignored. The robot may use FREE
cells at least ``clearance_m`` from every OCCUPIED cell (UNKNOWN cells do not count as
obstacles, so the free cells beside a frontier stay usable). The goal is the nearest (by path
cost) usable cell within ``reach_m`` of a kept frontier cell, found by an 8-connected Dijkstra
search from the robot. A step costs its length times ``1 + wall_cost * max(0, 1 - d / d_pref)``
with ``d`` the cell's distance to the nearest wall and ``d_pref = clearance_m + prefer_extra_m``,
so paths keep to the middle of corridors instead of hugging the usable region's edge.

:func:`pocket_exit_path` finds the way out when the robot stands in a pocket of the usable
cells (a spot the robot fits in, cut off from the rest by a gap narrower than the clearance).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
from scipy import ndimage

from semexplore_gym.core.frontiers.detection import frontier_cell_mask
from semexplore_gym.core.frontiers.reachable_kernels import (
    dijkstra,
    dilate,
    near_marked,
    nearest_usable,
    step_cost_kernel,
)
from semexplore_gym.core.frontiers.wall_distance import wall_distance_m
from semexplore_gym.core.grid import FREE, OCCUPIED, UNKNOWN, GridGeometry
from semexplore_gym.core.planning.grid_scan import checked_encoded_grid

#: Defaults of the searches' step cost (see the module docstring).
WALL_COST = 4.0
PREFER_EXTRA_M = 0.15


@dataclass(frozen=True)
class ReachableFrontier:
    """The nearest reachable frontier (by the search's path cost).

    Attributes:
        goal_xy_m: Centre of the goal cell (a usable cell within ``reach_m`` of the frontier).
        path_m: ``(K, 2)`` polyline from the robot's position through cell centres to the goal.
        path_length_m: Length of ``path_m``.
        frontier_xy_m: Centroid of the frontier group the goal is next to.
        n_frontier_cells: Size of that group.
    """

    goal_xy_m: tuple[float, float]
    path_m: np.ndarray
    path_length_m: float
    frontier_xy_m: tuple[float, float]
    n_frontier_cells: int


def clearance_field_m(grid: npt.ArrayLike, resolution_m: float) -> np.ndarray:
    """Distance in metres from every cell centre to the nearest OCCUPIED cell centre (inf if none)."""
    # The same floats as ndimage.distance_transform_edt(g != OCCUPIED) * resolution_m.
    return wall_distance_m(np.ascontiguousarray(checked_encoded_grid(grid)), float(resolution_m))


def known_free_clearance_m(grid: npt.ArrayLike, resolution_m: float) -> np.ndarray:
    """Distance in metres from every FREE cell centre to the nearest cell centre that is not
    FREE (OCCUPIED or UNKNOWN; 0 on those): the clearance a robot can count on where walls
    may still be unseen (a passage mapped on one side only is as narrow as its known part)."""
    g = checked_encoded_grid(grid)
    return ndimage.distance_transform_edt(g == FREE) * float(resolution_m)


def frontier_groups(
    grid: np.ndarray, min_frontier_cells: int, min_unknown_depth_cells: float = 0.0
) -> tuple[np.ndarray, int]:
    """Label 8-connected groups of frontier cells (FREE with an UNKNOWN 4-neighbour).

    A group is kept when it has at least ``min_frontier_cells`` cells and, with
    ``min_unknown_depth_cells > 0``, when unknown space at least that deep lies next to it: an
    UNKNOWN cell at least ``min_unknown_depth_cells`` from every known cell, within
    ``min_unknown_depth_cells + 2`` cells of the group. This rejects unknown slivers no scan can
    ever fill: the inside of thick walls seen through gaps in their mapped faces, pockets along
    walls. Returns ``(labels, n)``; label 0 is "not a kept frontier".
    """
    unknown = grid == UNKNOWN
    cells = frontier_cell_mask(grid, cell_convention="free")
    labels, n = ndimage.label(cells, structure=np.ones((3, 3), dtype=bool))
    if n == 0:
        return labels, 0
    sizes = np.bincount(labels.ravel(), minlength=n + 1)
    keep = sizes >= max(1, int(min_frontier_cells))
    if min_unknown_depth_cells > 0 and keep[1:].any():
        # Depth of unknown cells: distance to the nearest known cell. The grid is padded with
        # unknown so that unknown space running off the map counts as deep.
        # wall_distance_m is scipy's distance_transform_edt bit for bit (distances to the
        # cells marked OCCUPIED), a few times faster: this runs at every replan.
        pad = int(math.ceil(min_unknown_depth_cells)) + 2
        padded = np.pad(unknown, pad, constant_values=True)
        known_marked = np.where(padded, np.uint8(UNKNOWN), np.uint8(OCCUPIED))
        deep = wall_distance_m(known_marked, 1.0) >= min_unknown_depth_cells
        if deep.any():
            # Deep unknown within depth + 2 cells, tested at the frontier cells only.
            fr, fc = np.nonzero(cells)
            near = near_marked(deep, fr + pad, fc + pad, min_unknown_depth_cells + 2.0)
            ok = np.zeros(n + 1, dtype=bool)
            ok[np.unique(labels[fr[near], fc[near]])] = True
            keep &= ok
        else:
            keep[:] = False
    keep[0] = False
    remap = np.zeros(n + 1, dtype=labels.dtype)
    remap[keep] = np.arange(1, int(keep.sum()) + 1)
    return remap[labels], int(keep.sum())


@dataclass(frozen=True)
class FrontierFilter:
    """Which frontier cells :func:`nearest_reachable_frontier` may drive to.

    Attributes:
        min_frontier_cells: Smaller frontier groups are ignored.
        reach_m: A goal cell lies within this distance of a frontier cell.
        min_unknown_depth_cells: Frontier groups without unknown space this deep (in cells)
            next to them are ignored (see :func:`frontier_groups`).
        excluded_xy_m: Frontier cells within ``excluded_radius_m`` of these points are ignored
            (the expert's blacklist).
        excluded_radius_m: See ``excluded_xy_m``.
    """

    min_frontier_cells: int = 3
    reach_m: float = 0.3
    min_unknown_depth_cells: float = 0.0
    excluded_xy_m: Sequence[tuple[float, float]] = ()
    excluded_radius_m: float = 0.5


@dataclass(frozen=True)
class StepCost:
    """The grid searches' step cost near walls (see the module docstring).

    Attributes:
        wall_cost: Extra step cost near walls; 0 gives shortest paths.
        prefer_extra_m: Cells farther than ``clearance_m + prefer_extra_m`` from walls cost no
            extra.
    """

    wall_cost: float = WALL_COST
    prefer_extra_m: float = PREFER_EXTRA_M


def nearest_reachable_frontier(
    grid: npt.ArrayLike,
    geometry: GridGeometry,
    start_xy_m: tuple[float, float],
    clearance_m: float,
    frontiers: FrontierFilter = FrontierFilter(),
    clearance_field: np.ndarray | None = None,
    step_cost: StepCost = StepCost(),
) -> ReachableFrontier | None:
    """Search from the robot to the nearest usable cell next to a frontier.

    Args:
        grid: Encoded occupancy grid (uint8).
        geometry: Frame of ``grid``.
        start_xy_m: Robot position. When its cell is not usable (too close to a wall), the
            search starts from the nearest usable cell within 0.5 m.
        clearance_m: Minimum distance from usable cells to OCCUPIED cells.
        frontiers: Which frontier cells count, and how near the goal must be to them.
        clearance_field: A precomputed :func:`clearance_field_m` of ``grid`` (optional).
        step_cost: The step cost near walls.

    Returns:
        The :class:`ReachableFrontier`, or None when no frontier can be reached.

    Raises:
        ValueError: on a malformed grid, a shape mismatch or negative distances.
    """
    g = checked_search_inputs(grid, geometry, clearance_m, frontiers)
    f = frontiers
    res = geometry.resolution_m
    # Everything below happens within the window of the known cells (a large map is mostly
    # unknown): usable cells are FREE, so the search never leaves it, and the margin holds the
    # start's 0.5 m escape and the goals' reach. Same result as on the whole grid, cell for cell.
    margin = int(math.ceil(0.5 / res)) + int(math.ceil(f.reach_m / res)) + 2
    r0, r1, c0, c1 = known_window(g, geometry, start_xy_m, margin)
    if r0 >= r1 or c0 >= c1:  # nothing known and the start off the grid
        return None
    full_dist = clearance_field
    g = np.ascontiguousarray(g[r0:r1, c0:c1])
    labels, n = frontier_groups(g, f.min_frontier_cells, f.min_unknown_depth_cells)
    if n == 0:
        return None
    if len(f.excluded_xy_m) and not drop_excluded(labels, geometry, f, (r0, c0)):
        return None
    dist = (
        np.ascontiguousarray(full_dist[r0:r1, c0:c1])
        if full_dist is not None
        else clearance_field_m(g, res)
    )
    usable = usable_cells(g, dist, clearance_m)
    near = dilate(labels > 0, f.reach_m / res) if f.reach_m > 0 else labels > 0
    goal_mask = usable & near

    cost = step_cost_field(dist, usable, clearance_m, step_cost.wall_cost, step_cost.prefer_extra_m)
    path = _search_path(g, geometry, usable, cost, goal_mask, start_xy_m, (r0, c0))
    if path is None:
        return None
    centre_xy_m, n_cells = _served_group(labels, (r0, c0), geometry, path[-1])
    return ReachableFrontier(
        goal_xy_m=(float(path[-1, 0]), float(path[-1, 1])),
        path_m=path,
        path_length_m=float(np.hypot(*np.diff(path, axis=0).T).sum()) if len(path) > 1 else 0.0,
        frontier_xy_m=centre_xy_m,
        n_frontier_cells=n_cells,
    )


def checked_search_inputs(
    grid: npt.ArrayLike, geometry: GridGeometry, clearance_m: float, frontiers: FrontierFilter
) -> np.ndarray:
    """The encoded grid, after checking its shape against ``geometry`` and that the
    distances are finite and >= 0 (ValueError naming the bad one)."""
    g = checked_encoded_grid(grid)
    if g.shape != geometry.shape:
        raise ValueError(f"grid shape {g.shape} does not match geometry shape {geometry.shape}")
    for name, value in (
        ("clearance_m", clearance_m),
        ("reach_m", frontiers.reach_m),
        ("excluded_radius_m", frontiers.excluded_radius_m),
    ):
        if not (math.isfinite(value) and value >= 0.0):
            raise ValueError(f"{name} must be a finite number >= 0, got {value!r}")
    return g


def _served_group(
    labels: np.ndarray, offset: tuple[int, int], geometry: GridGeometry, goal_xy_m: np.ndarray
) -> tuple[tuple[float, float], int]:
    """The centre and size of the frontier group a goal serves: the group with the cell nearest
    the goal's cell (``labels`` covers the grid's window starting at cell ``offset``)."""
    r0, c0 = offset
    gr, gc = (int(v) for v in geometry.world_to_grid(goal_xy_m[0], goal_xy_m[1]))
    fr, fc = np.nonzero(labels)
    j = int(np.argmin((fr + r0 - gr) ** 2 + (fc + c0 - gc) ** 2))
    lab = labels[fr, fc]
    grp = lab == lab[j]  # the group's cells, in the same (row-major) order as a mask's nonzero
    rows, cols = fr[grp], fc[grp]
    cx, cy = geometry.grid_to_world((rows + r0).mean(), (cols + c0).mean())
    return (float(cx), float(cy)), int(grp.sum())


def known_window(
    g: np.ndarray, geometry: GridGeometry, start_xy_m: tuple[float, float], margin: int
) -> tuple[int, int, int, int]:
    """``(r0, r1, c0, c1)``: the rows and columns holding every known cell and the start cell,
    widened by ``margin`` cells (clipped to the grid)."""
    h, w = g.shape
    known = g != UNKNOWN
    rows = np.flatnonzero(known.any(axis=1))
    cols = np.flatnonzero(known.any(axis=0))
    sr, sc = (int(v) for v in geometry.world_to_grid(start_xy_m[0], start_xy_m[1]))
    if len(rows) == 0:
        rows = cols = np.empty(0, dtype=np.int64)
    lo_r, hi_r = min([*rows[:1], sr]), max([*rows[-1:], sr])
    lo_c, hi_c = min([*cols[:1], sc]), max([*cols[-1:], sc])
    return (
        max(int(lo_r) - margin, 0),
        min(int(hi_r) + margin + 1, h),
        max(int(lo_c) - margin, 0),
        min(int(hi_c) + margin + 1, w),
    )


def drop_excluded(
    labels: np.ndarray,
    geometry: GridGeometry,
    frontiers: FrontierFilter,
    offset: tuple[int, int] = (0, 0),
) -> bool:
    """Unlabel (in place) the frontier cells near the excluded points; False if none is left.
    ``labels`` covers the grid's window starting at cell ``offset``."""
    fr, fc = np.nonzero(labels)
    fx, fy = geometry.grid_to_world(fr + offset[0], fc + offset[1])
    drop = np.zeros(len(fr), dtype=bool)
    for ex, ey in frontiers.excluded_xy_m:
        drop |= np.hypot(fx - ex, fy - ey) <= frontiers.excluded_radius_m
    labels[fr[drop], fc[drop]] = 0
    return bool(labels.any())


def grid_path_to(
    grid: npt.ArrayLike,
    geometry: GridGeometry,
    start_xy_m: tuple[float, float],
    goal_xy_m: tuple[float, float],
    clearance_m: float,
    goal_radius_m: float = 0.15,
    clearance_field: np.ndarray | None = None,
    step_cost: StepCost = StepCost(),
) -> np.ndarray | None:
    """Path over usable cells (see the module docstring) from ``start_xy_m`` to a usable cell
    within ``goal_radius_m`` of ``goal_xy_m``; ``(K, 2)`` world polyline, or None if unreachable."""
    g = checked_encoded_grid(grid)
    if g.shape != geometry.shape:
        raise ValueError(f"grid shape {g.shape} does not match geometry shape {geometry.shape}")
    res = geometry.resolution_m
    # Within the window of the known cells, as nearest_reachable_frontier: usable cells are
    # FREE, so neither the search nor a goal cell leaves it. Same path as on the whole grid.
    w0r, w1r, w0c, w1c = known_window(g, geometry, start_xy_m, int(math.ceil(0.5 / res)) + 2)
    if w0r >= w1r or w0c >= w1c:
        return None
    g = np.ascontiguousarray(g[w0r:w1r, w0c:w1c])
    dist = (
        np.ascontiguousarray(clearance_field[w0r:w1r, w0c:w1c])
        if clearance_field is not None
        else clearance_field_m(g, res)  # every wall is in the window: the same values
    )
    usable = usable_cells(g, dist, clearance_m)
    h, w = g.shape
    gr, gc = (int(v) for v in geometry.world_to_grid(goal_xy_m[0], goal_xy_m[1]))
    gr, gc = gr - w0r, gc - w0c
    rad = int(math.ceil(goal_radius_m / res))
    r0, r1 = max(gr - rad, 0), min(gr + rad + 1, h)
    c0, c1 = max(gc - rad, 0), min(gc + rad + 1, w)
    if r0 >= r1 or c0 >= c1:
        return None
    goal_mask = np.zeros((h, w), dtype=bool)
    rr, cc = np.mgrid[r0:r1, c0:c1]
    xs, ys = geometry.grid_to_world(rr + w0r, cc + w0c)
    goal_mask[r0:r1, c0:c1] = np.hypot(xs - goal_xy_m[0], ys - goal_xy_m[1]) <= max(
        goal_radius_m, 0.5 * res
    )
    goal_mask &= usable
    if not goal_mask.any():
        return None
    cost = step_cost_field(dist, usable, clearance_m, step_cost.wall_cost, step_cost.prefer_extra_m)
    return _search_path(g, geometry, usable, cost, goal_mask, start_xy_m, (w0r, w0c))


def grid_path_to_mask(
    grid: npt.ArrayLike,
    geometry: GridGeometry,
    start_xy_m: tuple[float, float],
    goal_mask: np.ndarray,
    clearance_m: float,
    clearance_field: np.ndarray | None = None,
) -> np.ndarray | None:
    """Path over usable cells (see the module docstring) from ``start_xy_m`` to the nearest (by
    path cost) usable cell of ``goal_mask`` (``(H, W)`` bool); ``(K, 2)`` world polyline, or
    None if none is reachable."""
    g = checked_encoded_grid(grid)
    if g.shape != geometry.shape or np.shape(goal_mask) != g.shape:
        raise ValueError(f"grid, geometry and goal_mask shapes differ: {g.shape}, {geometry.shape}")
    dist = (
        clearance_field
        if clearance_field is not None
        else clearance_field_m(g, geometry.resolution_m)
    )
    usable = usable_cells(g, dist, clearance_m)
    goals = usable & np.asarray(goal_mask, dtype=bool)
    if not goals.any():
        return None
    cost = step_cost_field(dist, usable, clearance_m, WALL_COST, PREFER_EXTRA_M)
    return _search_path(g, geometry, usable, cost, goals, start_xy_m)


def usable_cells(g: np.ndarray, dist: np.ndarray, clearance_m: float) -> np.ndarray:
    """FREE cells at least ``clearance_m`` from every OCCUPIED cell (to rounding)."""
    return (g == FREE) & (dist >= clearance_m - 1e-9)


def step_cost_field(
    dist: np.ndarray,
    usable: np.ndarray,
    clearance_m: float,
    wall_cost: float,
    prefer_extra_m: float,
) -> np.ndarray:
    """The searches' cost of entering each cell (see the module docstring: 1 far from walls,
    up to ``1 + wall_cost`` near them; ``usable`` cells only, the others are never entered)."""
    if not (
        math.isfinite(wall_cost)
        and wall_cost >= 0.0
        and math.isfinite(prefer_extra_m)
        and prefer_extra_m >= 0.0
    ):
        raise ValueError(
            f"wall_cost and prefer_extra_m must be finite and >= 0, got {wall_cost!r}, {prefer_extra_m!r}"
        )
    pref = clearance_m + prefer_extra_m
    cost = np.empty(dist.shape)
    step_cost_kernel(
        np.ascontiguousarray(dist, dtype=np.float64),
        np.ascontiguousarray(usable, dtype=np.bool_),
        float(pref),
        float(wall_cost),
        cost,
    )
    return cost


def pocket_exit_path(
    grid: npt.ArrayLike,
    geometry: GridGeometry,
    start_xy_m: tuple[float, float],
    clearance_m: float,
    exit_clearance_m: float,
    max_share: float,
    clearance_field: np.ndarray | None = None,
) -> np.ndarray | None:
    """The way out of a pocket of the usable map, over cells with a thinner clearance.

    A search from ``start_xy_m`` starts at the robot's cell, or the nearest usable cell within
    0.5 m, and steps between side neighbours (diagonal steps need both side cells usable, so
    they connect nothing more). The region it starts in is a pocket when it holds less than
    ``max_share`` of the cells usable with ``clearance_m`` (or when no start cell is found): a
    spot narrower than ``clearance_m`` cuts it off from the rest. The path then leads, over FREE
    cells at least ``exit_clearance_m`` from walls, to the nearest usable cell of a region that
    is not a pocket.

    Returns:
        ``(K, 2)`` polyline from ``start_xy_m`` to that cell's centre, or None when the start
        is not in a pocket or no way out exists.

    Raises:
        ValueError: on a malformed grid, a shape mismatch, negative clearances, an exit
            clearance above ``clearance_m`` or a share outside [0, 1].
    """
    g = checked_encoded_grid(grid)
    if g.shape != geometry.shape:
        raise ValueError(f"grid shape {g.shape} does not match geometry shape {geometry.shape}")
    if not (math.isfinite(exit_clearance_m) and 0.0 <= exit_clearance_m <= clearance_m):
        raise ValueError(
            f"need 0 <= exit_clearance_m <= clearance_m, got {exit_clearance_m!r}, {clearance_m!r}"
        )
    if not (math.isfinite(max_share) and 0.0 <= max_share <= 1.0):
        raise ValueError(f"max_share must be in [0, 1], got {max_share!r}")
    dist = (
        clearance_field
        if clearance_field is not None
        else clearance_field_m(g, geometry.resolution_m)
    )
    usable = usable_cells(g, dist, clearance_m)
    n_usable = int(np.count_nonzero(usable))
    if n_usable == 0:
        return None
    labels, _n = ndimage.label(usable)
    sizes = np.bincount(labels.ravel())
    sizes[0] = 0
    start = search_start_cell(g, geometry, usable, start_xy_m)
    own = int(labels[start]) if start is not None else 0
    big = sizes >= max_share * n_usable
    big[0] = False
    if own and big[own]:
        return None
    big[own] = False
    wide = usable_cells(g, dist, exit_clearance_m)
    cost = step_cost_field(dist, wide, exit_clearance_m, WALL_COST, PREFER_EXTRA_M)
    return _search_path(g, geometry, wide, cost, big[labels], start_xy_m)


def search_start_cell(
    g: np.ndarray,
    geometry: GridGeometry,
    usable: np.ndarray,
    start_xy_m: tuple[float, float],
    offset: tuple[int, int] = (0, 0),
) -> tuple[int, int] | None:
    """The search's start: the robot's cell when usable, else the nearest usable within 0.5 m
    (cells of the window starting at ``offset``)."""
    h, w = g.shape
    sr, sc = (int(v) for v in geometry.world_to_grid(start_xy_m[0], start_xy_m[1]))
    sr, sc = sr - offset[0], sc - offset[1]
    if not (0 <= sr < h and 0 <= sc < w):
        return None
    if not usable[sr, sc]:
        found = nearest_usable(
            usable, g != OCCUPIED, sr, sc, int(math.ceil(0.5 / geometry.resolution_m))
        )
        if found[0] < 0:
            return None
        sr, sc = found
    return sr, sc


def _search_path(
    g: np.ndarray,
    geometry: GridGeometry,
    usable: np.ndarray,
    cost: np.ndarray,
    goal_mask: np.ndarray,
    start_xy_m: tuple[float, float],
    offset: tuple[int, int] = (0, 0),
) -> np.ndarray | None:
    """The search from the start to the first goal cell settled, as a world polyline; the
    arrays cover the grid's window starting at cell ``offset``."""
    w = g.shape[1]
    start = search_start_cell(g, geometry, usable, start_xy_m, offset)
    if start is None:
        return None
    sr, sc = start
    goal, parent = dijkstra(cost, goal_mask, sr, sc)
    if goal < 0:
        return None
    cells = []
    k = goal
    while k >= 0:
        cells.append(k)
        k = parent[k]
    cells.reverse()
    idx = np.asarray(cells)
    xs, ys = geometry.grid_to_world(idx // w + offset[0], idx % w + offset[1])
    return np.vstack([np.asarray(start_xy_m, dtype=np.float64)[None, :], np.column_stack([xs, ys])])
