"""Build a :class:`World` from a free-space raster or from wall segments."""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from semexplore_gym.core.grid import GridGeometry
from semexplore_gym.core.worlds.geometry import as_segments, segments_bounds_m
from semexplore_gym.core.worlds.raster import (
    raster_to_segments,
    rasterize_free,
    remove_small_free_components,
)
from semexplore_gym.core.worlds.world import World

#: Free components smaller than this many cells are dropped from raster maps (see
#: :func:`~semexplore_gym.core.worlds.raster.remove_small_free_components`).
DEFAULT_MIN_FREE_CELLS = 4

#: Native resolution of the free mask of vector worlds (mazes, caves, HouseExpo JSON).
DEFAULT_VECTOR_RESOLUTION_M = 0.025


def _resolve_bounds(
    name: str, segments: np.ndarray, bounds_m: tuple[float, float, float, float] | None
) -> tuple[float, float, float, float]:
    """The walls' box, or ``bounds_m`` after checking that it contains them (up to rounding)."""
    tight = segments_bounds_m(segments)
    if bounds_m is None:
        return tight
    b = tuple(float(v) for v in bounds_m)
    if len(b) != 4 or not np.isfinite(b).all():
        raise ValueError(f"world {name!r}: bounds_m must be four finite numbers, got {bounds_m!r}")
    tol = 1e-9 * max(1.0, *(abs(v) for v in tight))
    if (
        b[0] > tight[0] + tol
        or b[1] > tight[1] + tol
        or b[2] < tight[2] - tol
        or b[3] < tight[3] - tol
    ):
        raise ValueError(f"world {name!r}: bounds_m {b} does not contain the walls' box {tight}")
    return (min(b[0], tight[0]), min(b[1], tight[1]), max(b[2], tight[2]), max(b[3], tight[3]))


def world_from_free_mask(
    name: str,
    free_mask: npt.ArrayLike,
    geometry: GridGeometry,
    *,
    start_pose: tuple[float, float, float] | None = None,
    metadata: dict | None = None,
    min_free_cells: int = DEFAULT_MIN_FREE_CELLS,
    bounds_m: tuple[float, float, float, float] | None = None,
) -> World:
    """A raster world: walls along every free / non-free cell edge of ``free_mask``.

    Free components smaller than ``min_free_cells`` cells are dropped first. The stored
    ``free_mask`` is cropped to the free cells plus a one-cell non-free border (on the same
    cell lattice as the input), and ``bounds_m`` is the box of the walls unless given (a
    generator may fix it so that every seed gives the same box).

    Raises:
        ValueError: if no free cell is left.
    """
    free = np.asarray(free_mask, dtype=bool)
    if free.shape != geometry.shape:
        raise ValueError(
            f"world {name!r}: free_mask shape {free.shape} != geometry shape {geometry.shape}"
        )
    free = remove_small_free_components(free, min_free_cells)
    if not free.any():
        raise ValueError(
            f"world {name!r}: the map has no free space (after dropping specks < {min_free_cells} cells)"
        )
    rows = np.flatnonzero(free.any(axis=1))
    cols = np.flatnonzero(free.any(axis=0))
    r0, r1 = int(rows[0]), int(rows[-1]) + 1
    c0, c1 = int(cols[0]), int(cols[-1]) + 1
    cropped = np.zeros((r1 - r0 + 2, c1 - c0 + 2), dtype=bool)
    cropped[1:-1, 1:-1] = free[r0:r1, c0:c1]
    res = geometry.resolution_m
    crop_geometry = GridGeometry(
        res,
        geometry.origin_x_m + (c0 - 1) * res,
        geometry.origin_y_m + (r0 - 1) * res,
        cropped.shape[0],
        cropped.shape[1],
    )
    segments = raster_to_segments(cropped, crop_geometry)
    return World(
        name=name,
        segments_m=segments,
        bounds_m=_resolve_bounds(name, segments, bounds_m),
        free_mask=cropped,
        free_geometry=crop_geometry,
        start_pose=start_pose,
        metadata=dict(metadata or {}),
        free_space_source="raster",
    )


def world_from_segments(
    name: str,
    segments_m: npt.ArrayLike,
    interior_points_m: npt.ArrayLike,
    *,
    resolution_m: float = DEFAULT_VECTOR_RESOLUTION_M,
    start_pose: tuple[float, float, float] | None = None,
    metadata: dict | None = None,
    bounds_m: tuple[float, float, float, float] | None = None,
) -> World:
    """A vector world: given walls, with free space found by flood fill from interior points.

    The native ``free_mask`` is :func:`~semexplore_gym.core.worlds.raster.rasterize_free` on a
    grid of ``resolution_m`` covering ``bounds_m`` (default: the walls' box) plus one cell.

    Raises:
        ValueError: if the walls are empty or no interior point lands in free space.
    """
    segments = as_segments(segments_m)
    if segments.shape[0] == 0:
        raise ValueError(f"world {name!r}: no wall segments")
    bounds = _resolve_bounds(name, segments, bounds_m)
    geometry = GridGeometry.covering(*bounds, resolution_m=resolution_m, margin_m=resolution_m)
    free = rasterize_free(segments, geometry, interior_points_m=interior_points_m)
    if not free.any():
        raise ValueError(f"world {name!r}: no interior point lies in free space")
    return World(
        name=name,
        segments_m=segments,
        bounds_m=bounds,
        free_mask=free,
        free_geometry=geometry,
        start_pose=start_pose,
        metadata=dict(metadata or {}),
        free_space_source="vector",
    )
