"""The modified potential field: force, lookahead point, command mapping, collision guard."""

from __future__ import annotations

import math

import numpy as np
import pytest

from semexplore_gym.core.grid import GridGeometry, parse_ascii_grid
from semexplore_gym.core.planning.line_of_sight import segment_is_clear
from semexplore_gym.core.planning.potential_field import (
    PotentialFieldParams,
    RobotLimits,
    beam_angles_rad,
    field_force,
    front_free_distance,
    potential_field_command,
    resample_polyline,
    select_lookahead,
)

MAX_RANGE = 3.5
LIMITS = RobotLimits(
    radius_m=0.105, max_linear_speed_mps=0.22, max_angular_speed_radps=2.84, max_range_m=MAX_RANGE
)


def wall_scan(n: int, walls: list[tuple[float, float]]) -> np.ndarray:
    """Ranges in the robot frame to infinite straight walls, each given as (normal angle, distance).

    Rays parallel to or pointing away from every wall read the maximum range (no return).
    """
    angles = beam_angles_rad(n)
    out = np.full(n, MAX_RANGE)
    for normal, dist in walls:
        c = np.cos(angles - normal)
        with np.errstate(divide="ignore"):
            r = np.where(c > 1e-9, dist / np.where(c > 1e-9, c, 1.0), np.inf)
        out = np.minimum(out, np.where(r < MAX_RANGE, r, MAX_RANGE))
    return out


def open_grid() -> tuple[np.ndarray, GridGeometry]:
    grid = parse_ascii_grid("\n".join(["." * 60] * 60))
    return grid, GridGeometry(0.05, -1.5, -1.5, 60, 60)


def test_goal_ahead_without_obstacles_drives_straight_at_full_speed():
    grid, geom = open_grid()
    path = resample_polyline([[0.0, 0.0], [1.2, 0.0]], 0.05)
    cmd = potential_field_command(
        np.full(360, MAX_RANGE), (0.0, 0.0, 0.0), path, grid, geom, LIMITS
    )
    assert cmd.v_mps == pytest.approx(0.22)
    assert cmd.omega_radps == pytest.approx(0.0)
    assert cmd.force_xy == pytest.approx((30.0, 0.0))
    # No obstacle seen: the lookahead is the ceiling of the radius.
    assert cmd.lookahead_m == pytest.approx(3.0) and cmd.goal_visible
    assert cmd.goal_xy_m == pytest.approx((1.2, 0.0))


def test_obstacle_on_the_left_pushes_right():
    scan = wall_scan(360, [(math.pi / 2, 0.2)])
    fx, fy = field_force(scan, beam_angles_rad(360), 0.0, PotentialFieldParams(), MAX_RANGE)
    assert fy < 0.0 and fx == pytest.approx(30.0, abs=1e-6)
    grid, geom = open_grid()
    path = resample_polyline([[0.0, 0.0], [1.0, 0.0]], 0.05)
    cmd = potential_field_command(scan, (0.0, 0.0, 0.0), path, grid, geom, LIMITS)
    assert cmd.omega_radps < 0.0
    assert 0.0 < cmd.v_mps < 0.22
    # Repulsion of a wall at distance w over a 1-degree fan: about f_o * 90 / w (minus the
    # part beyond the maximum range).
    assert -fy == pytest.approx(0.065 * 90 / 0.2, rel=0.05)


def test_repulsion_does_not_depend_on_beam_count_and_scales():
    p = PotentialFieldParams()
    f360 = field_force(
        wall_scan(360, [(0.0, 0.5)]), beam_angles_rad(360), math.pi / 2, p, MAX_RANGE
    )
    f720 = field_force(
        wall_scan(720, [(0.0, 0.5)]), beam_angles_rad(720), math.pi / 2, p, MAX_RANGE
    )
    assert f720 == pytest.approx(f360, rel=1e-2)
    half = field_force(
        wall_scan(360, [(0.0, 0.5)]),
        beam_angles_rad(360),
        math.pi / 2,
        p,
        MAX_RANGE,
        repulsion_scale=0.5,
    )
    assert -half[0] == pytest.approx(-f360[0] / 2)


