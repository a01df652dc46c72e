"""Recovery manoeuvres: what a policy does once its :class:`ProgressWatch` says it is stuck.

* :class:`RotateRecovery`, move_base's ``rotate_recovery``: turn in place by a fixed angle
  (the :class:`~semexplore_gym.policies.navigation.navigator.Navigator` of the frontier baselines; it plans
  again afterwards and aborts the goal after ``max_recoveries``).
* :class:`BackoffRecovery`, the semantic expert's: back off for a fixed time, turning towards
  open space when the way back is blocked (the expert then blacklists the goal and replans).
"""

from __future__ import annotations

import math

import numpy as np

from semexplore_gym.core.grid import GridGeometry
from semexplore_gym.core.planning.potential_field import (
    PotentialFieldParams,
    RobotLimits,
    front_free_distance,
    nearby_obstacle_points,
)

__all__ = ["BackoffRecovery", "RotateRecovery"]

#: Free space behind the robot (metres) below which it turns instead of backing off.
_MIN_BACKOFF_ROOM_M = 0.05


class RotateRecovery:
    """Turn in place by ``angle_rad`` at ``angular_speed_radps`` (move_base ``rotate_recovery``).

    Args:
        angle_rad: Angle of one rotation (>= 0; 0 = no rotation).
        angular_speed_radps: Its angular speed, capped by the robot's at each :meth:`turn`.
    """

    def __init__(self, angle_rad: float, angular_speed_radps: float) -> None:
        self.angle_rad = float(angle_rad)
        self.angular_speed_radps = float(angular_speed_radps)
        self.left_rad = 0.0

    @property
    def active(self) -> bool:
        """Some of the rotation is left."""
        return self.left_rad > 0.0

    def start(self) -> None:
        """Begin a rotation."""
        self.left_rad = self.angle_rad

    def stop(self) -> None:
        """Drop what is left of the rotation."""
        self.left_rad = 0.0

    def turn(self, max_angular_speed_radps: float, dt_s: float) -> float:
        """The angular speed (rad/s) for the next ``dt_s``; counts that turn as done."""
        w = min(self.angular_speed_radps, max_angular_speed_radps)
        self.left_rad -= w * dt_s
        return w


class BackoffRecovery:
    """Back off for ``duration_s`` at ``speed_fraction`` of the top speed (the expert's).

    The speed is capped so that the robot can brake before the nearest obstacle behind it
    (scan and mapped walls, as the potential field's collision guard sees them); when there
    is no room behind, it turns towards the most open beam instead.

    Args:
        duration_s: Length of the manoeuvre (>= 0).
        speed_fraction: Back-off speed as a fraction of the top speed, in ``[0, 1]``.
    """

    def __init__(self, duration_s: float, speed_fraction: float) -> None:
        self.duration_s = float(duration_s)
        self.speed_fraction = float(speed_fraction)
        self.until_s = -1.0
        self.turn_sign = 0.0

    def start(self, now_s: float, rng: np.random.Generator) -> None:
        """Begin backing off at ``now_s``; ``rng`` picks the turn direction for a blind robot."""
        self.until_s = now_s + self.duration_s
        self.turn_sign = 1.0 if rng.random() < 0.5 else -1.0

    def active(self, now_s: float) -> bool:
        """The manoeuvre is still running at ``now_s``."""
        return now_s < self.until_s

    def finish(self) -> bool:
        """Once the manoeuvre is over: True the first time it is asked, then False."""
        if self.until_s > 0.0:
            self.until_s = -1.0
            return True
        return False

    def command(
        self,
        grid: np.ndarray,
        geometry: GridGeometry,
        pose: tuple[float, float, float],
        scan_m: np.ndarray,
        beam_angles_rad: np.ndarray,
        limits: RobotLimits,
        guard: PotentialFieldParams,
    ) -> tuple[float, float]:
        """``(v_mps, omega_radps)`` for this step.

        Args:
            grid: The occupancy grid observation.
            geometry: Its frame.
            pose: Robot ``(x_m, y_m, yaw_rad)``.
            scan_m: LiDAR ranges (0 = invalid).
            beam_angles_rad: Beam angles relative to the heading.
            limits: The robot's size, speeds and range.
            guard: The collision-guard margins and braking time of the potential field.
        """
        near = nearby_obstacle_points(grid, geometry, pose, guard.map_guard_radius_m)
        back = front_free_distance(
            scan_m,
            beam_angles_rad,
            limits.max_range_m,
            limits.radius_m + guard.safety_margin_m,
            backwards=True,
            contact_half_width_m=limits.radius_m + guard.contact_margin_m,
            extra_points_xy=near,
        )
        if back > _MIN_BACKOFF_ROOM_M:
            v = -self.speed_fraction * limits.max_linear_speed_mps
            v = max(v, -back / guard.braking_time_s)
            return v, 0.0
        # The way back is blocked too: turn towards the most open direction.
        ok = (scan_m > 0) & np.isfinite(scan_m)
        if not ok.any():
            return 0.0, self.turn_sign * 0.5 * limits.max_angular_speed_radps
        k = int(np.argmax(np.where(ok, scan_m, -1.0)))
        # In (-pi, pi]: the beam straight behind turns the robot left. wrap_angle_rad's
        # [-pi, pi) would turn it right, and differs from this in the last bit elsewhere.
        ang = math.atan2(math.sin(beam_angles_rad[k]), math.cos(beam_angles_rad[k]))
        return 0.0, float(
            np.clip(2.0 * ang, -limits.max_angular_speed_radps, limits.max_angular_speed_radps)
        )
