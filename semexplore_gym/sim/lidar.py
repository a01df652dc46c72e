"""The simulated 2D LiDAR (LDS-01-like) on the robot."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from semexplore_gym.core.mapping.disc_cast import DiscObstacles
from semexplore_gym.core.mapping.occupancy_grid import OccupancyGrid
from semexplore_gym.core.mapping.raycast import SegmentIndex, cast_scan
from semexplore_gym.core.mapping.scan_fusion import ScanFootprint, ScanFuser


@dataclass(frozen=True)
class LidarParams:
    """A 360-degree scanning range finder; defaults follow the ROBOTIS LDS-01.

    Attributes:
        n_beams: Beams per scan, evenly spaced over 360 degrees, beam 0 straight ahead,
            counter-clockwise.
        min_range_m: Returns closer than this are invalid (reported as 0).
        max_range_m: Farthest return; no hit within it is reported as ``max_range_m``.
        range_noise_std_m: Standard deviation of additive Gaussian range noise.
        dropout_prob: Probability that a beam returns nothing valid (reported as 0).
        mount_x_m: Sensor position ahead of the robot centre, in the robot frame.
        mount_y_m: Sensor position to the left of the robot centre, in the robot frame.
    """

    n_beams: int = 360
    min_range_m: float = 0.12
    max_range_m: float = 3.5
    range_noise_std_m: float = 0.0
    dropout_prob: float = 0.0
    mount_x_m: float = 0.0
    mount_y_m: float = 0.0

    def __post_init__(self) -> None:
        if not (4 <= self.n_beams <= 4096):
            raise ValueError(f"lidar.n_beams must be in 4..4096, got {self.n_beams!r}")
        if not (math.isfinite(self.max_range_m) and self.max_range_m > 0):
            raise ValueError(f"lidar.max_range_m must be positive, got {self.max_range_m!r}")
        if not (0 <= self.min_range_m < self.max_range_m):
            raise ValueError(
                f"lidar.min_range_m must be in [0, max_range_m), got {self.min_range_m!r}"
            )
        if not (0 <= self.range_noise_std_m <= 1.0):
            raise ValueError(
                f"lidar.range_noise_std_m must be in [0, 1] m, got {self.range_noise_std_m!r}"
            )
        if not (0 <= self.dropout_prob < 1):
            raise ValueError(f"lidar.dropout_prob must be in [0, 1), got {self.dropout_prob!r}")
        if math.hypot(self.mount_x_m, self.mount_y_m) > 0.5:
            raise ValueError(
                f"lidar mount offset ({self.mount_x_m}, {self.mount_y_m}) m is implausibly far from the robot centre"
            )

    @property
    def angle_increment_rad(self) -> float:
        return 2.0 * math.pi / self.n_beams

    def beam_angles_rad(self) -> np.ndarray:
        return np.arange(self.n_beams, dtype=np.float64) * self.angle_increment_rad


class Lidar:
    """Casts one scan against a world's wall segments.

    Args:
        params: Sensor parameters.
        index: Spatial index of the world's wall segments (built once per world).
    """

    def __init__(self, params: LidarParams, index: SegmentIndex) -> None:
        self.params = params
        self.index = index
        self.beam_angles_rad = params.beam_angles_rad()
        self._fuser = ScanFuser(index, self.beam_angles_rad, params.max_range_m, params.min_range_m)

    def sensor_pose(self, x_m: float, y_m: float, yaw_rad: float) -> tuple[float, float, float]:
        p = self.params
        c, s = math.cos(yaw_rad), math.sin(yaw_rad)
        return (
            x_m + c * p.mount_x_m - s * p.mount_y_m,
            y_m + s * p.mount_x_m + c * p.mount_y_m,
            yaw_rad,
        )

    def scan(self, x_m: float, y_m: float, yaw_rad: float, rng: np.random.Generator) -> np.ndarray:
        """Ranges (float32, metres) from the robot pose: 0 = invalid, ``max_range_m`` = no return."""
        p = self.params
        sx, sy, syaw = self.sensor_pose(x_m, y_m, yaw_rad)
        ranges = cast_scan(self.index, sx, sy, syaw, self.beam_angles_rad, p.max_range_m)
        if p.range_noise_std_m > 0:
            no_return = ~np.isfinite(ranges)
            ranges = ranges + rng.normal(0.0, p.range_noise_std_m, size=ranges.shape)
            ranges[no_return] = np.inf
        np.minimum(ranges, p.max_range_m, out=ranges)  # no return (inf) -> max_range_m
        invalid = ranges < p.min_range_m
        if p.dropout_prob > 0:
            invalid |= rng.random(ranges.shape) < p.dropout_prob
        ranges[invalid] = 0.0
        return ranges.astype(np.float32)

    def sense_and_map(
        self,
        true_pose: tuple[float, float, float],
        map_pose: tuple[float, float, float] | np.ndarray,
        grid: OccupancyGrid,
        rng: np.random.Generator,
        discs: DiscObstacles | None = None,
        footprint: ScanFootprint | None = None,
    ) -> np.ndarray:
        """:meth:`scan` at ``true_pose`` fused into ``grid`` from ``map_pose``, in one call.

        The same scan, the same random draws and the same map as :meth:`scan` followed by
        ``grid.integrate_scan`` at the sensor pose of ``map_pose``. ``discs``: other robots
        the beams also meet (:class:`~semexplore_gym.core.mapping.disc_cast.DiscObstacles`);
        ``footprint``: where to record the cells the scan updates
        (:class:`~semexplore_gym.core.mapping.scan_fusion.ScanFootprint`).
        """
        p = self.params
        n = p.n_beams
        noise = rng.normal(0.0, p.range_noise_std_m, size=n) if p.range_noise_std_m > 0 else None
        dropped = rng.random(n) < p.dropout_prob if p.dropout_prob > 0 else None
        return self._fuser.scan_and_integrate(
            grid,
            self.sensor_pose(*true_pose),
            self.sensor_pose(*map_pose),
            noise,
            dropped,
            discs,
            footprint,
        )

    @property
    def last_map_ranges(self) -> np.ndarray:
        """The ranges :meth:`sense_and_map` last fused into its grid (reused by the next call)."""
        return self._fuser.last_map_ranges
