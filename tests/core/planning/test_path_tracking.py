"""Slow, exact path tracking for passages barely wider than the robot (core/planning/path_tracking)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from semexplore_gym.core.planning.path_tracking import (
    TightTracking,
    path_clearance_ahead_m,
    path_heading_rad,
    safe_forward_speed_mps,
    scan_centring_offset_m,
    tight_tracking_command,
)
from semexplore_gym.core.planning.potential_field import beam_angles_rad

ANGLES = beam_angles_rad(360)
STRAIGHT = np.column_stack([np.linspace(0.0, 2.0, 41), np.zeros(41)])  # along +x
KW = {"lookahead_m": 0.06, "speed_mps": 0.08, "max_omega_radps": 2.0, "turn_in_place_rad": 0.15}
TRACK = TightTracking(**KW)


def corridor_scan(y_m: float, half_width_m: float, yaw_rad: float = 0.0) -> np.ndarray:
    """Ranges from (0, y_m) heading ``yaw_rad`` in an endless corridor |y| <= half_width_m
    along x (a 3.5 m LiDAR, returns under 0.12 m read 0)."""
    world = ANGLES + yaw_rad
    s = np.sin(world)
    with np.errstate(divide="ignore"):
        up = np.where(s > 1e-9, (half_width_m - y_m) / s, np.inf)
        down = np.where(s < -1e-9, (-half_width_m - y_m) / s, np.inf)
    r = np.minimum(np.minimum(up, down), 3.5)
    return np.where(r < 0.12, 0.0, r)


def test_on_the_path_and_facing_along_it_the_robot_drives_straight_at_the_set_speed():
    v, w = tight_tracking_command((0.0, 0.0, 0.0), STRAIGHT, 0, TRACK)
    assert v == pytest.approx(0.08) and w == pytest.approx(0.0)


def test_a_large_heading_error_turns_on_the_spot_towards_the_path():
    v, w = tight_tracking_command((0.0, 0.0, -0.5), STRAIGHT, 0, TRACK)
    assert v == 0.0 and w > 0  # turn left (counter-clockwise) back onto +x
    v, w = tight_tracking_command((0.0, 0.0, 0.1), STRAIGHT, 0, TRACK)
    assert v > 0 and w < 0  # small error: drive and steer right


def test_the_target_is_a_lookahead_ahead_from_the_progress_index():
    # Robot beyond the path's end, progress there: it aims at the last point (behind it).
    v, w = tight_tracking_command((2.5, 0.0, 0.0), STRAIGHT, 40, TRACK)
    assert v == 0.0 and abs(w) > 0


def test_a_lateral_shift_moves_the_target_to_the_paths_left():
    _, w = tight_tracking_command((0.0, 0.0, 0.0), STRAIGHT, 0, TRACK, 0.01)
    assert w > 0
    _, w = tight_tracking_command((0.0, 0.0, 0.0), STRAIGHT, 0, TRACK, -0.01)
    assert w < 0


def test_bad_tracking_parameters_are_refused_by_name():
    with pytest.raises(ValueError, match="speed_mps"):
        TightTracking(**{**KW, "speed_mps": 0.0})
    with pytest.raises(ValueError, match="path_m"):
        tight_tracking_command((0.0, 0.0, 0.0), np.zeros((0, 2)), 0, TRACK)


def test_the_scan_says_how_far_the_robot_sits_off_the_corridors_middle():
    # 0.26 m corridor, robot 1 cm right of its middle (y = -0.01): move left by 1 cm.
    scan = corridor_scan(-0.01, 0.13)
    offset = scan_centring_offset_m(scan, ANGLES, min_range_m=0.12, reach_m=0.3)
    assert offset == pytest.approx(0.01, abs=2e-3)
    # The same, seen with the robot turned: measured across the path, not the robot.
    turned = corridor_scan(-0.01, 0.13, yaw_rad=0.4)
    offset = scan_centring_offset_m(
        turned, ANGLES, min_range_m=0.12, reach_m=0.3, left_rad=0.5 * math.pi - 0.4
    )
    assert offset == pytest.approx(0.01, abs=3e-3)
    # Walls farther than the reach on one side: no correction.
    wide = corridor_scan(-0.01, 0.6)
    assert scan_centring_offset_m(wide, ANGLES, min_range_m=0.12, reach_m=0.3) == 0.0


def test_no_forward_step_brings_the_body_against_a_return_ahead():
    clear = corridor_scan(0.0, 0.13)
    assert safe_forward_speed_mps(clear, ANGLES, radius_m=0.105, dt_s=0.2, spare_m=0.003) > 0.2
    wall = np.full(360, 3.5)
    wall[0] = 0.115  # a return straight ahead, 1 cm from the body
    v = safe_forward_speed_mps(wall, ANGLES, radius_m=0.105, dt_s=0.2, spare_m=0.003)
    assert v == pytest.approx((0.115 - 0.108) / 0.2)
    wall[0] = 0.0  # under the LiDAR's minimum range: no forward step at all
    assert safe_forward_speed_mps(wall, ANGLES, radius_m=0.105, dt_s=0.2, spare_m=0.003) == 0.0
    behind = np.full(360, 3.5)
    behind[180] = 0.0  # straight behind does not matter
    assert safe_forward_speed_mps(behind, ANGLES, radius_m=0.105, dt_s=0.2, spare_m=0.003) > 1


def test_path_helpers():
    assert path_heading_rad(STRAIGHT, 5) == pytest.approx(0.0)
    up = np.array([[0.0, 0.0], [0.0, 1.0]])
    assert path_heading_rad(up, 0) == pytest.approx(0.5 * math.pi)
    field = np.array([[0.3, 0.2], [0.1, 0.4]])
    assert path_clearance_ahead_m(field, np.array([0, 1]), np.array([0, 0])) == pytest.approx(0.1)
    assert path_clearance_ahead_m(field, np.array([], int), np.array([], int)) == math.inf
