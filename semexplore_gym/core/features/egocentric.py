"""Egocentric features for learning agents: a heading-up map crop, a pooled scan, features.

The canonical observation of ``SemanticExplore-v0`` is the whole occupancy grid in the map
frame, whose shape depends on the world. Neural policies want a fixed-size, robot-centred
input instead. :class:`EgocentricObservation` turns the canonical observation into::

    =========  ===================  =======  ========  ======================================
    key        shape                dtype    range     meaning
    =========  ===================  =======  ========  ======================================
    image      (C, crop, crop)      uint8    0..255    crops around the robot, heading up
                                                       (row 0 = ahead), one per entry of
                                                       ``params.channels`` (below)
    scan       (n_scan_bins,)       float32  [0, 1]    LiDAR min-pooled per angular bin /
                                                       max_range_m; bin 0 starts at the
                                                       heading, counter-clockwise
    features   (3,)                 float32  [0, 1]    known fraction of the crop, free
                                                       fraction of the crop, fraction of
                                                       scan bins with no return in range
    =========  ===================  =======  ========  ======================================

Image channels (``EgocentricParams.channels``; the default is ``("occupancy",)``):

- ``occupancy``: the map, OCCUPIED=0, UNKNOWN=128, FREE=255; unknown outside the map.
- ``frontier_distance``: path length through known free space (cells at least
  ``frontier_clearance_m`` from every wall) to the nearest frontier cell (a FREE cell with an
  UNKNOWN 4-neighbour), *relative to the robot's own*: ``128 + distance_scale_per_m * (d - d_robot)``
  clipped to [0, 254]; 255 where no frontier can be reached (walls, unknown space, outside the
  map, or no frontier left). Values below 128 lie downhill, towards the nearest frontier.
- ``trail``: 0 where the robot has been during the episode (a disc of ``trail_radius_m`` round
  every encoded pose), 255 elsewhere. This channel needs the pose history, so an encoder is
  stateful: call :meth:`EgocentricEncoder.reset` (or build a new one) at every episode start.

Everything is computed from the observation alone (never from ground truth such as
``info["coverage"]``), so a scripted expert can label any visited state and a trained model can
run on raw observations through :func:`egocentric_features`. The image is channel-first uint8,
which SB3's ``MultiInputPolicy`` recognises as an image and feeds to its CNN.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numba import njit

from semexplore_gym.core.frontiers.distance import (
    FrontierDistanceField,
    frontier_distance_m,
    relative_distance_image,
)
from semexplore_gym.core.grid import FREE, UNKNOWN, GridGeometry, validate_encoded_grid

#: Number of scalar features in the ``features`` entry.
N_FEATURES = 3

#: Image channels an :class:`EgocentricEncoder` can produce (see the module docstring).
CHANNELS: tuple[str, ...] = ("occupancy", "frontier_distance", "trail")

# Stand-ins for the frontier field and the trail when their channel is off (never read; the
# kernel is compiled once for these types).
_NO_FIELD = np.full(1, np.inf)
_NO_TRAIL = np.full((1, 1), 255, np.uint8)


@dataclass(frozen=True)
class EgocentricParams:
    """How the egocentric observation is built.

    Attributes:
        crop_cells: Side of the square map crop, in crop cells (the image is crop x crop).
        crop_resolution_m: Side of one crop cell in metres; None uses the map resolution.
            When coarser than the map, each crop cell takes the minimum over the map cells it
            covers (OCCUPIED < UNKNOWN < FREE), so thin walls are never lost.
        n_scan_bins: Number of angular bins the scan is min-pooled into; must divide the
            number of beams.
        channels: Image channels, in order (names from :data:`CHANNELS`, no repeats).
        frontier_clearance_m: ``frontier_distance`` paths keep at least this far from walls.
        distance_scale_per_m: ``frontier_distance`` grey levels per metre of path length.
        trail_radius_m: Radius of the ``trail`` disc stamped round every pose.
        scan_bins_centred: Centre scan bin 0 on the heading (beams ``-k//2 .. k - k//2 - 1``
            for ``k`` beams per bin) instead of starting it there. With an odd ``k`` the pooled
            scan then mirrors exactly under a left-right flip (bin ``b`` <-> bin ``-b``).
        pool_map: Min-pool the map to the crop resolution first (blocks of ``f x f`` map cells,
            ``f = crop_resolution_m / map resolution``, which must be a whole number; cells
            beyond the map read UNKNOWN), then search the frontier field, stamp the trail and
            sample each crop cell once on that coarser grid. About 2.5x cheaper than sampling
            ``f x f`` points of the rotated full-resolution map per crop cell (False), and a
            slightly different image: a crop cell is the minimum over the axis-aligned block its
            centre falls in. Models record the setting; the default (False) is what models
            trained before it used.
    """

    crop_cells: int = 64
    crop_resolution_m: float | None = 0.1
    n_scan_bins: int = 60
    channels: tuple[str, ...] = ("occupancy",)
    frontier_clearance_m: float = 0.1
    distance_scale_per_m: float = 20.0
    trail_radius_m: float = 0.1
    scan_bins_centred: bool = False
    pool_map: bool = False

    def __post_init__(self) -> None:
        if (
            not isinstance(self.crop_cells, int)
            or isinstance(self.crop_cells, bool)
            or not 8 <= self.crop_cells <= 512
        ):
            raise ValueError(f"crop_cells must be an integer in [8, 512], got {self.crop_cells!r}")
        if self.crop_resolution_m is not None and not (
            isinstance(self.crop_resolution_m, (int, float))
            and math.isfinite(self.crop_resolution_m)
            and self.crop_resolution_m > 0
        ):
            raise ValueError(
                f"crop_resolution_m must be a positive number or None, got {self.crop_resolution_m!r}"
            )
        if (
            not isinstance(self.n_scan_bins, int)
            or isinstance(self.n_scan_bins, bool)
            or self.n_scan_bins < 1
        ):
            raise ValueError(f"n_scan_bins must be a positive integer, got {self.n_scan_bins!r}")
        if isinstance(self.channels, str) or not isinstance(self.channels, (tuple, list)):
            raise ValueError(f"channels must be a tuple of channel names, got {self.channels!r}")
        # Lists arrive from YAML/JSON; store a tuple so the parameters stay hashable.
        object.__setattr__(self, "channels", tuple(self.channels))
        bad = [c for c in self.channels if c not in CHANNELS]
        if bad or not self.channels or len(set(self.channels)) != len(self.channels):
            raise ValueError(
                f"channels must be distinct names from {list(CHANNELS)}, got {list(self.channels)}"
            )
        for name in ("frontier_clearance_m", "distance_scale_per_m", "trail_radius_m"):
            v = getattr(self, name)
            if not (isinstance(v, (int, float)) and math.isfinite(v) and v >= 0):
                raise ValueError(f"{name} must be a finite number >= 0, got {v!r}")
        if not isinstance(self.scan_bins_centred, bool):
            raise ValueError(f"scan_bins_centred must be a bool, got {self.scan_bins_centred!r}")
        if not isinstance(self.pool_map, bool):
            raise ValueError(f"pool_map must be a bool, got {self.pool_map!r}")
        if self.pool_map and self.crop_resolution_m is None:
            raise ValueError("pool_map needs crop_resolution_m (a multiple of the map resolution)")

    @property
    def n_channels(self) -> int:
        return len(self.channels)

    def to_dict(self) -> dict[str, Any]:
        d = dataclasses.asdict(self)
        d["channels"] = list(self.channels)
        return d

    @classmethod
    def from_dict(cls, d: dict[str, Any] | None) -> EgocentricParams:
        d = dict(d or {})
        names = {f.name for f in dataclasses.fields(cls)}
        unknown = sorted(set(d) - names)
        if unknown:
            raise ValueError(f"unknown egocentric parameter(s) {unknown}; valid: {sorted(names)}")
        return cls(**d)


@njit(cache=True)
def _crop_kernel(
    grid, x_cells, y_cells, cos_y, sin_y, cells_per_crop_cell, k, out, fill
):  # pragma: no cover
    """Fill ``out`` (c, c) with the min over k x k samples per crop cell of the rotated map.

    Crop row 0 lies farthest ahead of the robot and crop column 0 farthest to its left; the
    robot sits at the centre of the crop. Samples outside the map read as ``fill``.
    """
    c = out.shape[0]
    n = c * k
    h, w = grid.shape
    step = cells_per_crop_cell / k
    centre = (n - 1) / 2.0
    # Fine sample (u, v) sits centre-u steps ahead and centre-v steps left of the robot; walk
    # the lattice by increments instead of recomputing the rotation per sample.
    du_x, du_y = -step * cos_y, -step * sin_y
    dv_x, dv_y = step * sin_y, -step * cos_y
    x00 = x_cells + centre * step * cos_y - centre * step * sin_y
    y00 = y_cells + centre * step * sin_y + centre * step * cos_y
    out[:, :] = 255
    for u in range(n):
        xs = x00 + u * du_x
        ys = y00 + u * du_y
        i = u // k
        for v in range(n):
            xf = xs + v * dv_x
            yf = ys + v * dv_y
            if xf >= 0.0 and yf >= 0.0 and xf < w and yf < h:
                val = grid[int(yf), int(xf)]
            else:
                val = fill
            j = v // k
            if val < out[i, j]:
                out[i, j] = val


@njit(cache=True)
def _stamp_disc(trail, r0, c0, radius_cells):  # pragma: no cover - numba
    h, w = trail.shape
    rad = int(math.ceil(radius_cells))
    for dr in range(-rad, rad + 1):
        for dc in range(-rad, rad + 1):
            if dr * dr + dc * dc <= radius_cells * radius_cells + 1e-9:
                r, c = r0 + dr, c0 + dc
                if 0 <= r < h and 0 <= c < w:
                    trail[r, c] = 0


@njit(cache=True)
def _robot_distance(dp, wp, h, w, row, col):  # pragma: no cover - numba
    """Frontier distance of the robot's cell ``(row, col)`` in the padded flat field ``dp``.

    The cell's own when in the map and finite, else the smallest finite one in the 5 x 5 window
    round it (clipped to the map), else 0: as :func:`relative_distance_image`.
    """
    if 0 <= row < h and 0 <= col < w:
        d = dp[(row + 1) * wp + col + 1]
        if d < np.inf:
            return d
    best = np.inf
    for r in range(max(0, row - 2), min(h, max(0, row + 3))):
        for c in range(max(0, col - 2), min(w, max(0, col + 3))):
            d = dp[(r + 1) * wp + c + 1]
            if d < best:
                best = d
    return best if best < np.inf else 0.0


@njit(cache=True)
def _encode_kernel(
    grid,
    dp,
    wp,
    trail,
    x_cells,
    y_cells,
    cos_y,
    sin_y,
    cells_per_crop_cell,
    k,
    ch_occ,
    ch_fd,
    ch_trail,
    trail_radius_cells,
    scale,
    scan,
    max_range,
    shift,
    image,
    pooled,
    features,
):  # pragma: no cover - numba
    """One egocentric observation: stamp the trail, crop every channel, pool the scan.

    The crops sample the rotated map exactly as :func:`_crop_kernel` does (same lattice, same
    floating-point operations, min over ``k`` x ``k`` samples per crop cell), reading the map,
    the frontier field ``dp`` (padded flat, row stride ``wp``) and the trail at each sample
    once. The frontier channel takes the minimum *distance* per crop cell and maps it to grey
    levels afterwards: the mapping is non-decreasing (255 for ``inf`` above every finite level),
    so this equals the minimum of the mapped map-frame layer. A channel index < 0 skips it.
    """
    h, w = grid.shape
    row = int(math.floor(y_cells))
    col = int(math.floor(x_cells))
    if ch_trail >= 0:
        _stamp_disc(trail, row, col, trail_radius_cells)
    d_robot = _robot_distance(dp, wp, h, w, row, col) if ch_fd >= 0 else 0.0
    c = image.shape[1]
    n = c * k
    step = cells_per_crop_cell / k
    centre = (n - 1) / 2.0
    du_x, du_y = -step * cos_y, -step * sin_y
    dv_x, dv_y = step * sin_y, -step * cos_y
    x00 = x_cells + centre * step * cos_y - centre * step * sin_y
    y00 = y_cells + centre * step * sin_y + centre * step * cos_y
    unknown = np.uint8(UNKNOWN)
    n_known = 0
    n_free = 0
    for i in range(c):
        for j in range(c):
            occ = np.uint8(255)
            tr = np.uint8(255)
            dmin = np.inf
            for a in range(k):
                u = i * k + a
                xs = x00 + u * du_x
                ys = y00 + u * du_y
                for b in range(k):
                    v = j * k + b
                    xf = xs + v * dv_x
                    yf = ys + v * dv_y
                    if xf >= 0.0 and yf >= 0.0 and xf < w and yf < h:
                        r = int(yf)
                        cc = int(xf)
                        g = grid[r, cc]
                        if g < occ:
                            occ = g
                        if ch_fd >= 0:
                            d = dp[(r + 1) * wp + cc + 1]
                            if d < dmin:
                                dmin = d
                        if ch_trail >= 0:
                            t = trail[r, cc]
                            if t < tr:
                                tr = t
                    elif unknown < occ:
                        occ = unknown  # outside the map: unknown (and 255 for the others)
            if occ != UNKNOWN:
                n_known += 1
                if occ == FREE:
                    n_free += 1
            if ch_occ >= 0:
                image[ch_occ, i, j] = occ
            if ch_trail >= 0:
                image[ch_trail, i, j] = tr
            if ch_fd >= 0:
                if dmin < np.inf:
                    lv = np.rint(128.0 + scale * (dmin - d_robot))
                    image[ch_fd, i, j] = np.uint8(min(max(lv, 0.0), 254.0))
                else:
                    image[ch_fd, i, j] = 255
    # The scan: invalid returns (0: too close or dropout) read as max range; bin b pools beams
    # b * per - shift .. (b + 1) * per - shift - 1 (np.roll by shift, then consecutive beams).
    n_beams = scan.shape[0]
    n_bins = pooled.shape[0]
    per = n_beams // n_bins
    mr = np.float32(max_range)
    n_open = 0
    for b in range(n_bins):
        m = np.float32(np.inf)
        for q in range(b * per, (b + 1) * per):
            x = scan[(q - shift) % n_beams]
            if not x > 0.0:
                x = mr
            if x < m:
                m = x
        p = np.float32(m / mr)
        p = min(max(p, np.float32(0.0)), np.float32(1.0))
        pooled[b] = p
        if p >= 1.0:
            n_open += 1
    n_cells = c * c
    features[0] = n_known / n_cells
    features[1] = n_free / n_cells
    features[2] = n_open / n_bins


@njit(cache=True)
def _min_pool(grid, f, out):  # pragma: no cover - numba
    """``out[r, c]`` = min of ``grid[f r : f r + f, f c : f c + f]``; cells beyond the map read
    UNKNOWN (OCCUPIED < UNKNOWN < FREE: a wall anywhere in the block wins)."""
    h, w = grid.shape
    ho, wo = out.shape
    hf, wf = h // f, w // f  # whole blocks
    out[:, :] = 255
    # Row by row, then column blocks: each map row read once, in order.
    for r in range(hf * f):
        src = grid[r]
        dst = out[r // f]
        if f == 2:  # the common case (0.1 m crops of a 0.05 m map), in a loop that vectorises
            for co in range(wf):
                dst[co] = min(dst[co], min(src[2 * co], src[2 * co + 1]))
        else:
            for co in range(wf):
                m = dst[co]
                for k in range(f):
                    m = min(m, src[co * f + k])
                dst[co] = m
        for c in range(wf * f, w):  # a partial block at the right edge
            dst[wf] = min(dst[wf], src[c])
    for r in range(hf * f, h):  # a partial block row at the top
        src = grid[r]
        dst = out[hf]
        for c in range(w):
            dst[c // f] = min(dst[c // f], src[c])
    unknown = np.uint8(UNKNOWN)
    if w % f:
        for ro in range(ho):
            out[ro, wo - 1] = min(out[ro, wo - 1], unknown)
    if h % f:
        for co in range(wo):
            out[ho - 1, co] = min(out[ho - 1, co], unknown)


class EgocentricEncoder:
    """Precomputed sampling pattern that maps raw observations to egocentric ones.

    Build once per (params, map geometry, LiDAR); :meth:`encode` then costs one fused kernel
    per observation (every channel's crop, the trail stamp, the pooled scan, the features),
    plus, with a ``frontier_distance`` channel, the frontier search when the map changed since
    the previous call (its buffers are kept between calls). With a ``trail`` channel the encoder
    remembers the poses it encoded: call :meth:`reset` at the start of every episode.

    Args:
        params: Crop and scan settings.
        geometry: The map's grid geometry (``info["map_geometry"]``).
        max_range_m: LiDAR maximum range, used to normalise the scan.
        n_beams: Number of LiDAR beams; ``params.n_scan_bins`` must divide it.
    """

    def __init__(
        self, params: EgocentricParams, geometry: GridGeometry, max_range_m: float, n_beams: int
    ) -> None:
        if not (
            isinstance(max_range_m, (int, float)) and math.isfinite(max_range_m) and max_range_m > 0
        ):
            raise ValueError(f"max_range_m must be a positive number, got {max_range_m!r}")
        if n_beams % params.n_scan_bins != 0:
            raise ValueError(
                f"n_scan_bins={params.n_scan_bins} must divide the number of beams {n_beams}"
            )
        self.params = params
        self.geometry = geometry
        self.max_range_m = float(max_range_m)
        self.n_beams = int(n_beams)
        res_map = geometry.resolution_m
        res_crop = params.crop_resolution_m or res_map
        # The grid the crops sample: the map, or its min-pooled blocks (params.pool_map).
        self._pool = 1
        self._sampled = geometry
        if params.pool_map:
            ratio = res_crop / res_map
            self._pool = round(ratio)
            if self._pool < 1 or abs(ratio - self._pool) > 1e-6:
                raise ValueError(
                    f"pool_map needs crop_resolution_m ({res_crop}) to be a whole multiple of "
                    f"the map resolution ({res_map})"
                )
            f = self._pool
            self._sampled = GridGeometry(
                res_map * f,
                geometry.origin_x_m,
                geometry.origin_y_m,
                -(-geometry.height // f),
                -(-geometry.width // f),
            )
            self._pooled = np.empty(self._sampled.shape, np.uint8)
            # Sub-samples per crop cell side: one, on the pooled grid.
            self.supersample = 1
            self._cells_per_crop_cell = 1.0
        else:
            # Sub-samples per crop cell side: enough that no map cell falls between samples.
            self.supersample = max(1, math.ceil(res_crop / res_map - 1e-9))
            self._cells_per_crop_cell = res_crop / res_map
        channels = params.channels
        self._ch_occ, self._ch_fd, self._ch_trail = (
            channels.index(name) if name in channels else -1 for name in CHANNELS
        )
        self._scan_shift = (n_beams // params.n_scan_bins) // 2 if params.scan_bins_centred else 0
        self._trail_radius_cells = params.trail_radius_m / self._sampled.resolution_m
        self._field: FrontierDistanceField | None = None
        self._trail: np.ndarray | None = None
        self.reset()

    def __getstate__(self) -> dict[str, Any]:
        # The frontier field is a cache with large search buffers: rebuilt on first use.
        state = self.__dict__.copy()
        state["_field"] = None
        return state

    def reset(self) -> None:
        """Forget the pose history (the ``trail`` channel); call at every episode start."""
        self._trail = (
            np.full(self._sampled.shape, 255, np.uint8) if "trail" in self.params.channels else None
        )

    @classmethod
    def from_info(cls, params: EgocentricParams, info: dict[str, Any]) -> EgocentricEncoder:
        """Build from an env ``info`` dict (uses ``map_geometry`` and ``lidar``)."""
        try:
            geometry = GridGeometry.from_dict(info["map_geometry"])
            lidar = info["lidar"]
            return cls(params, geometry, float(lidar["max_range_m"]), int(lidar["n_beams"]))
        except KeyError as e:
            raise ValueError(
                f"info lacks {e.args[0]!r}; pass the info dict returned by the env's reset/step"
            ) from e

    def matches(self, info: dict[str, Any]) -> bool:
        """True when this encoder was built for the geometry and LiDAR described by ``info``."""
        lidar = info.get("lidar", {})
        return (
            info.get("map_geometry") == self.geometry.to_dict()
            and lidar.get("max_range_m") == self.max_range_m
            and lidar.get("n_beams") == self.n_beams
        )

    def crop(
        self, grid: np.ndarray, x_m: float, y_m: float, yaw_rad: float, fill: int = UNKNOWN
    ) -> np.ndarray:
        """Heading-up crop ``(crop, crop)`` uint8 of ``grid`` around pose (x, y, yaw).

        Samples outside the map read as ``fill``. With ``pool_map`` the crop samples the
        pooled map, as :meth:`encode` does.
        """
        if grid.shape != self.geometry.shape:
            raise ValueError(
                f"map has shape {grid.shape} but the encoder was built for {self.geometry.shape}"
            )
        grid, g = self.sampled_grid(np.ascontiguousarray(grid, dtype=np.uint8))
        out = np.empty((self.params.crop_cells, self.params.crop_cells), dtype=np.uint8)
        _crop_kernel(
            grid,
            (x_m - g.origin_x_m) / g.resolution_m,
            (y_m - g.origin_y_m) / g.resolution_m,
            math.cos(yaw_rad),
            math.sin(yaw_rad),
            self._cells_per_crop_cell,
            self.supersample,
            out,
            np.uint8(fill),
        )
        return out

    def sampled_grid(self, grid: np.ndarray) -> tuple[np.ndarray, GridGeometry]:
        """The grid the crops and the frontier field read, and its geometry: ``grid`` (a
        contiguous uint8 map of the encoder's shape) itself, or (``pool_map``) its min-pooled
        blocks, in a buffer the next call overwrites."""
        if self._pool == 1:
            return grid, self.geometry
        _min_pool(grid, self._pool, self._pooled)
        return self._pooled, self._sampled

    def pool_scan(self, scan: np.ndarray) -> np.ndarray:
        """Min-pool the scan into ``n_scan_bins`` bins, normalised to [0, 1] by max range."""
        if scan.shape != (self.n_beams,):
            raise ValueError(
                f"scan has shape {scan.shape} but the encoder expects ({self.n_beams},)"
            )
        # 0 marks an invalid return (too close or dropout): it carries no range, so ignore it.
        r = np.where(scan > 0.0, scan, self.max_range_m).astype(np.float32)
        if self.params.scan_bins_centred:
            r = np.roll(r, (self.n_beams // self.params.n_scan_bins) // 2)
        pooled = r.reshape(self.params.n_scan_bins, -1).min(axis=1)
        return np.clip(pooled / np.float32(self.max_range_m), 0.0, 1.0).astype(np.float32)

    def frontier_distance_image(self, grid: np.ndarray, x_m: float, y_m: float) -> np.ndarray:
        """``(H, W)`` uint8 map-frame ``frontier_distance`` layer (relative to the robot's cell);
        with ``pool_map``, of the pooled map (the grid :meth:`encode` searches)."""
        p = self.params
        grid, g = self.sampled_grid(np.ascontiguousarray(grid, dtype=np.uint8))
        dist = frontier_distance_m(grid, g.resolution_m, p.frontier_clearance_m)
        row, col = (int(v) for v in g.world_to_grid(x_m, y_m))
        return relative_distance_image(dist, row, col, p.distance_scale_per_m)

    def encode(self, obs: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
        """Egocentric observation dict (``image``, ``scan``, ``features``) for a raw observation."""
        try:
            grid, pose, scan = obs["map"], obs["pose"], obs["scan"]
        except (KeyError, TypeError) as e:
            raise ValueError(
                f"obs must be the env's observation dict with map, pose, scan; got {type(obs).__name__}"
            ) from e
        x_m, y_m, yaw_rad = np.asarray(pose).reshape(-1)[:3].tolist()
        g = self.geometry
        if not (type(grid) is np.ndarray and grid.dtype == np.uint8 and grid.flags.c_contiguous):
            grid = np.asarray(grid)
            if self._ch_fd >= 0 and grid.dtype != np.uint8:
                validate_encoded_grid(grid)  # raises naming the dtype
            grid = np.ascontiguousarray(grid, dtype=np.uint8)
        if grid.shape != g.shape:
            raise ValueError(f"map has shape {grid.shape} but the encoder was built for {g.shape}")
        if not (type(scan) is np.ndarray and scan.dtype == np.float32):
            scan = np.ascontiguousarray(scan, dtype=np.float32)
        if scan.shape != (self.n_beams,):
            raise ValueError(
                f"scan has shape {scan.shape} but the encoder expects ({self.n_beams},)"
            )
        grid, g = self.sampled_grid(grid)
        if self._ch_fd >= 0:
            if self._field is None:
                self._field = FrontierDistanceField(
                    g.shape, g.resolution_m, self.params.frontier_clearance_m
                )
            self._field.update(grid)
            dp, wp = self._field.dist_padded, self._field.row_stride
        else:
            dp, wp = _NO_FIELD, 0
        c = self.params.crop_cells
        image = np.empty((self.params.n_channels, c, c), np.uint8)
        pooled = np.empty(self.params.n_scan_bins, np.float32)
        features = np.empty(N_FEATURES, np.float32)
        _encode_kernel(
            grid, dp, wp, _NO_TRAIL if self._trail is None else self._trail,
            (x_m - g.origin_x_m) / g.resolution_m, (y_m - g.origin_y_m) / g.resolution_m,
            math.cos(yaw_rad), math.sin(yaw_rad), self._cells_per_crop_cell, self.supersample,
            self._ch_occ, self._ch_fd, self._ch_trail, self._trail_radius_cells,
            float(self.params.distance_scale_per_m), scan, self.max_range_m, self._scan_shift,
            image, pooled, features,
        )  # fmt: skip
        # Fresh arrays every call: recorders keep them (a dataset is a list of these).
        return {"image": image, "scan": pooled, "features": features}


def mirror_observations(
    obs: dict[str, np.ndarray], actions: np.ndarray, params: EgocentricParams
) -> tuple[dict[str, np.ndarray], np.ndarray]:
    """Left-right mirror images of a batch of egocentric observations and their actions.

    The crops are flipped left-right (crop column 0 is farthest to the robot's left, and the
    robot sits on the centre column, so this is the crop of the mirrored world), the scan bins
    are reversed about the heading (bin ``b`` -> bin ``-b``), the angular velocity is negated and
    the scalar features (crop fractions, share of open bins) are unchanged.

    Args:
        obs: Batched egocentric observations (sample axis first).
        actions: ``(N, 2)`` actions ``(linear, angular)``.
        params: Their parameters; ``scan_bins_centred`` must be True with an odd number of
            beams per bin, else the mirrored scan would be off by one beam.

    Raises:
        ValueError: the scan encoding does not mirror exactly.
    """
    if not params.scan_bins_centred:
        raise ValueError(
            "mirror augmentation needs egocentric.scan_bins_centred=true (bins centred on the heading)"
        )
    n_bins = obs["scan"].shape[-1]
    out = dict(obs)
    out["image"] = np.ascontiguousarray(obs["image"][..., ::-1])
    out["scan"] = np.ascontiguousarray(obs["scan"][..., (-np.arange(n_bins)) % n_bins])
    act = np.array(actions, dtype=np.float32, copy=True)
    act[:, 1] = -act[:, 1]
    return out, act


def egocentric_features(
    obs: dict[str, np.ndarray], info_static: dict[str, Any], params: EgocentricParams | None = None
) -> dict[str, np.ndarray]:
    """Egocentric observation for one raw observation (a pure function of its inputs).

    Args:
        obs: The env's observation dict (``map``, ``pose``, ``scan``).
        info_static: An env ``info`` dict, or any dict with its ``map_geometry`` and ``lidar``.
        params: Crop and scan settings (defaults of :class:`EgocentricParams` when None).

    Returns:
        ``{"image": uint8 (C, crop, crop), "scan": float32 (n_scan_bins,), "features": float32 (3,)}``.

    For many observations build an :class:`EgocentricEncoder` once instead.
    """
    return EgocentricEncoder.from_info(params or EgocentricParams(), info_static).encode(obs)
