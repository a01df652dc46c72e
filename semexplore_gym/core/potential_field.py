"""The paper's modified potential field for following a global path with a 2-D LiDAR.

The motion vector in the robot frame is (paper, Eq. 4)::

    F = f_g * [cos G_v, sin G_v]  -  sum_i (f_o / L_i) * [cos L_vi, sin L_vi]

with ``L_i`` the range and ``L_vi`` the angle of beam ``i``, and ``G_v`` the angle to the goal
point ``G``: the farthest point of the global path that is in line of sight and within
``f_l * L_min`` of the robot (``L_min`` the shortest beam). Near walls ``L_min`` is small, so
``G`` stays close and the robot follows the path tightly; in the open it may cut corners.

Beyond the paper (all named in :class:`PotentialFieldParams`):

* Beams with no return (range 0 = invalid, or the maximum range = nothing seen) are skipped.
* ``f_o`` is per beam of a 360-beam LiDAR; for other beam counts it is scaled by
  ``reference_n_beams / n_beams`` so that the field does not depend on the angular resolution.
* The lookahead radius is clamped to ``[min_lookahead_m, max_lookahead_m]`` so that ``G`` never
  collapses onto the robot beside a wall. When no path point within the radius is visible, ``G``
  is the nearest visible path point, else the nearest path point (``goal_visible`` False).
* ``F`` becomes ``(v, omega)``: ``omega`` steers towards ``F`` with a proportional gain; the robot
  turns in place when ``F`` points more than ``turn_in_place_rad`` away from the heading, and
  otherwise drives at ``v_max * cos(angle)``.
* A collision guard caps ``v`` so that the robot (radius plus ``safety_margin_m``) can stop
  within ``braking_time_s`` before any scan point or nearby mapped wall cell in its swept
  corridor (see :func:`front_free_distance`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from semexplore_gym.core.grid import OCCUPIED, GridGeometry
from semexplore_gym.core.line_of_sight import farthest_visible_index


@dataclass(frozen=True)
class PotentialFieldParams:
    """Parameters of the modified potential field (defaults: the paper's table, then ours).

    Attributes:
        f_g: Goal attraction ``f_g`` (paper: 30).
        f_o: Obstacle repulsion per beam ``f_o`` in force x metres (paper: 0.065).
        f_l: Lookahead factor ``f_l``: ``G`` lies within ``f_l * L_min`` (paper: 1.5).
        reference_n_beams: Beam count ``f_o`` is tuned for (the LDS-01 has 360).
        min_lookahead_m: Floor of the lookahead radius.
        max_lookahead_m: Ceiling of the lookahead radius.
        lookahead_clearance_m: Line of sight to ``G`` also needs no obstacle cell within this
            distance of the segment (0: the segment itself only).
        heading_gain_per_s: ``omega = gain * angle(F)`` (rad/s per rad).
        turn_in_place_rad: Above this angle between heading and ``F`` the robot only turns.
        safety_margin_m: Clearance kept beyond the robot radius by the collision guard.
        contact_margin_m: Points already within the safety margin stop the robot only when it
            would pass closer than the radius plus this (it may pass close to corners). Keep
            the radius plus this above the LiDAR's minimum range so passing points stay seen.
        map_guard_radius_m: The guard also treats OCCUPIED map cells within this distance as
            obstacles (walls inside the LiDAR's minimum range); 0 disables.
        braking_time_s: The guard allows ``v <= free_distance / braking_time_s``.
    """

    f_g: float = 30.0
    f_o: float = 0.065
    f_l: float = 1.5
    reference_n_beams: int = 360
    min_lookahead_m: float = 0.3
    max_lookahead_m: float = 3.0
    lookahead_clearance_m: float = 0.1
    heading_gain_per_s: float = 2.5
    turn_in_place_rad: float = 1.0
    safety_margin_m: float = 0.04
    contact_margin_m: float = 0.025
    map_guard_radius_m: float = 0.3
    braking_time_s: float = 0.6

    def __post_init__(self) -> None:
        for name in ("f_g", "f_o", "f_l", "lookahead_clearance_m", "safety_margin_m", "contact_margin_m", "map_guard_radius_m"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value >= 0.0):
                raise ValueError(f"{name} must be a finite number >= 0, got {value!r}")
        for name in (
            "min_lookahead_m",
            "max_lookahead_m",
            "heading_gain_per_s",
            "turn_in_place_rad",
            "braking_time_s",
        ):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0.0):
                raise ValueError(f"{name} must be a positive finite number, got {value!r}")
        if self.max_lookahead_m < self.min_lookahead_m:
            raise ValueError(
                f"max_lookahead_m ({self.max_lookahead_m}) < min_lookahead_m ({self.min_lookahead_m})"
            )
        if int(self.reference_n_beams) <= 0:
            raise ValueError(f"reference_n_beams must be positive, got {self.reference_n_beams!r}")


@dataclass(frozen=True)
class RobotLimits:
    """What the command mapping needs to know about the robot and its LiDAR."""

    radius_m: float
    max_linear_speed_mps: float
    max_angular_speed_radps: float
    max_range_m: float

    def __post_init__(self) -> None:
        for name in ("radius_m", "max_linear_speed_mps", "max_angular_speed_radps", "max_range_m"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0.0):
                raise ValueError(f"{name} must be a positive finite number, got {value!r}")


@dataclass(frozen=True)
class PotentialFieldCommand:
    """The result of one potential-field step.

    Attributes:
        v_mps: Linear velocity command.
        omega_radps: Angular velocity command (counter-clockwise positive).
        goal_xy_m: The lookahead point ``G`` in the map frame.
        goal_index: Index of ``G`` in the path given.
        goal_visible: Whether ``G`` passed the line-of-sight test.
        force_xy: ``F`` in the robot frame.
        l_min_m: Shortest valid beam (inf when none).
        lookahead_m: The lookahead radius used.
        front_free_m: Free distance ahead in the robot's swept corridor (inf when clear).
    """

    v_mps: float
    omega_radps: float
    goal_xy_m: tuple[float, float]
    goal_index: int
    goal_visible: bool
    force_xy: tuple[float, float]
    l_min_m: float
    lookahead_m: float
    front_free_m: float


def beam_angles_rad(n_beams: int) -> np.ndarray:
    """Beam angles relative to the heading: beam ``i`` at ``i * 2 pi / n_beams``, counter-clockwise."""
    if int(n_beams) <= 0:
        raise ValueError(f"n_beams must be positive, got {n_beams!r}")
    return np.arange(int(n_beams), dtype=np.float64) * (2.0 * math.pi / int(n_beams))


def valid_beams(scan_m: np.ndarray, max_range_m: float) -> np.ndarray:
    """Mask of beams that saw an obstacle: range > 0 (0 = invalid) and below the maximum range."""
    return (scan_m > 0.0) & (scan_m < max_range_m) & np.isfinite(scan_m)


def field_force(
    scan_m: np.ndarray,
    angles_rad: np.ndarray,
    goal_angle_rad: float,
    params: PotentialFieldParams,
    max_range_m: float,
    repulsion_scale: float = 1.0,
) -> tuple[float, float]:
    """``F`` in the robot frame (Eq. 4) from a scan and the angle to ``G``.

    ``repulsion_scale`` multiplies ``f_o`` (1 = the paper's field).
    """
    ok = valid_beams(scan_m, max_range_m)
    f_o = params.f_o * params.reference_n_beams / len(scan_m) * repulsion_scale
    inv = np.where(ok, 1.0 / np.where(ok, scan_m, 1.0), 0.0)
    fx = params.f_g * math.cos(goal_angle_rad) - f_o * float(inv @ np.cos(angles_rad))
    fy = params.f_g * math.sin(goal_angle_rad) - f_o * float(inv @ np.sin(angles_rad))
    return fx, fy


def front_free_distance(
    scan_m: np.ndarray,
    angles_rad: np.ndarray,
    max_range_m: float,
    half_width_m: float,
    backwards: bool = False,
    contact_half_width_m: float | None = None,
    extra_points_xy: np.ndarray | None = None,
) -> float:
    """Distance the robot can drive straight (forward, or backward) before an obstacle point
    enters its swept corridor of half-width ``half_width_m``; inf when nothing is in the way.

    The obstacle points are the scan's returns plus ``extra_points_xy`` (``(K, 2)`` in the robot
    frame, e.g. mapped walls too close for the LiDAR's minimum range). With
    ``contact_half_width_m`` (the robot radius plus a little), a point that is already inside
    the ``half_width_m`` corridor but passes beside the robot farther than
    ``contact_half_width_m`` does not stop it (it only passes close, e.g. a wall end at a corner);
    a point nearer the centre line limits the travel to where it would touch.
    """
    ok = valid_beams(scan_m, max_range_m)
    x = scan_m[ok] * np.cos(angles_rad[ok])
    y = scan_m[ok] * np.sin(angles_rad[ok])
    if extra_points_xy is not None and len(extra_points_xy):
        x = np.concatenate([x, extra_points_xy[:, 0]])
        y = np.concatenate([y, extra_points_xy[:, 1]])
    if backwards:
        x = -x
    hit = (x > 0.0) & (np.abs(y) < half_width_m)
    if not hit.any():
        return math.inf
    xh = x[hit]
    yh = y[hit]
    free = xh - np.sqrt(half_width_m**2 - yh**2)
    if contact_half_width_m is not None:
        inside = free < 0.0
        if inside.any():
            hard = np.abs(yh) < contact_half_width_m
            contact = xh - np.sqrt(np.maximum(contact_half_width_m**2 - yh**2, 0.0))
            free = np.where(inside, np.where(hard, contact, np.inf), free)
    return float(max(0.0, free.min()))


def nearby_obstacle_points(
    grid: np.ndarray, geometry: GridGeometry, pose: tuple[float, float, float], radius_m: float
) -> np.ndarray:
    """OCCUPIED cells within ``radius_m`` of the robot as ``(K, 2)`` points in the robot frame.

    Each cell is represented by the point of its square nearest the robot, so the points are
    never farther than the mapped wall.
    """
    x, y, yaw = pose
    res = geometry.resolution_m
    r0, c0 = (int(v) for v in geometry.world_to_grid(x - radius_m, y - radius_m))
    r1, c1 = (int(v) for v in geometry.world_to_grid(x + radius_m, y + radius_m))
    r0, c0 = max(r0, 0), max(c0, 0)
    r1, c1 = min(r1, geometry.height - 1), min(c1, geometry.width - 1)
    if r0 > r1 or c0 > c1:
        return np.empty((0, 2))
    rows, cols = np.nonzero(grid[r0 : r1 + 1, c0 : c1 + 1] == OCCUPIED)
    if len(rows) == 0:
        return np.empty((0, 2))
    lo_x = geometry.origin_x_m + (cols + c0) * res
    lo_y = geometry.origin_y_m + (rows + r0) * res
    px = np.clip(x, lo_x, lo_x + res) - x
    py = np.clip(y, lo_y, lo_y + res) - y
    keep = px * px + py * py <= radius_m * radius_m
    c, s = math.cos(yaw), math.sin(yaw)
    return np.column_stack([c * px[keep] + s * py[keep], -s * px[keep] + c * py[keep]])


def resample_polyline(poly: npt.ArrayLike, step_m: float) -> np.ndarray:
    """Points along a polyline every ``step_m`` (its vertices' ends kept), for lookahead search."""
    p = np.asarray(poly, dtype=np.float64).reshape(-1, 2)
    if not (math.isfinite(step_m) and step_m > 0):
        raise ValueError(f"step_m must be a positive finite number, got {step_m!r}")
    if len(p) < 2:
        return p.copy()
    seg = np.hypot(*np.diff(p, axis=0).T)
    cum = np.concatenate(([0.0], np.cumsum(seg)))
    if cum[-1] <= 0.0:
        return p[:1].copy()
    s = np.arange(0.0, cum[-1], step_m)
    s = np.append(s, cum[-1])
    x = np.interp(s, cum, p[:, 0])
    y = np.interp(s, cum, p[:, 1])
    return np.column_stack([x, y])


def select_lookahead(
    path_m: np.ndarray,
    robot_xy_m: tuple[float, float],
    radius_m: float,
    grid: np.ndarray,
    geometry: GridGeometry,
    start_index: int = 0,
    clearance_m: float = 0.0,
) -> tuple[int, bool]:
    """Index of ``G`` in ``path_m`` (points at most about a cell apart), and whether it is visible.

    ``G`` is the farthest point at or after ``start_index`` within ``radius_m`` of the robot and
    in line of sight on ``grid`` (unknown cells do not block; obstacles within ``clearance_m`` of
    the sight line do; if no point passes with the clearance, a thin sight line is enough). If
    there is none, the nearest visible point after ``start_index``, else the nearest point (not
    visible).
    """
    n = len(path_m)
    if n == 0:
        raise ValueError("path_m is empty")
    start = min(max(int(start_index), 0), n - 1)
    pts = path_m[start:]
    dist = np.hypot(pts[:, 0] - robot_xy_m[0], pts[:, 1] - robot_xy_m[1])
    inside = dist <= radius_m + 1e-9
    # First with the clearance; beside a wall (closer than the clearance) every sight line
    # fails it, so then with a thin line.
    tiers = (clearance_m, 0.0) if clearance_m > 0.0 else (0.0,)
    if inside.any():
        for clr in tiers:
            i = farthest_visible_index(grid, geometry, robot_xy_m, pts, inside, clr)
            if i >= 0:
                return start + i, True
    # Nothing visible within the radius: try the nearest points first.
    order = np.argsort(dist, kind="stable")[:64]
    # farthest_visible_index scans from the back, so reversing tries the nearest point first.
    near = np.ascontiguousarray(pts[order[::-1]])
    for clr in tiers:
        j = farthest_visible_index(grid, geometry, robot_xy_m, near, np.ones(len(near), dtype=bool), clr)
        if j >= 0:
            return start + int(order[::-1][j]), True
    return start + int(order[0]), False


def potential_field_command(
    scan_m: npt.ArrayLike,
    pose: tuple[float, float, float],
    path_m: np.ndarray,
    grid: np.ndarray,
    geometry: GridGeometry,
    limits: RobotLimits,
    params: PotentialFieldParams | None = None,
    start_index: int = 0,
    repulsion_scale: float = 1.0,
) -> PotentialFieldCommand:
    """One step of path following with the modified potential field.

    Args:
        scan_m: ``(N,)`` LiDAR ranges, beam ``i`` at ``i * 2 pi / N`` from the heading
            (0 = invalid, ``max_range_m`` = no return).
        pose: Robot ``(x_m, y_m, yaw_rad)`` in the map frame.
        path_m: ``(K, 2)`` global path, densely sampled (see :func:`resample_polyline`).
        grid: Encoded occupancy grid (uint8, matching ``geometry``) for the line-of-sight test.
        geometry: Frame of ``grid``.
        limits: Robot radius, speed limits and LiDAR range.
        params: Field parameters (default: the paper's).
        start_index: Path points before this index are ignored (the part already travelled).
        repulsion_scale: Multiplies ``f_o`` (local-minimum escape lowers it).

    Returns:
        The :class:`PotentialFieldCommand`; ``|v| <= max_linear_speed_mps`` and
        ``|omega| <= max_angular_speed_radps``.

    Raises:
        ValueError: on an empty or malformed path or scan, or a non-finite pose.
    """
    p = params if params is not None else PotentialFieldParams()
    scan = np.asarray(scan_m, dtype=np.float64)
    if scan.ndim != 1 or len(scan) == 0:
        raise ValueError(f"scan_m must be a non-empty 1-D array, got shape {scan.shape}")
    path = np.asarray(path_m, dtype=np.float64)
    if path.ndim != 2 or path.shape[1] != 2 or len(path) == 0:
        raise ValueError(f"path_m must have shape (K, 2) with K >= 1, got {path.shape}")
    x, y, yaw = (float(v) for v in pose)
    if not (math.isfinite(x) and math.isfinite(y) and math.isfinite(yaw)):
        raise ValueError(f"pose must be finite, got {pose!r}")

    angles = beam_angles_rad(len(scan))
    ok = valid_beams(scan, limits.max_range_m)
    l_min = float(scan[ok].min()) if ok.any() else math.inf
    lookahead = min(max(p.f_l * l_min, p.min_lookahead_m), p.max_lookahead_m)
    gi, visible = select_lookahead(
        path, (x, y), lookahead, grid, geometry, start_index, p.lookahead_clearance_m
    )
    gx, gy = float(path[gi, 0]), float(path[gi, 1])
    goal_angle = _wrap(math.atan2(gy - y, gx - x) - yaw)
    if math.hypot(gx - x, gy - y) < 1e-6:
        goal_angle = 0.0
    fx, fy = field_force(scan, angles, goal_angle, p, limits.max_range_m, repulsion_scale)

    near = nearby_obstacle_points(grid, geometry, (x, y, yaw), p.map_guard_radius_m) if p.map_guard_radius_m > 0 else None
    v, omega, front = force_to_velocity(fx, fy, scan, angles, limits, p, near)
    return PotentialFieldCommand(
        v, omega, (gx, gy), int(gi), bool(visible), (fx, fy), l_min, lookahead, front
    )


def force_to_velocity(
    fx: float,
    fy: float,
    scan: np.ndarray,
    angles: np.ndarray,
    limits: RobotLimits,
    params: PotentialFieldParams,
    extra_points_xy: np.ndarray | None = None,
) -> tuple[float, float, float]:
    """Map ``F`` (robot frame) to ``(v, omega)`` within the limits, with the collision guard.

    ``extra_points_xy`` are further obstacle points for the guard (robot frame), e.g. from
    :func:`nearby_obstacle_points`.

    Returns:
        ``(v_mps, omega_radps, front_free_m)``.
    """
    phi = math.atan2(fy, fx) if (fx != 0.0 or fy != 0.0) else 0.0
    omega = max(
        -limits.max_angular_speed_radps,
        min(limits.max_angular_speed_radps, params.heading_gain_per_s * phi),
    )
    if abs(phi) > params.turn_in_place_rad:
        v = 0.0
    else:
        v = limits.max_linear_speed_mps * max(0.0, math.cos(phi))
    front = front_free_distance(
        scan,
        angles,
        limits.max_range_m,
        limits.radius_m + params.safety_margin_m,
        contact_half_width_m=limits.radius_m + params.contact_margin_m,
        extra_points_xy=extra_points_xy,
    )
    v = min(v, front / params.braking_time_s)
    return float(v), float(omega), front


def _wrap(a: float) -> float:
    return (a + math.pi) % (2.0 * math.pi) - math.pi
