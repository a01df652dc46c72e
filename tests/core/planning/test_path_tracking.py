"""Slow, exact path tracking for passages barely wider than the robot (core/planning/path_tracking)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from semexplore_gym.core.planning.path_tracking import (
    path_clearance_ahead_m,
    tight_tracking_command,
)

STRAIGHT = np.column_stack([np.linspace(0.0, 2.0, 41), np.zeros(41)])  # along +x
KW = {"lookahead_m": 0.06, "speed_mps": 0.08, "max_omega_radps": 2.0, "turn_in_place_rad": 0.15}


def test_on_the_path_and_facing_along_it_the_robot_drives_straight_at_the_set_speed():
    v, w = tight_tracking_command((0.0, 0.0, 0.0), STRAIGHT, 0, **KW)
    assert v == pytest.approx(0.08) and w == pytest.approx(0.0)


def test_a_large_heading_error_turns_on_the_spot_towards_the_path():
    v, w = tight_tracking_command((0.0, 0.0, -0.5), STRAIGHT, 0, **KW)
    assert v == 0.0 and w > 0  # turn left (counter-clockwise) back onto +x
    v, w = tight_tracking_command((0.0, 0.0, 0.1), STRAIGHT, 0, **KW)
    assert 0 < v < 0.08 and w < 0  # small error: drive, slower, and steer right


def test_the_target_is_a_lookahead_ahead_from_the_progress_index():
    # Robot beside the path's end, progress there: it aims at the last point (behind it).
    v, w = tight_tracking_command((2.5, 0.0, 0.0), STRAIGHT, 40, **KW)
    assert v == 0.0 and abs(w) > 0


def test_bad_tracking_parameters_are_refused_by_name():
    with pytest.raises(ValueError, match="speed_mps"):
        tight_tracking_command((0.0, 0.0, 0.0), STRAIGHT, 0, **{**KW, "speed_mps": 0.0})
    with pytest.raises(ValueError, match="path_m"):
        tight_tracking_command((0.0, 0.0, 0.0), np.zeros((0, 2)), 0, **KW)


def test_the_clearance_ahead_is_the_least_over_the_stretch():
    field = np.array([[0.3, 0.2], [0.1, 0.4]])
    assert path_clearance_ahead_m(field, np.array([0, 1]), np.array([0, 0])) == pytest.approx(0.1)
    assert path_clearance_ahead_m(field, np.array([], int), np.array([], int)) == math.inf
