"""Start poses and the area a robot can reach.

Clearances are exact distances from a point (a cell centre) to the nearest wall *segment*,
not raster distances, so they mean the same on every world and every grid.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt
from scipy import ndimage

from semexplore_gym.core.grid import GridGeometry
from semexplore_gym.core.worlds.geometry import (
    crossed_links,
    distance_to_segments_m,
    flood_fill_links,
    segment_distance_field,
)
from semexplore_gym.core.worlds.raster import rasterize_free
from semexplore_gym.core.worlds.world import World

_FOUR_CONNECTED = ndimage.generate_binary_structure(2, 1)


def _check_distance(name: str, value: float, allow_zero: bool = True) -> float:
    v = float(value)
    if not np.isfinite(v) or v < 0 or (v == 0 and not allow_zero):
        raise ValueError(
            f"{name} must be a {'non-negative' if allow_zero else 'positive'} finite distance, got {value!r}"
        )
    return v


def _start_cells(world: World, clearance_m: float) -> np.ndarray:
    """Flat indices (into ``world.free_mask``) of the largest 4-connected set of free cells whose
    centres are at least ``clearance_m`` from every wall."""
    geometry = world.free_geometry
    dist = segment_distance_field(world.segments_m, geometry, clearance_m + geometry.resolution_m)
    ok = world.free_mask & (dist >= clearance_m)
    labels, n = ndimage.label(ok, structure=_FOUR_CONNECTED)
    if n == 0:
        return np.zeros(0, dtype=np.int64)
    sizes = np.bincount(labels.ravel())
    sizes[0] = 0
    cells = np.flatnonzero(labels == int(np.argmax(sizes)))
    return cells.astype(np.int32) if ok.size < 2**31 else cells


def sample_start_pose(
    world: World, rng: np.random.Generator, clearance_m: float
) -> tuple[float, float, float]:
    """A random start pose at least ``clearance_m`` from every wall.

    The position is the centre of a cell drawn uniformly from the largest 4-connected set of
    free cells of ``world.free_mask`` whose centres have that clearance (so the robot does not
    start in a closet it cannot leave); the heading is uniform in ``[-pi, pi)``. The cell set
    is computed once per world and clearance and kept on the world.

    Args:
        world: The world.
        rng: Random source.
        clearance_m: Minimum distance from the robot centre to any wall (robot radius + margin).

    Returns:
        ``(x_m, y_m, yaw_rad)``.

    Raises:
        ValueError: no free cell has that clearance.
    """
    clearance_m = _check_distance("clearance_m", clearance_m)
    cells = world.derived(("start_cells", clearance_m), lambda: _start_cells(world, clearance_m))
    if cells.size == 0:
        raise ValueError(
            f"world {world.name!r} has no free cell with {clearance_m} m clearance from the walls"
        )
    k = cells[int(rng.integers(cells.size))]
    row, col = divmod(int(k), world.free_geometry.width)
    x, y = world.free_geometry.grid_to_world(row, col)
    yaw = float(rng.uniform(-np.pi, np.pi))
    return (float(x), float(y), yaw)


def validate_start_pose(
    world: World, pose: npt.ArrayLike, clearance_m: float
) -> tuple[float, float, float]:
    """Check that a start pose is usable and return it as three floats.

    Raises:
        ValueError (naming the pose): not three finite numbers, outside ``world.bounds_m``,
            not in free space (inside a wall or outside the building), or closer than
            ``clearance_m`` to a wall.
    """
    clearance_m = _check_distance("clearance_m", clearance_m)
    p = np.asarray(pose, dtype=np.float64).ravel() if pose is not None else np.zeros(0)
    if p.shape != (3,) or not np.isfinite(p).all():
        raise ValueError(f"start pose {pose!r} must be three finite numbers (x_m, y_m, yaw_rad)")
    x, y, yaw = (float(v) for v in p)
    xmin, ymin, xmax, ymax = world.bounds_m
    if not (xmin <= x <= xmax and ymin <= y <= ymax):
        raise ValueError(
            f"start pose ({x:g}, {y:g}, {yaw:g}) is outside the world bounds {world.bounds_m}"
        )
    row, col = world.free_geometry.world_to_grid(x, y)
    inside = bool(world.free_geometry.contains(row, col)) and bool(
        world.free_mask[int(row), int(col)]
    )
    dist = float(distance_to_segments_m([x, y], world.segments_m)[0])
    if not inside:
        raise ValueError(
            f"start pose ({x:g}, {y:g}, {yaw:g}) is not in free space of world {world.name!r} "
            f"(inside a wall or outside the building; nearest wall {dist:.3f} m)"
        )
    if dist < clearance_m:
        raise ValueError(
            f"start pose ({x:g}, {y:g}, {yaw:g}) is {dist:.3f} m from a wall, closer than clearance_m={clearance_m:g}"
        )
    return (x, y, yaw)


def reachable_free_mask(
    world: World,
    geometry: GridGeometry,
    start_xy_m: npt.ArrayLike,
    radius_m: float,
    clearance_m: float,
    *,
    free_mask: np.ndarray | None = None,
) -> np.ndarray:
    """The free cells a robot starting at ``start_xy_m`` can cover: the denominator of coverage.

    Let C be the free cells whose centres are at least ``clearance_m`` from every wall and that
    are 4-connected (without crossing a wall) to the start cell. The result is C dilated by
    ``radius_m - geometry.resolution_m`` (what the robot's body sweeps, less a one-cell band at
    the walls so that a perfect map can reach 100 %), intersected with the free raster.

    Args:
        world: The world.
        geometry: The grid to compute on (typically the env's map grid).
        start_xy_m: Start position ``(x, y)``.
        radius_m: Robot radius.
        clearance_m: Minimum centre-to-wall distance the robot keeps (radius + margin).
        free_mask: ``rasterize_free(world, geometry)`` if already computed.

    Returns:
        ``geometry.shape`` bool mask.

    Raises:
        ValueError: bad arguments, or no cell with the clearance within 1.5 cells of the start.
    """
    radius_m = _check_distance("radius_m", radius_m, allow_zero=False)
    clearance_m = _check_distance("clearance_m", clearance_m)
    start = np.asarray(start_xy_m, dtype=np.float64).ravel()
    if start.shape[0] < 2 or not np.isfinite(start[:2]).all():
        raise ValueError(f"start_xy_m must be a finite (x, y), got {start_xy_m!r}")
    sx, sy = float(start[0]), float(start[1])
    res = geometry.resolution_m
    if free_mask is None:
        free_mask = rasterize_free(world, geometry)
    elif free_mask.shape != geometry.shape:
        raise ValueError(f"free_mask shape {free_mask.shape} != geometry shape {geometry.shape}")
    dist = segment_distance_field(world.segments_m, geometry, clearance_m + res)
    allowed = free_mask & (dist >= clearance_m)

    h, w = geometry.shape
    seeds = _start_seeds(geometry, allowed, sx, sy)
    if not seeds.any():
        raise ValueError(
            f"start ({sx:g}, {sy:g}) has no free cell with {clearance_m:g} m wall clearance within 1.5 cells "
            f"on grid {geometry}"
        )
    if clearance_m > 0.5 * res * (1.0 + 1e-6):
        # Any link crossing a wall has an end within half a cell of it, so no allowed cells sit
        # on both sides of a wall: plain 4-connectivity is exact.
        cut_x = np.zeros((h, max(w - 1, 0)), dtype=bool)
        cut_y = np.zeros((max(h - 1, 0), w), dtype=bool)
    else:
        cut_x, cut_y = crossed_links(world.segments_m, geometry)
    component = flood_fill_links(allowed, cut_x, cut_y, seeds)

    grow_cells = (radius_m - res) / res
    if grow_cells <= 0:
        return component & free_mask
    rows = np.flatnonzero(component.any(axis=1))
    cols = np.flatnonzero(component.any(axis=0))
    pad = int(np.ceil(grow_cells)) + 1
    r0, r1 = max(0, rows[0] - pad), min(h, rows[-1] + 1 + pad)
    c0, c1 = max(0, cols[0] - pad), min(w, cols[-1] + 1 + pad)
    out = np.zeros((h, w), dtype=bool)
    out[r0:r1, c0:c1] = _dilate_disk(component[r0:r1, c0:c1], grow_cells)
    return out & free_mask


def _start_seeds(geometry: GridGeometry, allowed: np.ndarray, sx: float, sy: float) -> np.ndarray:
    """The start cell if allowed, else the allowed cells within 1.5 cells of the start."""
    h, w = geometry.shape
    res = geometry.resolution_m
    seeds = np.zeros((h, w), dtype=bool)
    row, col = (int(v) for v in geometry.world_to_grid(sx, sy))
    if 0 <= row < h and 0 <= col < w and allowed[row, col]:
        seeds[row, col] = True
    else:
        # The start may sit a fraction of a cell closer to a wall than its neighbours' centres.
        r0, r1 = max(0, row - 2), min(h, row + 3)
        c0, c1 = max(0, col - 2), min(w, col + 3)
        if r0 < r1 and c0 < c1:
            rr, cc = np.mgrid[r0:r1, c0:c1]
            xs, ys = geometry.grid_to_world(rr, cc)
            near = np.hypot(xs - sx, ys - sy) <= 1.5 * res
            seeds[r0:r1, c0:c1] = near & allowed[r0:r1, c0:c1]
    return seeds


def _dilate_disk(mask: np.ndarray, radius_cells: float) -> np.ndarray:
    """Cells whose centre is within ``radius_cells`` of a True cell's centre."""
    if radius_cells <= 8.0:
        # A small disk footprint is several times faster than a full distance transform.
        k = int(np.floor(radius_cells + 1e-9))
        yy, xx = np.mgrid[-k : k + 1, -k : k + 1]
        footprint = xx * xx + yy * yy <= radius_cells * radius_cells + 1e-9
        return ndimage.binary_dilation(mask, structure=footprint)
    return ndimage.distance_transform_edt(~mask) <= radius_cells + 1e-9
