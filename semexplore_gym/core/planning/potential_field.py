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

from semexplore_gym.core.grid import GridGeometry, wrap_angle_rad
from semexplore_gym.core.planning.line_of_sight import farthest_visible_index
from semexplore_gym.core.planning.potential_field_kernels import (
    field_force_xy,
    free_along,
    guarded_velocity,
    map_points_xy,
    min_valid_range,
    scan_points_xy,
)
from semexplore_gym.core.validation import require_finite


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
            distance of the segment (0: the segment itself only), so that the robot's body, not
            only its centre, passes: aiming past a wall end at less than this would cut the
            corner onto it (see :func:`select_lookahead` for the fall-back tiers).
        heading_gain_per_s: ``omega = gain * angle(F)`` (rad/s per rad).
        turn_in_place_rad: Above this angle between heading and ``F`` the robot only turns.
        safety_margin_m: Clearance kept beyond the robot radius by the collision guard.
        contact_margin_m: Points already within the safety margin stop the robot only when it
            would pass closer than the radius plus this (it may pass close to corners). Keep
            the radius plus this above the LiDAR's minimum range so passing points stay seen.
        map_guard_radius_m: The guard also treats the centres of OCCUPIED map cells within this
            distance as obstacles: walls inside the LiDAR's minimum range are invisible to the
            scan. Keep it small (mapped cells sit up to half a cell nearer than the wall); 0
            disables.
        guard_steer_max_rad: Guard steering: when the way along ``F`` is blocked within the
            braking distance (at least ``guard_steer_min_free_m``), the robot aims at the nearest
            open heading within this angle of ``F`` (searched in ``guard_steer_step_rad``
            steps); 0 disables. It resolves the deadlock of a field pulling the robot straight
            onto a wall end that the guard does not let it pass.
        guard_steer_step_rad: See ``guard_steer_max_rad``.
        guard_steer_min_free_m: See ``guard_steer_max_rad``.
        braking_time_s: The guard allows ``v <= free_distance / braking_time_s``.
        braking_guard: Cap the speed by the free distance ahead (the collision guard); False
            leaves the speed to the field alone, as in the paper.
    """

    f_g: float = 30.0
    f_o: float = 0.065
    f_l: float = 1.5
    reference_n_beams: int = 360
    min_lookahead_m: float = 0.3
    max_lookahead_m: float = 3.0
    lookahead_clearance_m: float = 0.15
    heading_gain_per_s: float = 2.5
    turn_in_place_rad: float = 1.0
    safety_margin_m: float = 0.04
    contact_margin_m: float = 0.025
    map_guard_radius_m: float = 0.15
    guard_steer_max_rad: float = 1.6
    guard_steer_step_rad: float = 0.1
    guard_steer_min_free_m: float = 0.1
    braking_time_s: float = 0.6
    braking_guard: bool = True

    def __post_init__(self) -> None:
        require_finite(
            self,
            (
                "f_g",
                "f_o",
                "f_l",
                "lookahead_clearance_m",
                "safety_margin_m",
                "contact_margin_m",
                "map_guard_radius_m",
                "guard_steer_max_rad",
                "guard_steer_min_free_m",
            ),
            positive=False,
        )
        require_finite(
            self,
            (
                "min_lookahead_m",
                "max_lookahead_m",
                "heading_gain_per_s",
                "turn_in_place_rad",
                "braking_time_s",
                "guard_steer_step_rad",
            ),
            positive=True,
        )
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
        require_finite(
            self,
            ("radius_m", "max_linear_speed_mps", "max_angular_speed_radps", "max_range_m"),
            positive=True,
        )


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


#: ``(cos, sin)`` of :func:`beam_angles_rad` by beam count, computed once (only the numba
#: kernels of this module read them).
_BEAM_TRIG: dict[int, tuple[np.ndarray, np.ndarray]] = {}


def _beam_trig(n_beams: int) -> tuple[np.ndarray, np.ndarray]:
    """``np.cos`` and ``np.sin`` of ``beam_angles_rad(n_beams)``, cached (every control step
    needs them for the same scan size)."""
    trig = _BEAM_TRIG.get(n_beams)
    if trig is None:
        angles = beam_angles_rad(n_beams)
        trig = _BEAM_TRIG[n_beams] = (np.cos(angles), np.sin(angles))
    return trig


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
    scan = np.ascontiguousarray(scan_m, dtype=np.float64)
    a = np.ascontiguousarray(angles_rad, dtype=np.float64)
    f_o = params.f_o * params.reference_n_beams / len(scan) * repulsion_scale
    fx, fy = field_force_xy(
        scan, np.cos(a), np.sin(a), float(max_range_m), float(goal_angle_rad), params.f_g, f_o
    )
    return float(fx), float(fy)


def obstacle_points(
    scan_m: np.ndarray,
    angles_rad: np.ndarray,
    max_range_m: float,
    extra_points_xy: np.ndarray | None = None,
) -> np.ndarray:
    """``(K, 2)`` obstacle points in the robot frame: the scan's returns plus ``extra_points_xy``."""
    scan = np.ascontiguousarray(scan_m, dtype=np.float64)
    a = np.ascontiguousarray(angles_rad, dtype=np.float64)
    px, py = scan_points_xy(scan, np.cos(a), np.sin(a), float(max_range_m))
    pts = np.column_stack([px, py])
    if extra_points_xy is not None and len(extra_points_xy):
        pts = np.vstack([pts, extra_points_xy])
    return pts


