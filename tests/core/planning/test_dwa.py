"""DWA local planner in a simple unicycle simulation."""

from __future__ import annotations

import math

import numpy as np
import pytest

from semexplore_gym.core.grid import FREE, OCCUPIED, GridGeometry
from semexplore_gym.core.planning.dwa import DWAParams, DWAPlanner, scan_points_m

DT_S = 0.2
# Fewer samples than the TurtleBot3 defaults keep the closed-loop tests fast.
FAST = DWAParams(linear_samples=8, angular_samples=15)


def _world(
    obstacle_boxes: list[tuple[float, float, float, float]] = (),
) -> tuple[np.ndarray, GridGeometry]:
    geo = GridGeometry(0.05, -1.0, -1.5, 60, 100)  # x in [-1, 4), y in [-1.5, 1.5)
    grid = np.full(geo.shape, FREE, dtype=np.uint8)
    for x0, y0, x1, y1 in obstacle_boxes:
        r0, c0 = geo.world_to_grid(x0, y0)
        r1, c1 = geo.world_to_grid(x1, y1)
        grid[int(r0) : int(r1) + 1, int(c0) : int(c1) + 1] = OCCUPIED
    return grid, geo


def _occupied_xy(grid: np.ndarray, geo: GridGeometry) -> np.ndarray:
    rc = np.argwhere(grid == OCCUPIED)
    x, y = geo.grid_to_world(rc[:, 0], rc[:, 1])
    return np.column_stack([x, y])


def _simulate(planner, grid, geo, pose, n_steps=200, limits=None, points=None):
    """Unicycle integration of the commands; returns poses, commands and whether it arrived."""
    pose = np.array(pose, dtype=float)
    vel = (0.0, 0.0)
    poses, cmds = [pose.copy()], []
    for _ in range(n_steps):
        cmd = planner.compute(pose, vel, grid, geo, obstacle_points_m=points, limits=limits)
        if cmd.goal_reached:
            return np.array(poses), np.array(cmds), True
        cmds.append((cmd.v_mps, cmd.omega_radps))
        for _ in range(10):
            pose[0] += cmd.v_mps * math.cos(pose[2]) * DT_S / 10
            pose[1] += cmd.v_mps * math.sin(pose[2]) * DT_S / 10
            pose[2] += cmd.omega_radps * DT_S / 10
        vel = (cmd.v_mps, cmd.omega_radps)
        poses.append(pose.copy())
    return np.array(poses), np.array(cmds), False


def _straight_path(x_end: float = 3.0) -> np.ndarray:
    xs = np.arange(0.0, x_end + 1e-9, 0.05)
    return np.column_stack([xs, np.zeros_like(xs)])


def test_reaches_goal_in_free_space_from_a_wrong_heading() -> None:
    grid, geo = _world()
    planner = DWAPlanner(FAST)
    planner.set_path(_straight_path())
    poses, cmds, arrived = _simulate(planner, grid, geo, (0.0, 0.0, 2.0))
    assert arrived
    assert math.hypot(poses[-1][0] - 3.0, poses[-1][1]) <= 0.05
    # It turns first, then drives at (near) full speed for most of the way.
    assert np.median(cmds[:, 0]) > 0.2


@pytest.mark.parametrize("limits", [None, (0.15, 2.0)])
def test_commands_never_exceed_limits(limits) -> None:
    prm = FAST
    grid, geo = _world([(1.0, -0.4, 1.2, -0.06)])
    planner = DWAPlanner(prm)
    planner.set_path(_straight_path())
    _, cmds, _ = _simulate(planner, grid, geo, (0.0, 0.3, -2.5), n_steps=120, limits=limits)
    max_v = prm.max_linear_speed_mps if limits is None else limits[0]
    max_w = prm.max_angular_speed_radps if limits is None else limits[1]
    assert (cmds[:, 0] <= max_v + 1e-12).all() and (
        cmds[:, 0] >= prm.min_linear_speed_mps - 1e-12
    ).all()
    assert (np.abs(cmds[:, 1]) <= max_w + 1e-12).all()
    # Acceleration limits: consecutive commands differ by at most one dynamic window.
    dv = np.abs(np.diff(np.vstack([[0.0, 0.0], cmds]), axis=0))
    assert (dv[:, 0] <= prm.linear_accel_mps2 * prm.control_period_s + 1e-9).all()
    assert (dv[:, 1] <= prm.angular_accel_radps2 * prm.control_period_s + 1e-9).all()


def _polyline(points: list[tuple[float, float]], step_m: float = 0.05) -> np.ndarray:
    out = [np.asarray(points[0], dtype=float)]
    for a, b in zip(points[:-1], points[1:], strict=True):
        a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
        n = max(1, int(np.ceil(np.hypot(*(b - a)) / step_m)))
        out.extend(a + (b - a) * k / n for k in range(1, n + 1))
    return np.array(out)


