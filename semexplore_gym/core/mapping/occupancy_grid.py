"""Log-odds occupancy mapping from 2-D LiDAR scans.

:class:`OccupancyGrid` keeps a float32 log-odds grid and, alongside it, the uint8 encoded
grid of :mod:`semexplore_gym.core.grid` (UNKNOWN / FREE / OCCUPIED) that the env returns as
its ``map`` observation. Both are updated only at the cells a scan touches, and so are the
free-cell counters used for coverage, so one 360-beam update costs well under a millisecond
even on large maps.

Update rule of one scan (:meth:`OccupancyGrid.integrate_scan`):

* Each beam is traced from the sensor with an exact grid traversal (Amanatides-Woo): every
  cell the beam's segment passes through, clipped at the grid border.
* A beam with range ``0`` or NaN is invalid and ignored. A beam with range ``>= max_range_m``
  (or inf) saw nothing: the cells along it up to ``max_range_m`` get the free update and no
  cell gets the occupied update. Otherwise the cell containing the end point gets the
  occupied update and the cells before it the free update.
* A cell is updated at most once per scan, and the occupied update wins over the free one
  (a beam grazing past another beam's end point does not erase it).
* Log-odds are clamped to ``[log_odds_min, log_odds_max]``. A cell is FREE when its log-odds
  is below ``free_threshold``, OCCUPIED when above ``occupied_threshold``, UNKNOWN otherwise
  (thresholds compared in float32, the dtype of the log-odds grid).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

import numpy as np
import numpy.typing as npt
from numba import njit

from semexplore_gym.core.grid import FREE, OCCUPIED, UNKNOWN, GridGeometry

# Stamps are uint8 (a small footprint keeps the grids in cache); they are cleared and the
# scan counter restarted every 255 scans.
_MAX_SCAN_ID = 255


@dataclass(frozen=True)
class MappingParams:
    """Parameters of the log-odds occupancy mapping.

    Attributes:
        resolution_m: Cell edge in metres.
        margin_m: Free border added around the world bounds when sizing the grid.
        log_odds_free: Increment for a cell a beam passed through (negative).
        log_odds_occupied: Increment for the cell a beam ended in (positive).
        log_odds_min: Lower clamp of the log-odds.
        log_odds_max: Upper clamp of the log-odds.
        free_threshold: Log-odds below this is FREE.
        occupied_threshold: Log-odds above this is OCCUPIED.
    """

    resolution_m: float = 0.05
    margin_m: float = 0.5
    log_odds_free: float = -0.4
    log_odds_occupied: float = 0.85
    log_odds_min: float = -4.0
    log_odds_max: float = 4.0
    free_threshold: float = -0.2
    occupied_threshold: float = 0.2

    def __post_init__(self) -> None:
        for f in fields(self):
            v = getattr(self, f.name)
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
                raise ValueError(f"MappingParams.{f.name} must be a finite number, got {v!r}")
        if not self.resolution_m > 0:
            raise ValueError(
                f"MappingParams.resolution_m must be positive, got {self.resolution_m!r}"
            )
        if self.margin_m < 0:
            raise ValueError(f"MappingParams.margin_m must be >= 0, got {self.margin_m!r}")
        if not self.log_odds_free < 0:
            raise ValueError(
                f"MappingParams.log_odds_free must be negative, got {self.log_odds_free!r}"
            )
        if not self.log_odds_occupied > 0:
            raise ValueError(
                f"MappingParams.log_odds_occupied must be positive, got {self.log_odds_occupied!r}"
            )
        if not self.log_odds_min < 0 < self.log_odds_max:
            raise ValueError(
                f"MappingParams.log_odds_min must be < 0 < log_odds_max, got log_odds_min={self.log_odds_min!r}, "
                f"log_odds_max={self.log_odds_max!r}"
            )
        if not self.log_odds_min <= self.free_threshold <= 0:
            raise ValueError(
                f"MappingParams.free_threshold must be in [log_odds_min, 0], got {self.free_threshold!r}"
            )
        if not 0 <= self.occupied_threshold <= self.log_odds_max:
            raise ValueError(
                f"MappingParams.occupied_threshold must be in [0, log_odds_max], got {self.occupied_threshold!r}"
            )
        if not self.free_threshold < self.occupied_threshold:
            raise ValueError(
                f"MappingParams.free_threshold ({self.free_threshold!r}) must be below "
                f"occupied_threshold ({self.occupied_threshold!r})"
            )

    def grid_geometry(self, bounds_m: tuple[float, float, float, float]) -> GridGeometry:
        """The map frame for a world: its bounds ``(xmin, ymin, xmax, ymax)`` plus ``margin_m``."""
        xmin, ymin, xmax, ymax = (float(v) for v in bounds_m)
        return GridGeometry.covering(xmin, ymin, xmax, ymax, self.resolution_m, self.margin_m)


class OccupancyGrid:
    """A log-odds occupancy grid with a live encoded view and free-cell counters.

    Args:
        geometry: Where the grid lies in the world (its resolution is used, not
            ``params.resolution_m``).
        params: Update and threshold parameters.
        count_mask: Optional ``(H, W)`` bool mask; ``n_free_in_mask`` counts the FREE cells
            inside it (the env passes the ground-truth free space to measure coverage).
            ``None`` counts every cell.

    Attributes:
        geometry: The grid frame.
        params: The mapping parameters.
        n_free_cells: Number of FREE cells.
        n_free_in_mask: Number of FREE cells inside ``count_mask``.
    """

    def __init__(
        self,
        geometry: GridGeometry,
        params: MappingParams | None = None,
        count_mask: npt.ArrayLike | None = None,
    ) -> None:
        if not isinstance(geometry, GridGeometry):
            raise TypeError(f"geometry must be a GridGeometry, got {type(geometry).__name__}")
        params = MappingParams() if params is None else params
        if not isinstance(params, MappingParams):
            raise TypeError(f"params must be MappingParams, got {type(params).__name__}")
        shape = geometry.shape
        if count_mask is None:
            mask = np.ones(shape, dtype=np.bool_)
        else:
            mask = np.asarray(count_mask)
            if mask.dtype != np.bool_:
                raise TypeError(f"count_mask must have dtype bool, got {mask.dtype}")
            if mask.shape != shape:
                raise ValueError(f"count_mask shape {mask.shape} != grid shape {shape}")
            mask = mask.copy()  # private: its flags are changed below
        self.geometry = geometry
        self.params = params
        self._count_mask = mask
        self._count_mask.flags.writeable = False
        self._n_mask_cells = int(mask.sum())
        self._log_odds = np.zeros(shape, dtype=np.float32)
        self._encoded = np.full(shape, UNKNOWN, dtype=np.uint8)
        self._stamp = np.zeros(shape, dtype=np.uint8)
        self._scan_id = 0
        self.n_free_cells = 0
        self.n_free_in_mask = 0
        f32 = np.float32
        self._update_consts = np.array(
            [
                params.log_odds_free,
                params.log_odds_occupied,
                params.log_odds_min,
                params.log_odds_max,
                params.free_threshold,
                params.occupied_threshold,
            ],
            dtype=f32,
        )

    def __setstate__(self, state: dict) -> None:
        self.__dict__.update(state)
        self._count_mask.flags.writeable = False

    def reset(self) -> None:
        """Forget everything: all cells UNKNOWN, counters zero."""
        self._log_odds.fill(0.0)
        self._encoded.fill(UNKNOWN)
        self._stamp.fill(0)
        self._scan_id = 0
        self.n_free_cells = 0
        self.n_free_in_mask = 0

    @property
    def log_odds(self) -> np.ndarray:
        """Read-only ``(H, W)`` float32 view of the log-odds."""
        v = self._log_odds.view()
        v.flags.writeable = False
        return v

    @property
    def encoded(self) -> np.ndarray:
        """Read-only live ``(H, W)`` uint8 view of the encoded grid (changes with every scan)."""
        v = self._encoded.view()
        v.flags.writeable = False
        return v

    @property
    def count_mask(self) -> np.ndarray:
        """Read-only ``(H, W)`` bool mask counted by ``n_free_in_mask``."""
        return self._count_mask

    @property
    def n_mask_cells(self) -> int:
        """Number of cells inside ``count_mask``."""
        return self._n_mask_cells

    @property
    def free_area_m2(self) -> float:
        """Area of the FREE cells in square metres."""
        return self.n_free_cells * self.geometry.resolution_m**2

    def encoded_copy(self) -> np.ndarray:
        """A fresh copy of the encoded grid (safe to hand out as an observation)."""
        return self._encoded.copy()

    def keep_encoded_in(self, buffer: np.ndarray) -> None:
        """Keep the encoded grid in ``buffer`` from now on (a vector env's batch row).

        ``buffer`` gets the current cells and every later update is written there; the
        previous array no longer changes. A no-op when ``buffer`` already holds the grid.

        Raises:
            ValueError: unless ``buffer`` is a writable C-contiguous uint8 array of the grid's shape.
        """
        if buffer is self._encoded:
            return
        if not (
            isinstance(buffer, np.ndarray)
            and buffer.dtype == np.uint8
            and buffer.shape == self._encoded.shape
            and buffer.flags.c_contiguous
            and buffer.flags.writeable
        ):
            raise ValueError(
                "buffer must be a writable C-contiguous uint8 array of shape "
                f"{self._encoded.shape}, got {type(buffer).__name__} of dtype "
                f"{getattr(buffer, 'dtype', None)} and shape {getattr(buffer, 'shape', None)}"
            )
        buffer[...] = self._encoded
        self._encoded = buffer

    def integrate_scan(
        self,
        x_m: float,
        y_m: float,
        yaw_rad: float,
        beam_angles_rad: npt.ArrayLike,
        ranges_m: npt.ArrayLike,
        max_range_m: float,
    ) -> int:
        """Fuse one LiDAR scan taken at pose ``(x_m, y_m, yaw_rad)`` into the map.

        Args:
            x_m: Sensor x in the map frame, metres.
            y_m: Sensor y in the map frame, metres.
            yaw_rad: Sensor heading, radians.
            beam_angles_rad: ``(n,)`` beam angles relative to the heading, counter-clockwise.
            ranges_m: ``(n,)`` measured ranges in metres: 0 or NaN = invalid (skipped),
                ``>= max_range_m`` or inf = no return (free up to ``max_range_m``).
            max_range_m: The sensor's maximum range in metres.

        Returns:
            The change of ``n_free_cells`` caused by this scan.

        Raises:
            ValueError: on a non-finite pose, a non-positive ``max_range_m``, negative
                ranges, or beam/range arrays that are not 1-D of the same length.
        """
        if not (math.isfinite(x_m) and math.isfinite(y_m) and math.isfinite(yaw_rad)):
            raise ValueError(f"pose must be finite, got ({x_m!r}, {y_m!r}, {yaw_rad!r})")
        max_range = float(max_range_m)
        if not (math.isfinite(max_range) and max_range > 0):
            raise ValueError(f"max_range_m must be a positive finite number, got {max_range_m!r}")
        beams = np.asarray(beam_angles_rad, dtype=np.float64)
        ranges = np.asarray(ranges_m, dtype=np.float64)
        if beams.ndim != 1 or ranges.ndim != 1 or beams.shape != ranges.shape:
            raise ValueError(
                f"beam_angles_rad and ranges_m must be 1-D of equal length, got shapes {beams.shape} and {ranges.shape}"
            )
        g = self.geometry
        status, d_free, d_free_mask = _integrate_kernel(
            self._log_odds,
            self._encoded,
            self._stamp,
            self._count_mask,
            self._begin_scan(),
            float(x_m),
            float(y_m),
            float(yaw_rad),
            beams,
            ranges,
            max_range,
            g.origin_x_m,
            g.origin_y_m,
            g.resolution_m,
            self._update_consts,
        )
        if status != 0:
            # The kernel checks before writing anything, so the map is unchanged.
            bad = beams if status == 1 else ranges
            k = int(np.argwhere(~np.isfinite(bad) if status == 1 else bad < 0)[0, 0])
            what = "beam_angles_rad" if status == 1 else "ranges_m"
            raise ValueError(
                f"{what}[{k}] = {float(bad[k])!r} is invalid ({'not finite' if status == 1 else 'negative'})"
            )
        self.n_free_cells += d_free
        self.n_free_in_mask += d_free_mask
        return int(d_free)

    def touched_by_last_scan(self, rows: slice, cols: slice) -> np.ndarray:
        """Bool mask of the cells in ``[rows, cols]`` that the latest scan updated."""
        return self._stamp[rows, cols] == self._scan_id

    def load_log_odds(self, log_odds: np.ndarray) -> None:
        """Replace the whole map by ``log_odds`` (``(H, W)``, e.g. a merged team map), in place.

        The encoded cells and both free-cell counters follow from the new log-odds (the
        thresholds of :attr:`params`); the scan stamps are kept.
        """
        if log_odds.shape != self._log_odds.shape:
            raise ValueError(
                f"log_odds must have shape {self._log_odds.shape}, got {log_odds.shape}"
            )
        p = self.params
        encoded = np.full(log_odds.shape, UNKNOWN, dtype=np.uint8)
        encoded[log_odds < p.free_threshold] = FREE
        encoded[log_odds > p.occupied_threshold] = OCCUPIED
        free = encoded == FREE
        self._log_odds[...] = log_odds
        self._encoded[...] = encoded
        self.n_free_cells = int(free.sum())
        self.n_free_in_mask = int(np.count_nonzero(free & self.count_mask))

    def _begin_scan(self) -> int:
        """The stamp of a new scan (stamps are cleared every ``_MAX_SCAN_ID`` scans)."""
        if self._scan_id >= _MAX_SCAN_ID:
            self._stamp.fill(0)
            self._scan_id = 0
        self._scan_id += 1
        return self._scan_id

    def __repr__(self) -> str:
        h, w = self.geometry.shape
        return f"OccupancyGrid({h}x{w} @ {self.geometry.resolution_m} m, free={self.n_free_cells})"


@njit(cache=True, error_model="numpy")
def _integrate_kernel(
    log_odds,
    encoded,
    stamp,
    mask,
    scan_id,
    ox,
    oy,
    yaw,
    beams,
    ranges,
    max_range,
    gx0,
    gy0,
    res,
    consts,
):  # pragma: no cover - numba
    """Returns (status, d_free, d_free_in_mask); status 1 = bad angle, 2 = negative range."""
    n = beams.shape[0]
    for j in range(n):
        if not math.isfinite(beams[j]):
            return 1, 0, 0
        if ranges[j] < 0.0:
            return 2, 0, 0
    cos_b = np.empty(n)
    sin_b = np.empty(n)
    for j in range(n):
        th = yaw + beams[j]
        cos_b[j] = math.cos(th)
        sin_b[j] = math.sin(th)
    d_free, d_mask = integrate_dirs(
        log_odds,
        encoded,
        stamp,
        mask,
        scan_id,
        ox,
        oy,
        cos_b,
        sin_b,
        ranges,
        max_range,
        gx0,
        gy0,
        res,
        consts,
    )
    return 0, d_free, d_mask


@njit(cache=True, error_model="numpy")
def integrate_dirs(
    log_odds,
    encoded,
    stamp,
    mask,
    scan_id,
    ox,
    oy,
    cos_b,
    sin_b,
    ranges,
    max_range,
    gx0,
    gy0,
    res,
    consts,
):  # pragma: no cover - numba
    """The update of one scan given each beam's world-frame direction; returns (d_free, d_mask).

    Inputs are trusted (checked by the caller): ranges >= 0 or NaN, directions finite. The grids
    are walked through flat views; each beam's traversal keeps the exact float operations of
    the Amanatides-Woo walk (the same cells for the same inputs, to the last bit).
    """
    n = cos_b.shape[0]
    height, width = log_odds.shape
    size = height * width
    lo = log_odds.reshape(size)
    enc = encoded.reshape(size)
    st = stamp.reshape(size)
    msk = mask.reshape(size)
    l_free = consts[0]
    l_occ = consts[1]
    l_min = consts[2]
    l_max = consts[3]
    thr_free = consts[4]
    thr_occ = consts[5]
    inv_res = 1.0 / res
    gx1 = gx0 + width * res
    gy1 = gy0 + height * res
    d_free = 0
    d_mask = 0
    sid = np.uint8(scan_id)

    # Pass 1: end-point cells first, so the occupied update wins within this scan.
    for j in range(n):
        r = ranges[j]
        if not (r > 0.0) or r >= max_range:
            continue
        fc = math.floor((ox + r * cos_b[j] - gx0) * inv_res)
        fr = math.floor((oy + r * sin_b[j] - gy0) * inv_res)
        if fc < 0 or fr < 0 or fc >= width or fr >= height:
            continue
        k = int(fr) * width + int(fc)
        if st[k] == sid:
            continue
        st[k] = sid
        a, b = _update_flat(lo, enc, msk, k, l_occ, l_min, l_max, thr_free, thr_occ)
        d_free += a
        d_mask += b

    # Pass 2: free cells along each beam, clipped to the grid box.
    for j in range(n):
        r = ranges[j]
        if not (r > 0.0):
            continue  # 0 or NaN: invalid return
        t1 = r if r < max_range else max_range
        dx = cos_b[j]
        dy = sin_b[j]
        t0 = 0.0
        ex = ox + t1 * dx
        ey = oy + t1 * dy
        if not (gx0 <= ox < gx1 and gy0 <= oy < gy1 and gx0 <= ex < gx1 and gy0 <= ey < gy1):
            # Liang-Barsky clip of t in [0, t1] to the grid box.
            if dx != 0.0:
                ta = (gx0 - ox) / dx
                tb = (gx1 - ox) / dx
                t0 = max(t0, min(ta, tb))
                t1 = min(t1, max(ta, tb))
            elif ox < gx0 or ox >= gx1:
                continue
            if dy != 0.0:
                ta = (gy0 - oy) / dy
                tb = (gy1 - oy) / dy
                t0 = max(t0, min(ta, tb))
                t1 = min(t1, max(ta, tb))
            elif oy < gy0 or oy >= gy1:
                continue
            if not t0 < t1:
                continue
        # Amanatides-Woo traversal; t is the distance from the sensor.
        col = min(max(int(math.floor((ox + t0 * dx - gx0) * inv_res)), 0), width - 1)
        row = min(max(int(math.floor((oy + t0 * dy - gy0) * inv_res)), 0), height - 1)
        if dx != 0.0:
            inv_dx = 1.0 / dx
            step_c = 1 if dx > 0.0 else -1
            t_next_x = (gx0 + (col + (1 if dx > 0.0 else 0)) * res - ox) * inv_dx
            t_dx = res * abs(inv_dx)
        else:
            step_c = 0
            t_next_x = np.inf
            t_dx = 0.0
        if dy != 0.0:
            inv_dy = 1.0 / dy
            step_r = 1 if dy > 0.0 else -1
            t_next_y = (gy0 + (row + (1 if dy > 0.0 else 0)) * res - oy) * inv_dy
            t_dy = res * abs(inv_dy)
        else:
            step_r = 0
            t_next_y = np.inf
            t_dy = 0.0
        # The walk leaves the grid when col or row would; the last column/row it may enter.
        col_end = width if step_c > 0 else -1
        row_end = height if step_r > 0 else -1
        k = row * width + col
        step_k = step_r * width
        while True:
            if st[k] != sid:
                st[k] = sid
                a, b = _update_flat(lo, enc, msk, k, l_free, l_min, l_max, thr_free, thr_occ)
                d_free += a
                d_mask += b
            if t_next_x < t_next_y:
                if t_next_x >= t1:
                    break
                col += step_c
                if col == col_end:
                    break
                k += step_c
                t_next_x += t_dx
            else:
                if t_next_y >= t1:
                    break
                row += step_r
                if row == row_end:
                    break
                k += step_k
                t_next_y += t_dy
    return d_free, d_mask


@njit(cache=True, inline="always", error_model="numpy")
def _update_flat(
    lo, enc, msk, k, delta, l_min, l_max, thr_free, thr_occ
):  # pragma: no cover - numba
    """Add ``delta`` to flat cell ``k``; return the changes of (n_free, n_free_in_mask)."""
    v = min(max(lo[k] + delta, l_min), l_max)
    lo[k] = v
    new = FREE if v < thr_free else (OCCUPIED if v > thr_occ else UNKNOWN)
    old = enc[k]
    if new == old:
        return 0, 0
    enc[k] = new
    d = 0
    if old == FREE:
        d = -1
    elif new == FREE:
        d = 1
    if msk[k]:
        return d, d
    return d, 0
