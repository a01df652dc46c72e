"""Slow, exact path tracking for passages barely wider than the robot.

A potential field balances the two walls of a gap that is a few centimetres wider than the
robot and stalls there; a follower that knows its path is clear (a privileged planner on the
true map, or a path planned on a clearance grid) can instead track the path's centre line
closely and slowly. :func:`tight_tracking_command` is a pure-pursuit step with a short
lookahead that turns on the spot (safe for a round differential-drive robot) whenever the
heading error is large, so the body never sweeps sideways into a wall. For a follower that
knows the walls only from a map (within a cell), :func:`scan_centring_offset_m` measures from
the scan how far it sits off the middle between the walls on both sides of its path, and
:func:`safe_forward_speed_mps` bounds a step so that no scan return comes within a few
millimetres of the body.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = [
    "TightTracking",
    "path_clearance_ahead_m",
    "path_heading_rad",
    "safe_forward_speed_mps",
    "scan_centring_offset_m",
    "tight_tracking_command",
]


def path_clearance_ahead_m(
    clearance_m: np.ndarray,
    rows: np.ndarray,
    cols: np.ndarray,
) -> float:
    """Smallest wall clearance (metres) over the cells ``(rows, cols)`` of a path stretch;
    ``inf`` for an empty stretch."""
    if rows.size == 0:
        return math.inf
    return float(np.min(clearance_m[rows, cols]))


def path_heading_rad(path_m: np.ndarray, index: int) -> float:
    """Direction (world frame) of ``path_m`` at point ``index`` (from the point before it, or
    to the point after it at the start); 0 for a single point."""
    p = np.asarray(path_m, dtype=np.float64)
    if p.shape[0] < 2:
        return 0.0
    i = min(max(int(index), 1), p.shape[0] - 1)
    return math.atan2(float(p[i, 1] - p[i - 1, 1]), float(p[i, 0] - p[i - 1, 0]))


@dataclass(frozen=True)
class TightTracking:
    """How :func:`tight_tracking_command` tracks a path.

    Attributes:
        lookahead_m: Aim at the first path point at least this far from the robot.
        speed_mps: Forward speed (scaled by the cosine of the heading error).
        max_omega_radps: Turn-rate limit.
        turn_in_place_rad: Above this heading error the robot only turns.
        heading_gain: Turn rate per radian of heading error.
    """

    lookahead_m: float
    speed_mps: float
    max_omega_radps: float
    turn_in_place_rad: float
    heading_gain: float = 2.0

    def __post_init__(self) -> None:
        for name in ("lookahead_m", "speed_mps", "max_omega_radps", "turn_in_place_rad"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0):
                raise ValueError(f"{name} must be positive, got {value!r}")


def tight_tracking_command(
    pose: tuple[float, float, float],
    path_m: np.ndarray,
    start_index: int,
    tracking: TightTracking,
    lateral_shift_m: float = 0.0,
) -> tuple[float, float]:
    """One pure-pursuit step along ``path_m`` (``(n, 2)`` metres) from ``start_index``.

    The target is the first path point at least ``tracking.lookahead_m`` from the robot (the
    path's last point near its end). With a heading error above ``tracking.turn_in_place_rad``
    the robot turns on the spot; otherwise it drives at ``tracking.speed_mps`` scaled by the
    cosine of the error and steers with ``tracking.heading_gain`` times the error.
    ``lateral_shift_m`` moves the target that far to the path's left (negative: right), e.g.
    by :func:`scan_centring_offset_m`, to keep the robot centred between walls measured more
    exactly than the path was planned.

    Returns:
        ``(v_mps, omega_radps)``.

    Raises:
        ValueError: An empty path.
    """
    path = np.asarray(path_m, dtype=np.float64)
    if path.ndim != 2 or path.shape[0] == 0 or path.shape[1] != 2:
        raise ValueError(f"path_m must be a non-empty (n, 2) array, got shape {path.shape}")
    t = tracking
    x, y, yaw = pose
    tail = path[min(max(int(start_index), 0), path.shape[0] - 1) :]
    d = np.hypot(tail[:, 0] - x, tail[:, 1] - y)
    far = np.flatnonzero(d >= t.lookahead_m)
    k = int(far[0]) if far.size else tail.shape[0] - 1
    target = tail[k]
    heading = path_heading_rad(tail, k)
    dx = float(target[0] - x) - lateral_shift_m * math.sin(heading)
    dy = float(target[1] - y) + lateral_shift_m * math.cos(heading)
    if math.hypot(dx, dy) < 1e-9:
        return 0.0, 0.0
    err = math.atan2(dy, dx) - yaw
    err = math.atan2(math.sin(err), math.cos(err))
    omega = float(np.clip(t.heading_gain * err, -t.max_omega_radps, t.max_omega_radps))
    if abs(err) > t.turn_in_place_rad:
        return 0.0, omega
    return t.speed_mps * math.cos(err), omega


def _angle_within(a: np.ndarray, centre_rad: float, halfwidth_rad: float) -> np.ndarray:
    d = np.mod(a - centre_rad + math.pi, 2.0 * math.pi) - math.pi
    return np.abs(d) <= halfwidth_rad


def scan_centring_offset_m(
    scan_m: np.ndarray,
    angles_rad: np.ndarray,
    *,
    min_range_m: float,
    reach_m: float,
    left_rad: float = 0.5 * math.pi,
    side_halfwidth_rad: float = math.pi / 6,
) -> float:
    """How far (metres) the robot sits right of the middle between walls on both its sides.

    ``left_rad`` is the direction (robot frame) counted as left, e.g. the left normal of the
    path; the nearest return within ``side_halfwidth_rad`` of it and of its opposite is taken
    on each side; an invalid return (0: closer than the LiDAR's minimum range) counts as
    ``min_range_m``. When both sides have a wall within ``reach_m`` the result is half their
    difference (positive: move left), else 0.
    """
    r = np.asarray(scan_m, dtype=np.float64)
    a = np.asarray(angles_rad, dtype=np.float64)
    r = np.where(r <= 0.0, min_range_m, r)
    left = _angle_within(a, left_rad, side_halfwidth_rad)
    right = _angle_within(a, left_rad + math.pi, side_halfwidth_rad)
    if not (left.any() and right.any()):
        return 0.0
    d_left = float(r[left].min())
    d_right = float(r[right].min())
    if d_left > reach_m or d_right > reach_m:
        return 0.0
    return 0.5 * (d_left - d_right)


def safe_forward_speed_mps(
    scan_m: np.ndarray,
    angles_rad: np.ndarray,
    *,
    radius_m: float,
    dt_s: float,
    spare_m: float,
    max_angle_rad: float = 7.0 * math.pi / 18.0,
) -> float:
    """The fastest forward speed for one step of ``dt_s`` that keeps every return within
    ``max_angle_rad`` of ahead farther than ``radius_m + spare_m`` from the robot's centre
    (a return at angle a comes ``s cos a`` nearer over ``s`` of travel). A return of 0 (under
    the LiDAR's minimum range: somewhere between the body and that range) there allows none.
    """
    r = np.asarray(scan_m, dtype=np.float64)
    a = np.asarray(angles_rad, dtype=np.float64)
    c = np.cos(a)
    ahead = c >= math.cos(max_angle_rad)
    if not ahead.any():
        return math.inf
    r, c = r[ahead], c[ahead]
    if (r <= 0.0).any():
        return 0.0
    room = (r - radius_m - spare_m) / c
    return max(0.0, float(room.min()) / dt_s)