def free_distance_along(
    points_xy: np.ndarray,
    heading_rad: float,
    half_width_m: float,
    contact_half_width_m: float | None = None,
) -> float:
    """Distance the robot can drive straight along ``heading_rad`` (robot frame) before an obstacle
    point enters its swept corridor of half-width ``half_width_m``; inf when nothing is in the way.

    With ``contact_half_width_m`` (the robot radius plus a little), a point that is already inside
    the ``half_width_m`` corridor but passes beside the robot farther than
    ``contact_half_width_m`` does not stop it (it only passes close, e.g. a wall end at a corner);
    a point nearer the centre line limits the travel to where it would touch.
    """
    pts = np.ascontiguousarray(points_xy, dtype=np.float64).reshape(-1, 2)
    hard = -1.0 if contact_half_width_m is None else float(contact_half_width_m)
    return float(
        free_along(
            pts[:, 0].copy(), pts[:, 1].copy(), float(heading_rad), float(half_width_m), hard
        )
    )


def front_free_distance(
    scan_m: np.ndarray,
    angles_rad: np.ndarray,
    max_range_m: float,
    half_width_m: float,
    backwards: bool = False,
    contact_half_width_m: float | None = None,
    extra_points_xy: np.ndarray | None = None,
) -> float:
    """:func:`free_distance_along` the heading (or backwards) for the scan's returns plus
    ``extra_points_xy`` (``(K, 2)`` robot frame, e.g. mapped walls inside the LiDAR's minimum range)."""
    pts = obstacle_points(scan_m, angles_rad, max_range_m, extra_points_xy)
    return free_distance_along(
        pts, math.pi if backwards else 0.0, half_width_m, contact_half_width_m
    )


