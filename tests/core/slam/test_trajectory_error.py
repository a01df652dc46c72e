"""The relative pose error over 1 m of travel."""

from __future__ import annotations

import math

import numpy as np
import pytest

from semexplore_gym.core.slam.trajectory_error import relative_pose_error_m


def _straight(n: int, step_m: float, yaw: float = 0.0) -> np.ndarray:
    s = np.arange(n) * step_m
    return np.column_stack([s * math.cos(yaw), s * math.sin(yaw), np.full(n, yaw)])


def test_a_constant_offset_has_no_relative_error() -> None:
    truth = _straight(21, 0.25)
    shifted = truth + np.array([0.7, -0.3, 0.0])
    assert relative_pose_error_m(shifted, truth) == pytest.approx(0.0, abs=1e-12)


def test_a_scale_error_shows_per_metre_of_travel() -> None:
    truth = _straight(21, 0.25)  # 5 m
    est = truth * np.array([1.1, 1.0, 1.0])  # 10 % too long: 0.1 m per metre
    assert relative_pose_error_m(est, truth) == pytest.approx(0.1)
    # Over 2 m of travel the same drift is twice the error.
    assert relative_pose_error_m(est, truth, delta_m=2.0) == pytest.approx(0.2)


def test_a_heading_error_is_measured_in_the_frame_of_the_start_pose() -> None:
    truth = _straight(9, 0.25)
    est = truth.copy()
    est[:, 2] = 0.1  # the estimate thinks it looks 0.1 rad left while moving along x
    # In its own frame the estimated motion over 1 m bends right by 0.1 rad.
    expected = math.hypot(1 - math.cos(0.1), math.sin(0.1))
    assert relative_pose_error_m(est, truth) == pytest.approx(expected)


def test_less_travel_than_delta_gives_none_and_bad_shapes_raise() -> None:
    truth = _straight(3, 0.25)  # 0.5 m
    assert relative_pose_error_m(truth, truth) is None
    with pytest.raises(ValueError, match=r"must both be \(n, 3\)"):
        relative_pose_error_m(truth[:, :2], truth[:, :2])
