"""Egocentric features for learning agents: a heading-up map crop, a pooled scan, features.

The canonical observation of ``SemanticExplore-v0`` is the whole occupancy grid in the map
frame, whose shape depends on the world. Neural policies want a fixed-size, robot-centred
input instead. :class:`EgocentricObservation` turns the canonical observation into::

    =========  ===================  =======  ========  ======================================
    key        shape                dtype    range     meaning
    =========  ===================  =======  ========  ======================================
    image      (1, crop, crop)      uint8    0..255    map crop around the robot, heading up
                                                       (row 0 = ahead), OCCUPIED=0,
                                                       UNKNOWN=128, FREE=255; unknown outside
                                                       the map
    scan       (n_scan_bins,)       float32  [0, 1]    LiDAR min-pooled per angular bin /
                                                       max_range_m; bin 0 starts at the
                                                       heading, counter-clockwise
    features   (3,)                 float32  [0, 1]    known fraction of the crop, free
                                                       fraction of the crop, fraction of
                                                       scan bins with no return in range
    =========  ===================  =======  ========  ======================================

Everything is computed from the observation alone (never from ground truth such as
``info["coverage"]``), so a scripted expert can label any visited state and a trained model can
run on raw observations through :func:`egocentric_features`. The image is channel-first uint8,
which SB3's ``MultiInputPolicy`` recognises as an image and feeds to its CNN.
"""

from __future__ import annotations

import dataclasses
import json
import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numba import njit

from semexplore_gym.core.grid import FREE, UNKNOWN, GridGeometry

#: Number of scalar features in the ``features`` entry.
N_FEATURES = 3

_UNKNOWN_U8 = np.uint8(UNKNOWN)


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
    """

    crop_cells: int = 64
    crop_resolution_m: float | None = 0.1
    n_scan_bins: int = 60

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

    def to_dict(self) -> dict[str, Any]:
        return dataclasses.asdict(self)

    @classmethod
    def from_dict(cls, d: dict[str, Any] | None) -> EgocentricParams:
        d = dict(d or {})
        names = {f.name for f in dataclasses.fields(cls)}
        unknown = sorted(set(d) - names)
        if unknown:
            raise ValueError(f"unknown egocentric parameter(s) {unknown}; valid: {sorted(names)}")
        return cls(**d)

    def to_json(self) -> str:
        return json.dumps(self.to_dict(), sort_keys=True)


@njit(cache=True)
def _crop_kernel(
    grid, x_cells, y_cells, cos_y, sin_y, cells_per_crop_cell, k, out
):  # pragma: no cover
    """Fill ``out`` (c, c) with the min over k x k samples per crop cell of the rotated map.

    Crop row 0 lies farthest ahead of the robot and crop column 0 farthest to its left; the
    robot sits at the centre of the crop. Samples outside the map read as UNKNOWN.
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
                val = _UNKNOWN_U8
            j = v // k
            if val < out[i, j]:
                out[i, j] = val


class EgocentricEncoder:
    """Precomputed sampling pattern that maps raw observations to egocentric ones.

    Build once per (params, map geometry, LiDAR); :meth:`encode` then costs a few vectorised
    numpy operations per observation.

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
        # Sub-samples per crop cell side: enough that no map cell falls between samples.
        self.supersample = max(1, math.ceil(res_crop / res_map - 1e-9))
        self._cells_per_crop_cell = res_crop / res_map

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

    def crop(self, grid: np.ndarray, x_m: float, y_m: float, yaw_rad: float) -> np.ndarray:
        """Heading-up crop ``(crop, crop)`` uint8 of encoded ``grid`` around pose (x, y, yaw)."""
        g = self.geometry
        if grid.shape != g.shape:
            raise ValueError(f"map has shape {grid.shape} but the encoder was built for {g.shape}")
        out = np.empty((self.params.crop_cells, self.params.crop_cells), dtype=np.uint8)
        _crop_kernel(
            np.ascontiguousarray(grid, dtype=np.uint8),
            (x_m - g.origin_x_m) / g.resolution_m,
            (y_m - g.origin_y_m) / g.resolution_m,
            math.cos(yaw_rad),
            math.sin(yaw_rad),
            self._cells_per_crop_cell,
            self.supersample,
            out,
        )
        return out

    def pool_scan(self, scan: np.ndarray) -> np.ndarray:
        """Min-pool the scan into ``n_scan_bins`` bins, normalised to [0, 1] by max range."""
        if scan.shape != (self.n_beams,):
            raise ValueError(
                f"scan has shape {scan.shape} but the encoder expects ({self.n_beams},)"
            )
        # 0 marks an invalid return (too close or dropout): it carries no range, so ignore it.
        r = np.where(scan > 0.0, scan, self.max_range_m).astype(np.float32)
        pooled = r.reshape(self.params.n_scan_bins, -1).min(axis=1)
        return np.clip(pooled / np.float32(self.max_range_m), 0.0, 1.0).astype(np.float32)

    def encode(self, obs: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
        """Egocentric observation dict (``image``, ``scan``, ``features``) for a raw observation."""
        try:
            grid, pose, scan = obs["map"], obs["pose"], obs["scan"]
        except (KeyError, TypeError) as e:
            raise ValueError(
                f"obs must be the env's observation dict with map, pose, scan; got {type(obs).__name__}"
            ) from e
        x_m, y_m, yaw_rad = (float(v) for v in np.asarray(pose).reshape(-1)[:3])
        crop = self.crop(np.asarray(grid), x_m, y_m, yaw_rad)
        n = crop.size
        known_crop = np.count_nonzero(crop != UNKNOWN) / n
        free_crop = np.count_nonzero(crop == FREE) / n
        pooled = self.pool_scan(np.asarray(scan, dtype=np.float32))
        open_bins = np.count_nonzero(pooled >= 1.0) / pooled.size
        return {
            "image": crop[None],
            "scan": pooled,
            "features": np.array([known_crop, free_crop, open_bins], dtype=np.float32),
        }


def egocentric_features(
    obs: dict[str, np.ndarray], info_static: dict[str, Any], params: EgocentricParams | None = None
) -> dict[str, np.ndarray]:
    """Egocentric observation for one raw observation (a pure function of its inputs).

    Args:
        obs: The env's observation dict (``map``, ``pose``, ``scan``).
        info_static: An env ``info`` dict, or any dict with its ``map_geometry`` and ``lidar``.
        params: Crop and scan settings (defaults of :class:`EgocentricParams` when None).

    Returns:
        ``{"image": uint8 (1, crop, crop), "scan": float32 (n_scan_bins,), "features": float32 (3,)}``.

    For many observations build an :class:`EgocentricEncoder` once instead.
    """
    return EgocentricEncoder.from_info(params or EgocentricParams(), info_static).encode(obs)
