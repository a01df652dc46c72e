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

import math
from typing import Any

import numpy as np

from semexplore_gym.core.features.egocentric_kernels import crop_kernel, encode_kernel, min_pool
from semexplore_gym.core.features.egocentric_params import CHANNELS, N_FEATURES, EgocentricParams
from semexplore_gym.core.frontiers.distance import (
    FrontierDistanceField,
    frontier_distance_m,
    relative_distance_image,
)
from semexplore_gym.core.grid import UNKNOWN, GridGeometry, validate_encoded_grid

__all__ = [
    "CHANNELS",
    "N_FEATURES",
    "EgocentricEncoder",
    "EgocentricParams",
    "egocentric_features",
    "mirror_observations",
]

# Stand-ins for the frontier field and the trail when their channel is off (never read; the
# kernel is compiled once for these types).
_NO_FIELD = np.full(1, np.inf)
_NO_TRAIL = np.full((1, 1), 255, np.uint8)


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
        crop_kernel(
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
        min_pool(grid, self._pool, self._pooled)
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
        encode_kernel(
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