def test_invalid_and_no_return_beams_are_ignored():
    scan = np.full(360, MAX_RANGE)
    scan[:10] = 0.0  # invalid returns straight ahead must not repel
    fx, fy = field_force(scan, beam_angles_rad(360), 0.0, PotentialFieldParams(), MAX_RANGE)
    assert (fx, fy) == pytest.approx((30.0, 0.0))


def test_goal_behind_turns_in_place_and_outputs_stay_within_limits():
    grid, geom = open_grid()
    path = resample_polyline([[0.0, 0.0], [-1.0, 0.0]], 0.05)
    cmd = potential_field_command(
        np.full(360, MAX_RANGE), (0.0, 0.0, 0.1), path, grid, geom, LIMITS
    )
    assert cmd.v_mps == 0.0 and abs(cmd.omega_radps) == pytest.approx(2.84)
    rng = np.random.default_rng(3)
    for _ in range(200):
        scan = rng.uniform(0.0, MAX_RANGE, 360)
        scan[rng.random(360) < 0.1] = 0.0
        pose = (rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-math.pi, math.pi))
        path = resample_polyline(rng.uniform(-1.4, 1.4, (3, 2)), 0.05)
        cmd = potential_field_command(scan, pose, path, grid, geom, LIMITS)
        assert 0.0 <= cmd.v_mps <= 0.22
        assert abs(cmd.omega_radps) <= 2.84


def test_collision_guard_stops_before_a_wall_ahead():
    scan = wall_scan(360, [(0.0, 0.2)])
    free = front_free_distance(scan, beam_angles_rad(360), MAX_RANGE, 0.105 + 0.04)
    assert free == pytest.approx(0.2 - 0.145, abs=1e-9)
    grid, geom = open_grid()
    path = resample_polyline([[0.0, 0.0], [2.0, 0.0]], 0.05)
    # No repulsion and no guard steering: only the guard slows the robot.
    p = PotentialFieldParams(f_o=0.0, guard_steer_max_rad=0.0)
    cmd = potential_field_command(scan, (0.0, 0.0, 0.0), path, grid, geom, LIMITS, p)
    assert cmd.v_mps == pytest.approx(0.055 / 0.6) and cmd.omega_radps == 0.0
    # Inside the safety margin the robot may at most creep up to the contact margin (0.13 m).
    near = wall_scan(360, [(0.0, 0.14)])
    v_near = potential_field_command(near, (0.0, 0.0, 0.0), path, grid, geom, LIMITS, p).v_mps
    assert 0.0 <= v_near <= 0.01 / 0.6 + 1e-12
    touching = wall_scan(360, [(0.0, 0.13)])
    assert (
        potential_field_command(touching, (0.0, 0.0, 0.0), path, grid, geom, LIMITS, p).v_mps == 0.0
    )
    # Backwards, the wall in front does not matter.
    assert (
        front_free_distance(scan, beam_angles_rad(360), MAX_RANGE, 0.145, backwards=True)
        == math.inf
    )


def test_wall_end_beside_the_robot_is_passed_not_hit():
    angles = beam_angles_rad(360)
    # A single obstacle point (a wall end) beside the robot, 0.14 m to the left and 0.025 m
    # ahead: inside the safety margin (0.145) but clear of contact (0.13): it may drive past.
    scan = np.full(360, MAX_RANGE)
    scan[80] = 0.14 / math.sin(math.radians(80))
    assert (
        front_free_distance(scan, angles, MAX_RANGE, 0.145, contact_half_width_m=0.13) == math.inf
    )
    assert front_free_distance(scan, angles, MAX_RANGE, 0.145) == 0.0
    # Farther ahead, 0.11 m to the side: the guard stops the robot where the point would enter
    # the safety margin.
    scan[:] = MAX_RANGE
    scan[38] = math.hypot(0.14, 0.11)
    free = front_free_distance(scan, angles, MAX_RANGE, 0.145, contact_half_width_m=0.13)
    x, y = scan[38] * math.cos(math.radians(38)), scan[38] * math.sin(math.radians(38))
    assert free == pytest.approx(x - math.sqrt(0.145**2 - y**2))
    # Already inside the margin and 0.12 m to the side (< 0.13): it would touch, no travel.
    scan[:] = MAX_RANGE
    scan[70] = 0.12 / math.sin(math.radians(70))
    assert front_free_distance(scan, angles, MAX_RANGE, 0.145, contact_half_width_m=0.13) == 0.0


