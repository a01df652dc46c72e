"""Recovery manoeuvres: move_base's rotation and the expert's back-off."""

from __future__ import annotations

import math

import numpy as np
from semexplore_gym.policies.navigation import BackoffRecovery, RotateRecovery

from semexplore_gym.core.grid import FREE, GridGeometry
from semexplore_gym.core.planning.potential_field import PotentialFieldParams, RobotLimits

LIMITS = RobotLimits(
    radius_m=0.105, max_linear_speed_mps=0.22, max_angular_speed_radps=2.84, max_range_m=3.5
)


def test_rotation_turns_once_round_at_the_capped_speed() -> None:
    rot = RotateRecovery(2.0 * math.pi, angular_speed_radps=1.0)
    assert not rot.active
    rot.start()
    turns = []
    while rot.active:
        turns.append(rot.turn(max_angular_speed_radps=0.5, dt_s=0.2))
    assert set(turns) == {0.5} and len(turns) == math.ceil(2.0 * math.pi / 0.1)
    rot.start()
    rot.stop()
    assert not rot.active


def test_backoff_runs_for_its_duration_then_finishes_once() -> None:
    rec = BackoffRecovery(duration_s=1.5, speed_fraction=0.5)
    assert not rec.active(0.0) and not rec.finish()
    rec.start(2.0, np.random.default_rng(0))
    assert rec.active(3.4) and not rec.active(3.5)
    assert rec.finish() and not rec.finish()


def test_backoff_reverses_in_open_space_and_turns_when_boxed_in() -> None:
    geo = GridGeometry(0.05, 0.0, 0.0, 60, 60)
    grid = np.full((60, 60), FREE, dtype=np.uint8)
    angles = np.arange(360) * (2.0 * math.pi / 360)
    rec = BackoffRecovery(duration_s=1.5, speed_fraction=0.5)
    rec.start(0.0, np.random.default_rng(0))
    guard = PotentialFieldParams()
    v, w = rec.command(grid, geo, (1.5, 1.5, 0.0), np.full(360, 3.5), angles, LIMITS, guard)
    assert v < 0.0 and w == 0.0 and v >= -0.5 * LIMITS.max_linear_speed_mps
    # A wall right behind, the most open beam at +90 degrees: turn left on the spot.
    scan = np.full(360, 0.15)
    scan[90] = 2.0
    v, w = rec.command(grid, geo, (1.5, 1.5, 0.0), scan, angles, LIMITS, guard)
    assert v == 0.0 and w == LIMITS.max_angular_speed_radps