def nearby_obstacle_points(
    grid: np.ndarray, geometry: GridGeometry, pose: tuple[float, float, float], radius_m: float
) -> np.ndarray:
    """Centres of the OCCUPIED cells within ``radius_m`` of the robot, ``(K, 2)`` in the robot frame."""
    x, y, yaw = (float(v) for v in pose)
    px, py = map_points_xy(
        grid,
        geometry.origin_x_m,
        geometry.origin_y_m,
        geometry.resolution_m,
        x,
        y,
        yaw,
        float(radius_m),
    )
    return np.column_stack([px, py])


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
    robot_clearance_m: float = math.inf,
) -> tuple[int, bool]:
    """Index of ``G`` in ``path_m`` (points at most about a cell apart), and whether it is visible.

    ``G`` is the farthest point at or after ``start_index`` within ``radius_m`` of the robot and
    in line of sight on ``grid`` (unknown cells do not block; obstacles within ``clearance_m`` of
    the sight line do). Beside a wall every sight line fails the clearance, so the test is
    repeated with the robot's own clearance ``robot_clearance_m`` less a cell (the sight line may
    not pass closer to a wall than the robot already is), then with a thin line. If no point
    within the radius passes, the nearest visible point after ``start_index``, else the nearest
    point (not visible).
    """
    n = len(path_m)
    if n == 0:
        raise ValueError("path_m is empty")
    start = min(max(int(start_index), 0), n - 1)
    pts = path_m[start:]
    dist = np.hypot(pts[:, 0] - robot_xy_m[0], pts[:, 1] - robot_xy_m[1])
    inside = dist <= radius_m + 1e-9
    own = min(clearance_m, robot_clearance_m - geometry.resolution_m)
    tiers = tuple(c for c in (clearance_m, own) if c > 0.0) + (0.0,)
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
        j = farthest_visible_index(
            grid, geometry, robot_xy_m, near, np.ones(len(near), dtype=bool), clr
        )
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
) -> PotentialFieldCommand:
    """One step of path following with the modified potential field (the paper's field).

    ``PotentialFieldFollower(limits, params).command(...)`` with the arguments of
    :meth:`PotentialFieldFollower.command`; build the follower once to step it many times, or
    to scale the repulsion.
    """
    follower = PotentialFieldFollower(limits, params)
    return follower.command(scan_m, pose, path_m, grid, geometry, start_index=start_index)


class PotentialFieldFollower:
    """Follows a global path with the modified potential field, for one robot.

    Args:
        limits: Robot radius, speed limits and LiDAR range.
        params: Field parameters (default: the paper's).
    """

    def __init__(self, limits: RobotLimits, params: PotentialFieldParams | None = None) -> None:
        self.limits = limits
        self.params = params if params is not None else PotentialFieldParams()

    def command(
        self,
        scan_m: npt.ArrayLike,
        pose: tuple[float, float, float],
        path_m: np.ndarray,
        grid: np.ndarray,
        geometry: GridGeometry,
        *,
        start_index: int = 0,
        repulsion_scale: float = 1.0,
    ) -> PotentialFieldCommand:
        """One step of path following.

        Args:
            scan_m: ``(N,)`` LiDAR ranges, beam ``i`` at ``i * 2 pi / N`` from the heading
                (0 = invalid, ``max_range_m`` = no return).
            pose: Robot ``(x_m, y_m, yaw_rad)`` in the map frame.
            path_m: ``(K, 2)`` global path, densely sampled (see :func:`resample_polyline`).
            grid: Encoded occupancy grid (uint8, matching ``geometry``) for the line-of-sight
                test.
            geometry: Frame of ``grid``.
            start_index: Path points before this index are ignored (the part already
                travelled).
            repulsion_scale: Multiplies ``f_o`` (local-minimum escape lowers it).

        Returns:
            The :class:`PotentialFieldCommand`; ``|v| <= max_linear_speed_mps`` and
            ``|omega| <= max_angular_speed_radps``.

        Raises:
            ValueError: on an empty or malformed path or scan, or a non-finite pose.
        """
        p, limits = self.params, self.limits
        scan, path, (x, y, yaw) = _checked_inputs(scan_m, path_m, pose)
        n = len(scan)
        cos_a, sin_a = _beam_trig(n)
        l_min = float(min_valid_range(scan, limits.max_range_m))
        lookahead = min(max(p.f_l * l_min, p.min_lookahead_m), p.max_lookahead_m)
        gi, visible = select_lookahead(
            path, (x, y), lookahead, grid, geometry, start_index, p.lookahead_clearance_m, l_min
        )
        gx, gy = float(path[gi, 0]), float(path[gi, 1])
        goal_angle = wrap_angle_rad(math.atan2(gy - y, gx - x) - yaw)
        if math.hypot(gx - x, gy - y) < 1e-6:
            goal_angle = 0.0
        f_o = p.f_o * p.reference_n_beams / n * repulsion_scale
        fx, fy = field_force_xy(scan, cos_a, sin_a, limits.max_range_m, goal_angle, p.f_g, f_o)
        px, py = self._guard_points(scan, cos_a, sin_a, grid, geometry, (x, y, yaw))
        v, omega, front = guarded_velocity(fx, fy, px, py, *_guard_args(limits, p))
        return PotentialFieldCommand(
            float(v),
            float(omega),
            (gx, gy),
            int(gi),
            bool(visible),
            (float(fx), float(fy)),
            l_min,
            lookahead,
            float(front),
        )

    def _guard_points(
        self,
        scan: np.ndarray,
        cos_a: np.ndarray,
        sin_a: np.ndarray,
        grid: np.ndarray,
        geometry: GridGeometry,
        pose: tuple[float, float, float],
    ) -> tuple[np.ndarray, np.ndarray]:
        """Obstacle points for the collision guard (robot frame): the scan's returns, plus the
        mapped walls within ``map_guard_radius_m``."""
        px, py = scan_points_xy(scan, cos_a, sin_a, self.limits.max_range_m)
        radius = self.params.map_guard_radius_m
        if radius > 0:
            x, y, yaw = pose
            mx, my = map_points_xy(
                grid,
                geometry.origin_x_m,
                geometry.origin_y_m,
                geometry.resolution_m,
                x,
                y,
                yaw,
                radius,
            )
            if len(mx):
                px = np.concatenate((px, mx))
                py = np.concatenate((py, my))
        return px, py


