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

#: Most cells of a world's native raster (a map image, or the grid a vector world is
#: rasterised on): the env's own map check uses the same figure.
MAX_WORLD_CELLS = 40_000_000

#: Most wall segments a world may have (the largest real map we know has ~23 k). Each is a
#: pymunk shape and a LiDAR candidate; millions (a noise image) take minutes and gigabytes.
MAX_WALL_SEGMENTS = 200_000


class WorldTooLargeError(ValueError):
    """A world is beyond :data:`MAX_WORLD_CELLS` or :data:`MAX_WALL_SEGMENTS`; says what to do."""


def check_world_cells(name: str, n_rows: float, n_cols: float, resolution_m: float) -> None:
    """Refuse a raster of ``n_rows x n_cols`` cells beyond :data:`MAX_WORLD_CELLS`, before
    anything of that size is allocated."""
    cells = float(n_rows) * float(n_cols)
    if not np.isfinite(cells) or cells > MAX_WORLD_CELLS:
        raise WorldTooLargeError(
            f"world {name!r}: {n_cols:.0f} x {n_rows:.0f} cells at {resolution_m:g} m "
            f"({cells:.3g} cells) is more than the {MAX_WORLD_CELLS:,} cell limit; use a coarser "
            "resolution or crop the map"
        )


def count_wall_runs(free: np.ndarray) -> int:
    """Number of maximal wall segments :func:`raster_to_segments` would make of ``free``
    (counted with numpy, without building them)."""
    h, w = free.shape
    padded = np.zeros((h + 2, w + 2), dtype=bool)
    padded[1:-1, 1:-1] = free
    total = 0
    for a, b in ((padded[1:], padded[:-1]), (padded[:, 1:].T, padded[:, :-1].T)):
        for face in (a & ~b, b & ~a):  # the two orientations are separate segments
            starts = face.copy()
            starts[:, 1:] &= ~face[:, :-1]
            total += int(np.count_nonzero(starts))
    return total


def check_wall_segments(name: str, n_segments: int, resolution_m: float) -> None:
    """Refuse a world with more than :data:`MAX_WALL_SEGMENTS` wall segments."""
    if n_segments > MAX_WALL_SEGMENTS:
        raise WorldTooLargeError(
            f"world {name!r}: {n_segments:,} wall segments at {resolution_m:g} m is more than the "
            f"{MAX_WALL_SEGMENTS:,} limit (a noisy image?); clean the map (fewer specks), use a "
            "coarser resolution or crop it"
        )


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
    check_world_cells(name, free.shape[0], free.shape[1], geometry.resolution_m)
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
    check_wall_segments(name, count_wall_runs(cropped), res)
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
    check_wall_segments(name, segments.shape[0], resolution_m)
    bounds = _resolve_bounds(name, segments, bounds_m)
    check_world_cells(
        name,
        (bounds[3] - bounds[1]) / resolution_m + 3,
        (bounds[2] - bounds[0]) / resolution_m + 3,
        resolution_m,
    )
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