def test_follows_a_detour_round_an_obstacle_without_touching_it() -> None:
    prm = FAST
    grid, geo = _world([(1.0, -0.5, 1.2, 0.0)])  # box across the straight line
    planner = DWAPlanner(prm)
    # A global path that bends round the box with little room to spare at the corners.
    planner.set_path(
        _polyline([(0.0, 0.0), (0.6, 0.0), (0.85, 0.35), (1.35, 0.35), (1.6, 0.0), (3.0, 0.0)])
    )
    poses, _, arrived = _simulate(planner, grid, geo, (0.0, 0.0, 0.0))
    assert arrived
    obstacle = _occupied_xy(grid, geo)
    d = np.hypot(poses[:, None, 0] - obstacle[None, :, 0], poses[:, None, 1] - obstacle[None, :, 1])
    # The robot centre stays farther than radius + margin from every obstacle cell centre (less
    # a little: rollouts are checked every 0.1 s, i.e. every 2.2 cm at full speed).
    assert d.min() > prm.robot_radius_m + prm.clearance_margin_m - 0.01
    assert poses[:, 1].max() > 0.2  # it really went round


def test_never_drives_into_an_obstacle_seen_only_by_the_lidar() -> None:
    prm = FAST
    grid, geo = _world()  # the map knows nothing
    wall = np.column_stack([np.full(81, 1.5), np.linspace(-1.0, 1.0, 81)])
    planner = DWAPlanner(prm)
    planner.set_path(_straight_path())
    poses, _, _ = _simulate(planner, grid, geo, (0.0, 0.0, 0.0), n_steps=80, points=wall)
    d = np.hypot(poses[:, None, 0] - wall[None, :, 0], poses[:, None, 1] - wall[None, :, 1])
    assert d.min() > prm.robot_radius_m + prm.clearance_margin_m - 0.01
    assert poses[:, 0].max() > 1.0  # it did drive up to the wall
    # Without the scan points it drives through the (unmapped) wall.
    planner.set_path(_straight_path())
    poses2, _, arrived2 = _simulate(planner, grid, geo, (0.0, 0.0, 0.0), n_steps=80)
    assert arrived2 and poses2[:, 0].max() > 2.9


def test_min_velocity_filter_never_creeps_or_stands_still() -> None:
    prm = FAST
    grid, geo = _world()
    planner = DWAPlanner(prm)
    planner.set_path(_straight_path())
    poses, cmds, arrived = _simulate(planner, grid, geo, (0.0, 0.0, math.pi), n_steps=120)
    assert arrived
    slow = (np.abs(cmds[:, 0]) < prm.min_trans_speed_mps - 1e-9) & (
        np.abs(cmds[:, 1]) < prm.min_rot_speed_radps - 1e-9
    )
    settling = (
        np.hypot(poses[:-1, 0] - 3.0, poses[:-1, 1]) <= prm.min_trans_speed_mps * prm.sim_time_s
    )
    # Away from the goal, only while spinning up from rest may it turn slower than
    # min_rot_speed (and then v = 0); it never creeps forward slowly.
    assert (cmds[slow & ~settling, 0] == 0.0).all()
    assert (slow & ~settling).sum() <= 3


def test_robot_too_close_to_a_wall_moves_on_without_getting_closer() -> None:
    prm = FAST
    grid, geo = _world([(0.1, -1.5, 0.2, 1.5)])  # wall cells from x = 0.1: centres 0.125 m ahead
    planner = DWAPlanner(prm)
    planner.set_path(_polyline([(0.0, 0.0), (0.0, 0.5), (-0.4, 1.0)]))  # along, then away
    poses, _, arrived = _simulate(planner, grid, geo, (0.0, 0.0, 0.0), n_steps=100)
    wall_x = _occupied_xy(grid, geo)[:, 0].min()
    start_clear = wall_x - 0.0
    assert start_clear < prm.robot_radius_m + prm.clearance_margin_m  # it starts too close
    # ... and never gets closer than 1 cm more (5 mm slack, plus rollouts checked every 0.1 s).
    assert (wall_x - poses[:, 0]).min() >= start_clear - 0.01
    assert arrived


def test_scan_points_drop_invalid_and_max_range_returns() -> None:
    ranges = np.array([1.0, 0.0, 3.5, 2.0], dtype=np.float32)
    pts = scan_points_m((1.0, 2.0, math.pi / 2), ranges, max_range_m=3.5)
    # Beam 0 points along +y (yaw), beam 3 at yaw + 3*pi/2 = along +x.
    assert pts == pytest.approx(np.array([[1.0, 3.0], [3.0, 2.0]]), abs=1e-9)


def test_bad_params_raise() -> None:
    with pytest.raises(ValueError, match="max_linear_speed_mps"):
        DWAParams(max_linear_speed_mps=0.0)
    with pytest.raises(ValueError, match="linear_samples"):
        DWAParams(linear_samples=1)
    with pytest.raises(ValueError, match="min_linear_speed_mps"):
        DWAParams(min_linear_speed_mps=0.5)
    with pytest.raises(ValueError, match="path_m"):
        DWAPlanner().set_path(np.zeros((0, 2)))
