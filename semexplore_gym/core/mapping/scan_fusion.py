"""One compiled call per control step: cast a LiDAR scan and fuse it into an occupancy grid.

:class:`ScanFuser` does what :func:`~semexplore_gym.core.mapping.raycast.cast_scan`, the
sensor's range post-processing and :meth:`OccupancyGrid.integrate_scan` do one after the
other, with the same float operations in the same order (the scan and the map are
bit-identical), but in a single numba call on buffers allocated once:

* the beam directions (cos, sin) are computed once and shared by the caster and the map
  update when the map pose equals the sensor pose (no odometry noise);
* the inputs that never change (beam angles, ranges, parameters) are checked once, when the
  fuser is built, instead of at every scan; the pose is checked inside the kernel;
* other robots (:class:`~.disc_cast.DiscObstacles`) are cast in the same call, as
  :func:`~.disc_cast.cast_discs` after :func:`~.raycast.cast_scan` would (a team's step).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
import numpy.typing as npt
from numba import njit

from semexplore_gym.core.mapping.disc_cast import DiscObstacles, cast_discs_into
from semexplore_gym.core.mapping.occupancy_grid import OccupancyGrid, integrate_dirs
from semexplore_gym.core.mapping.raycast import SegmentIndex, cast_dirs


class ScanFootprint(NamedTuple):
    """Where a fused scan records the cells it updated: bit ``bit`` of ``bits`` (uint8, the
    grid's shape) is set in each, within the box of ``max_range_m`` plus one cell around the
    sensor (a team's overlap ratio counts the robots that scanned each cell)."""

    bits: np.ndarray
    bit: int


_NO_NOISE = np.zeros(0, dtype=np.float64)
_NO_DROPOUT = np.zeros(0, dtype=np.bool_)
_NO_DISCS = np.zeros((0, 2), dtype=np.float64)
_NO_FOOTPRINT = np.zeros((0, 0), dtype=np.uint8)


class ScanFuser:
    """Casts scans against one world's walls and fuses them into a grid, one call per scan.

    Args:
        index: The world's wall index.
        beam_angles_rad: ``(n,)`` finite beam angles relative to the heading.
        max_range_m: Sensor maximum range (no return reads as this).
        min_range_m: Returns closer than this read as 0 (invalid).

    Raises:
        ValueError: on non-finite beam angles or ranges out of order.
    """

    def __init__(
        self,
        index: SegmentIndex,
        beam_angles_rad: npt.ArrayLike,
        max_range_m: float,
        min_range_m: float,
    ) -> None:
        beams = np.ascontiguousarray(beam_angles_rad, dtype=np.float64)
        if beams.ndim != 1 or not np.isfinite(beams).all():
            raise ValueError("beam_angles_rad must be a 1-D array of finite angles")
        if not (math.isfinite(max_range_m) and 0 <= min_range_m < max_range_m):
            raise ValueError(
                f"need 0 <= min_range_m < max_range_m < inf, got {min_range_m!r}, {max_range_m!r}"
            )
        n = beams.shape[0]
        self.index = index
        self.beams = beams
        self.max_range_m = float(max_range_m)
        self._consts = np.array([max_range_m, min_range_m], dtype=np.float64)
        self._pose = np.empty(6, dtype=np.float64)
        self._dirs = np.empty((4, n), dtype=np.float64)
        self._cast = np.empty(n, dtype=np.float64)
        self._map_ranges = np.empty(n, dtype=np.float64)
        self._disc_t = np.empty(n, dtype=np.float64)

    @property
    def last_map_ranges(self) -> np.ndarray:
        """The ranges the latest :meth:`scan_and_integrate` fused into its grid (a buffer
        reused by the next call): to fuse the same scan into another grid."""
        return self._map_ranges

    def scan_and_integrate(
        self,
        grid: OccupancyGrid,
        sensor_pose: tuple[float, float, float],
        map_pose: tuple[float, float, float],
        noise_m: np.ndarray | None = None,
        dropped: np.ndarray | None = None,
        discs: DiscObstacles | None = None,
        footprint: ScanFootprint | None = None,
    ) -> np.ndarray:
        """Cast from ``sensor_pose``, fuse the scan into ``grid`` as seen from ``map_pose``.

        Args:
            grid: The grid to update.
            sensor_pose: True sensor ``(x_m, y_m, yaw_rad)``: where the rays are cast from.
            map_pose: Sensor pose the map is built with (the estimate under odometry noise).
            noise_m: Optional ``(n,)`` range noise added to every return.
            dropped: Optional ``(n,)`` bool, beams that return nothing valid.
            discs: Optional discs the rays also meet (other robots), as
                :func:`~.disc_cast.cast_discs` along the beams' directions.
            footprint: Optional record of the cells this scan updates.

        Returns:
            A new ``(n,)`` float32 scan: 0 = invalid, ``max_range_m`` = no return.
        """
        pose = self._pose
        pose[0], pose[1], pose[2] = sensor_pose
        pose[3], pose[4], pose[5] = map_pose
        scan = np.empty(self.beams.shape[0], dtype=np.float32)
        idx = self.index
        g = grid.geometry
        centres, radius, map_hits = _NO_DISCS, 0.0, True
        if discs is not None and len(discs.centres_m):
            centres = np.ascontiguousarray(discs.centres_m, dtype=np.float64).reshape(-1, 2)
            radius, map_hits = float(discs.radius_m), bool(discs.map_hits)
        bits, bit_value = _NO_FOOTPRINT, np.uint8(0)
        if footprint is not None:
            if footprint.bits.shape != grid._stamp.shape or footprint.bits.dtype != np.uint8:
                raise ValueError("footprint.bits must be a uint8 array of the grid's shape")
            bits, bit_value = footprint.bits, np.uint8(1 << int(footprint.bit))
        status, d_free, d_mask = _cast_and_integrate(
            idx.segments_m,
            idx.bucket_start,
            idx.bucket_items,
            idx.origin_x_m,
            idx.origin_y_m,
            idx.cell_size_m,
            idx.n_rows,
            idx.n_cols,
            pose,
            self.beams,
            self._consts,
            _NO_NOISE if noise_m is None else noise_m,
            _NO_DROPOUT if dropped is None else dropped,
            self._dirs,
            self._cast,
            self._map_ranges,
            scan,
            (centres, self._disc_t, radius, radius**2, map_hits),
            (bits, bit_value),
            grid._log_odds,
            grid._encoded,
            grid._stamp,
            grid._count_mask,
            grid._begin_scan(),
            g.origin_x_m,
            g.origin_y_m,
            g.resolution_m,
            grid._update_consts,
        )
        if status:
            raise ValueError(f"pose must be finite, got {sensor_pose!r} and {map_pose!r}")
        grid.n_free_cells += d_free
        grid.n_free_in_mask += d_mask
        return scan


@njit(cache=True, error_model="numpy")
def _cast_and_integrate(
    seg,
    bucket_start,
    bucket_items,
    bx0,
    by0,
    bcell,
    n_rows,
    n_cols,
    pose,
    beams,
    consts,
    noise,
    dropped,
    dirs,
    cast,
    map_ranges,
    scan,
    discs,
    footprint,
    log_odds,
    encoded,
    stamp,
    mask,
    scan_id,
    gx0,
    gy0,
    res,
    map_consts,
):  # pragma: no cover - numba
    """Returns (status, d_free, d_free_in_mask); status 1 = a pose value is not finite.

    ``discs`` = (centres (k, 2), scratch (n,), radius, its square, map hits): rays end on the nearer of a
    wall and a disc within ``max_range + radius`` of the sensor (cast along the same
    directions); with ``map hits`` false the beams that end on a disc are left out of the map. ``footprint`` = (bits, value): ``value``
    is or-ed into ``bits`` where the scan updated the grid (bits of shape (0, 0): none)."""
    for i in range(6):
        if not math.isfinite(pose[i]):
            return 1, 0, 0
    n = beams.shape[0]
    sx, sy, syaw = pose[0], pose[1], pose[2]
    mx, my, myaw = pose[3], pose[4], pose[5]
    max_r = consts[0]
    min_r = consts[1]
    for j in range(n):
        th = beams[j] + syaw
        dirs[0, j] = math.cos(th)
        dirs[1, j] = math.sin(th)
    cast_dirs(
        seg,
        bucket_start,
        bucket_items,
        bx0,
        by0,
        bcell,
        n_rows,
        n_cols,
        sx,
        sy,
        dirs[0],
        dirs[1],
        max_r,
        cast,
    )
    centres, disc_t, radius, r2, map_hits = discs
    near = np.empty(centres.shape[0], dtype=np.bool_)
    for k in range(centres.shape[0]):
        near[k] = math.hypot(centres[k, 0] - sx, centres[k, 1] - sy) < max_r + radius
    on_disc = near.any()
    if on_disc:
        for j in range(n):
            disc_t[j] = np.inf
        cast_discs_into(sx, sy, dirs[0], dirs[1], centres[near], r2, disc_t)
        for j in range(n):
            if disc_t[j] < cast[j]:
                cast[j] = disc_t[j]
            else:
                disc_t[j] = np.inf  # marks the beams that end on a wall
    # The sensor's post-processing (sim.lidar.Lidar.scan), in float64, then stored as float32.
    has_noise = noise.shape[0] == n
    has_drop = dropped.shape[0] == n
    for j in range(n):
        r = cast[j]
        if has_noise and math.isfinite(r):
            r = r + noise[j]
        if r > max_r:
            r = max_r
        if r < min_r or (has_drop and dropped[j]):
            r = 0.0
        scan[j] = np.float32(r)
        map_ranges[j] = np.float64(scan[j])
        if on_disc and not map_hits and disc_t[j] < np.inf:
            map_ranges[j] = 0.0
    if myaw == syaw:
        cos_m = dirs[0]
        sin_m = dirs[1]
    else:
        for j in range(n):
            th = myaw + beams[j]
            dirs[2, j] = math.cos(th)
            dirs[3, j] = math.sin(th)
        cos_m = dirs[2]
        sin_m = dirs[3]
    d_free, d_mask = integrate_dirs(
        log_odds,
        encoded,
        stamp,
        mask,
        scan_id,
        mx,
        my,
        cos_m,
        sin_m,
        map_ranges,
        max_r,
        gx0,
        gy0,
        res,
        map_consts,
    )
    bits, value = footprint
    if bits.shape[0] > 0:
        _mark_footprint(
            bits, value, stamp, scan_id, mx, my, cos_m, sin_m, map_ranges, max_r, gx0, gy0, res
        )
    return 0, d_free, d_mask


@njit(cache=True, error_model="numpy")
def _mark_footprint(
    bits, value, stamp, scan_id, mx, my, cos_m, sin_m, ranges, max_r, gx0, gy0, res
):  # pragma: no cover - numba
    """Or ``value`` into ``bits`` where ``stamp == scan_id``, in the box of ``max_r`` + one
    cell around the sensor ``(mx, my)``, looking only between the sensor and the beams' ends
    (the cells a scan updates lie there)."""
    height, width = stamp.shape
    reach = max_r + res
    r0 = max(0, int((my - reach - gy0) / res))
    r1 = min(height, int((my + reach - gy0) / res) + 2)
    c0 = max(0, int((mx - reach - gx0) / res))
    c1 = min(width, int((mx + reach - gx0) / res) + 2)
    xlo = xhi = mx
    ylo = yhi = my
    for j in range(ranges.shape[0]):
        r = ranges[j]
        if not (r > 0.0):
            continue
        t = r if r < max_r else max_r
        x = mx + t * cos_m[j]
        y = my + t * sin_m[j]
        xlo = min(xlo, x)
        xhi = max(xhi, x)
        ylo = min(ylo, y)
        yhi = max(yhi, y)
    r0 = max(r0, int(math.floor((ylo - gy0) / res)) - 2)
    r1 = min(r1, int(math.floor((yhi - gy0) / res)) + 3)
    c0 = max(c0, int(math.floor((xlo - gx0) / res)) - 2)
    c1 = min(c1, int(math.floor((xhi - gx0) / res)) + 3)
    sid = np.uint8(scan_id)
    zero = np.uint8(0)
    for r in range(r0, r1):
        srow = stamp[r, c0:c1]
        brow = bits[r, c0:c1]
        # Branch-free (all ones where stamped), so that the loop vectorises.
        for c in range(srow.shape[0]):
            brow[c] = brow[c] | ((zero - np.uint8(srow[c] == sid)) & value)
