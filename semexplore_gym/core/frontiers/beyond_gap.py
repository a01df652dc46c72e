"""Room beyond a gap: usable space the map shows past a passage narrower than the clearance.

A LiDAR looks through a gap the robot could squeeze through and maps free space beyond it.
Where that space is wide enough for the robot's usual clearance and has a frontier next to it,
the map itself says the gap leads somewhere: it is not a crack whose far side is rock (a crack
maps no such space). :func:`room_beyond_gap_path` finds the way there over a thinner clearance.

The cells usable at ``clearance_m`` (FREE, at least that far from every OCCUPIED cell) fall into
regions joined by side steps (a diagonal step needs both side cells usable, so it joins
nothing more). The robot's region is the one its search starts in: the robot's cell, or the
nearest usable cell within 0.5 m. Every other region of at least ``min_room_cells`` cells with
a usable cell within ``reach_m`` of a kept frontier cell is room beyond a gap. The path leads
from the robot over cells at least ``thin_m`` from every cell in ``thin_field`` (a clearance
field: the caller's choice of what a wall is) to the nearest cell of such a region.
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt
from scipy import ndimage

from semexplore_gym.core.frontiers.reachable import (
    FrontierFilter,
    checked_search_inputs,
    clearance_field_m,
    drop_excluded,
    frontier_groups,
    grid_path_to_mask,
    known_window,
    search_start_cell,
    usable_cells,
)
from semexplore_gym.core.frontiers.reachable_kernels import dilate
from semexplore_gym.core.grid import GridGeometry

__all__ = ["room_beyond_gap_path"]


def room_beyond_gap_path(
    grid: npt.ArrayLike,
    geometry: GridGeometry,
    start_xy_m: tuple[float, float],
    clearance_m: float,
    thin_m: float,
    thin_field: np.ndarray,
    frontiers: FrontierFilter | None = None,
    min_room_cells: int = 1,
) -> np.ndarray | None:
    """The way through a gap narrower than ``clearance_m`` into room beyond it (see the module
    docstring).

    Args:
        grid: Encoded occupancy grid (uint8).
        geometry: Frame of ``grid``.
        start_xy_m: Robot position.
        clearance_m: The planners' clearance: what counts as room.
        thin_m: The clearance the way there keeps, on ``thin_field``.
        thin_field: Clearance field (metres, the grid's shape) the way is measured on.
        frontiers: Which frontier cells count (groups, depth, exclusions) and ``reach_m``
            (default: :class:`FrontierFilter`'s defaults).
        min_room_cells: Smaller regions are not room.

    Returns:
        ``(K, 2)`` polyline from ``start_xy_m`` to the nearest cell of room beyond a gap, or
        None when there is none or no way there.

    Raises:
        ValueError: on a malformed grid, a shape mismatch, negative distances or
            ``thin_m > clearance_m``.
    """
    frontiers = FrontierFilter() if frontiers is None else frontiers
    g = checked_search_inputs(grid, geometry, clearance_m, frontiers)
    if not (np.isfinite(thin_m) and 0.0 <= thin_m <= clearance_m):
        raise ValueError(f"need 0 <= thin_m <= clearance_m, got {thin_m!r}, {clearance_m!r}")
    if np.shape(thin_field) != g.shape:
        raise ValueError(f"thin_field shape {np.shape(thin_field)} does not match {g.shape}")
    # Everything but the last search happens within the window of the known cells (a large
    # map is mostly unknown; usable cells are FREE), as in nearest_reachable_frontier: the same
    # result as on the whole grid, cell for cell, at the cost of the explored part only.
    res = geometry.resolution_m
    margin = int(math.ceil(0.5 / res)) + int(math.ceil(frontiers.reach_m / res)) + 2
    r0, r1, c0, c1 = known_window(g, geometry, start_xy_m, margin)
    if r0 >= r1 or c0 >= c1:
        return None
    w = np.ascontiguousarray(g[r0:r1, c0:c1])
    labels_f, n = frontier_groups(
        w, frontiers.min_frontier_cells, frontiers.min_unknown_depth_cells
    )
    if n == 0 or (
        len(frontiers.excluded_xy_m) and not drop_excluded(labels_f, geometry, frontiers, (r0, c0))
    ):
        return None
    usable = usable_cells(w, clearance_field_m(w, res), clearance_m)
    regions, n_regions = ndimage.label(usable)
    if n_regions == 0:
        return None
    near = dilate(labels_f > 0, frontiers.reach_m / res) if frontiers.reach_m > 0 else labels_f > 0
    served = np.zeros(n_regions + 1, dtype=bool)
    served[np.unique(regions[near & usable])] = True
    sizes = np.bincount(regions.ravel(), minlength=n_regions + 1)
    room = served & (sizes >= max(1, int(min_room_cells)))
    room[0] = False
    start = search_start_cell(w, geometry, usable, start_xy_m, (r0, c0))
    if start is not None:
        room[regions[start]] = False
    if not room.any():
        return None
    goal = np.zeros(g.shape, dtype=bool)
    goal[r0:r1, c0:c1] = room[regions]
    return grid_path_to_mask(g, geometry, start_xy_m, goal, thin_m, thin_field)