def test_guard_steering_turns_away_from_a_blocking_wall_end():
    grid, geom = open_grid()
    path = resample_polyline([[0.0, 0.0], [2.0, 0.0]], 0.05)
    scan = np.full(360, MAX_RANGE)
    scan[20] = math.hypot(0.2, 0.07)  # a point 0.2 m ahead, 0.07 m to the left
    p = PotentialFieldParams(f_o=0.0)
    cmd = potential_field_command(scan, (0.0, 0.0, 0.0), path, grid, geom, LIMITS, p)
    assert cmd.omega_radps < 0.0  # turns right, away from the point
    stuck = potential_field_command(
        scan,
        (0.0, 0.0, 0.0),
        path,
        grid,
        geom,
        LIMITS,
        PotentialFieldParams(f_o=0.0, guard_steer_max_rad=0.0),
    )
    assert stuck.omega_radps == 0.0


def test_mapped_walls_inside_the_lidar_minimum_range_stop_the_robot():
    # The LiDAR reads nothing (the wall is inside its 0.12 m minimum range), the map shows it.
    grid, geom = open_grid()
    grid = grid.copy()
    row, col = geom.world_to_grid(0.12, 0.0)
    grid[int(row) - 2 : int(row) + 3, int(col)] = 0
    path = resample_polyline([[0.0, 0.0], [1.0, 0.0]], 0.05)
    blind = np.zeros(360)
    cmd = potential_field_command(
        blind,
        (0.0, 0.0, 0.0),
        path,
        grid,
        geom,
        LIMITS,
        PotentialFieldParams(guard_steer_max_rad=0.0),
    )
    assert cmd.v_mps == 0.0
    off = PotentialFieldParams(guard_steer_max_rad=0.0, map_guard_radius_m=0.0)
    assert (
        potential_field_command(blind, (0.0, 0.0, 0.0), path, grid, geom, LIMITS, off).v_mps > 0.2
    )


WALL_MAP = """
..............................
..............................
..............................
..............................
..............................
..............................
..............................
..............................
..............................
..............................
..............................
...........##########.........
...........##########.........
..............................
..............................
..............................
..............................
..............................
..............................
..............................
"""


def test_lookahead_is_within_f_l_times_l_min():
    grid, geom = open_grid()
    path = resample_polyline([[0.0, 0.0], [1.4, 0.0]], 0.05)
    scan = wall_scan(360, [(math.pi / 2, 0.4), (-math.pi / 2, 0.4)])  # corridor 0.8 m wide
    cmd = potential_field_command(scan, (0.0, 0.0, 0.0), path, grid, geom, LIMITS)
    assert cmd.l_min_m == pytest.approx(0.4)
    assert cmd.lookahead_m == pytest.approx(0.6)
    assert cmd.goal_xy_m == pytest.approx((0.6, 0.0))
    # A floor keeps G off the robot when it brushes a wall.
    scan = wall_scan(360, [(math.pi / 2, 0.13)])
    cmd = potential_field_command(scan, (0.0, 0.0, 0.0), path, grid, geom, LIMITS)
    assert cmd.lookahead_m == pytest.approx(0.3) and cmd.goal_xy_m == pytest.approx((0.3, 0.0))