def _checked_inputs(
    scan_m: npt.ArrayLike, path_m: np.ndarray, pose: tuple[float, float, float]
) -> tuple[np.ndarray, np.ndarray, tuple[float, float, float]]:
    """The scan and path as float arrays and the pose as floats; raises on malformed ones."""
    scan = np.asarray(scan_m, dtype=np.float64)
    if scan.ndim != 1 or len(scan) == 0:
        raise ValueError(f"scan_m must be a non-empty 1-D array, got shape {scan.shape}")
    path = np.asarray(path_m, dtype=np.float64)
    if path.ndim != 2 or path.shape[1] != 2 or len(path) == 0:
        raise ValueError(f"path_m must have shape (K, 2) with K >= 1, got {path.shape}")
    x, y, yaw = (float(v) for v in pose)
    if not (math.isfinite(x) and math.isfinite(y) and math.isfinite(yaw)):
        raise ValueError(f"pose must be finite, got {pose!r}")
    return scan, path, (x, y, yaw)


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
    pts = obstacle_points(scan, angles, limits.max_range_m, extra_points_xy)
    v, omega, front = guarded_velocity(
        float(fx),
        float(fy),
        np.ascontiguousarray(pts[:, 0]),
        np.ascontiguousarray(pts[:, 1]),
        *_guard_args(limits, params),
    )
    return float(v), float(omega), float(front)


def _guard_args(limits: RobotLimits, params: PotentialFieldParams) -> tuple[float, ...]:
    return (
        limits.radius_m + params.safety_margin_m,
        limits.radius_m + params.contact_margin_m,
        params.guard_steer_max_rad,
        params.guard_steer_step_rad,
        max(params.guard_steer_min_free_m, limits.max_linear_speed_mps * params.braking_time_s),
        params.turn_in_place_rad,
        params.heading_gain_per_s,
        limits.max_linear_speed_mps,
        limits.max_angular_speed_radps,
        params.braking_time_s,
        bool(params.braking_guard),
    )