def test_lookahead_respects_line_of_sight():
    grid = parse_ascii_grid(
        WALL_MAP
    )  # 30 x 20 cells of 0.1 m; wall rows 7-8 (y 0.7-0.9), x 1.1-2.1
    geom = GridGeometry(0.1, 0.0, 0.0, 20, 30)
    robot = (1.6, 0.3)
    # The path goes up past the wall's left end and back over it: the point above the wall is
    # within the radius but hidden behind it.
    path = resample_polyline([[1.6, 0.3], [0.8, 0.3], [0.8, 1.3], [1.6, 1.3]], 0.05)
    i, visible = select_lookahead(path, robot, 1.2, grid, geom)
    assert visible
    gx, gy = path[i]
    assert segment_is_clear(grid, geom, robot, (gx, gy))
    assert not segment_is_clear(grid, geom, robot, (1.6, 1.3))
    # The farthest visible point is on the vertical leg, below the hidden part.
    assert gx == pytest.approx(0.8) and 0.3 < gy < 1.3
    # Ignoring sight the farthest point within the radius would be beyond the wall.
    far = np.hypot(path[:, 0] - robot[0], path[:, 1] - robot[1]) <= 1.2
    assert path[np.flatnonzero(far)[-1], 1] == pytest.approx(1.3)
    # Points before start_index are ignored.
    j, _ = select_lookahead(path, robot, 1.2, grid, geom, start_index=i + 3)
    assert j >= i + 3


def test_lookahead_falls_back_to_the_nearest_visible_point():
    grid = parse_ascii_grid(WALL_MAP)
    geom = GridGeometry(0.1, 0.0, 0.0, 20, 30)
    # Nothing within 0.3 m; above the wall only the far left end of the path can be seen.
    path = resample_polyline([[0.0, 1.5], [2.5, 1.5]], 0.05)
    i, visible = select_lookahead(path, (1.6, 0.3), 0.3, grid, geom)
    assert visible and segment_is_clear(grid, geom, (1.6, 0.3), tuple(path[i]))
    assert path[i, 0] == pytest.approx(0.05)
    assert not any(segment_is_clear(grid, geom, (1.6, 0.3), tuple(q)) for q in path[i + 1 :])
    i, visible = select_lookahead(
        resample_polyline([[1.6, 1.5], [1.7, 1.5]], 0.05), (1.6, 0.3), 0.3, grid, geom
    )
    assert not visible and i == 0


def test_line_of_sight_clearance_and_unknown():
    grid = parse_ascii_grid("""
    ..........
    ....?.....
    ..........
    ....#.....
    ..........
    """)
    geom = GridGeometry(1.0, 0.0, 0.0, 5, 10)
    assert not segment_is_clear(grid, geom, (0.5, 1.5), (9.5, 1.5))  # through the wall cell
    assert segment_is_clear(grid, geom, (0.5, 2.5), (9.5, 2.5))
    assert not segment_is_clear(grid, geom, (0.5, 2.5), (9.5, 2.5), clearance_m=1.2)
    assert segment_is_clear(grid, geom, (0.5, 3.5), (9.5, 3.5))
    assert not segment_is_clear(grid, geom, (0.5, 3.5), (9.5, 3.5), unknown_blocks=True)
    # A diagonal wall of corner-touching cells blocks a diagonal sight line through it.
    diag = parse_ascii_grid("""
    ...#
    ..#.
    .#..
    #...
    """)
    g4 = GridGeometry(1.0, 0.0, 0.0, 4, 4)
    # Through the corner shared by wall cells (row 0, col 0) and (row 1, col 1): no sample
    # lands in either, the sight line still must not slip through.
    assert not segment_is_clear(diag, g4, (1.7, 0.3), (0.3, 1.7))
    assert segment_is_clear(diag, g4, (1.7, 0.3), (3.7, 2.3))
    with pytest.raises(ValueError, match="clearance_m"):
        segment_is_clear(grid, geom, (0, 0), (1, 1), clearance_m=-1.0)
    with pytest.raises(ValueError, match="shape"):
        segment_is_clear(grid, g4, (0, 0), (1, 1))


def test_params_validate():
    with pytest.raises(ValueError, match="f_g"):
        PotentialFieldParams(f_g=-1.0)
    with pytest.raises(ValueError, match="max_lookahead_m"):
        PotentialFieldParams(min_lookahead_m=1.0, max_lookahead_m=0.5)
    with pytest.raises(ValueError, match="radius_m"):
        RobotLimits(0.0, 0.2, 2.0, 3.5)
