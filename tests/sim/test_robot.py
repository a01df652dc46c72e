"""Physics of the TurtleBot3 disc: walls stop it, at any speed, without penetration."""

from __future__ import annotations

import math
import pickle

import numpy as np
import pytest

from semexplore_gym.core.grid import GridGeometry
from semexplore_gym.core.worlds.world import World
from semexplore_gym.sim.robot import PhysicsParams, RobotParams, RobotSim, nearest_wall_distance_m

BOX = np.array(
    [[0, 0, 4, 0], [4, 0, 4, 4], [4, 4, 0, 4], [0, 4, 0, 0], [2, 0, 2, 1.5]], dtype=float
)


def _world() -> World:
    return World(
        "box", BOX, (0.0, 0.0, 4.0, 4.0), np.ones((80, 80), bool), GridGeometry(0.05, 0, 0, 80, 80)
    )


def test_free_drive_follows_the_exact_arc() -> None:
    sim = RobotSim(_world(), RobotParams(), PhysicsParams())
    sim.reset((1.0, 2.0, 0.0))
    v, w, dt = 0.2, 1.0, 0.2
    for _ in range(5):
        sim.step(v, w, dt)
    t = 1.0
    x_exp = 1.0 + v / w * math.sin(w * t)
    y_exp = 2.0 + v / w * (1 - math.cos(w * t))
    x, y, yaw = sim.pose
    assert x == pytest.approx(x_exp, abs=1e-9)
    assert y == pytest.approx(y_exp, abs=1e-9)
    assert yaw == pytest.approx(w * t, abs=1e-9)
    assert sim.collisions == 0


def test_wall_stops_the_robot_and_counts_one_collision() -> None:
    sim = RobotSim(_world(), RobotParams(), PhysicsParams())
    sim.reset((1.0, 1.0, -math.pi / 2))  # facing the y=0 wall
    for _ in range(100):
        sim.step(0.22, 0.0, 0.2)
    x, y, _ = sim.pose
    assert y == pytest.approx(0.105, abs=0.006)
    assert x == pytest.approx(1.0, abs=1e-3)
    assert sim.collisions == 1


@pytest.mark.parametrize("speed_mps", [0.22, 1.0])
def test_no_penetration_over_10000_random_max_speed_steps(speed_mps: float) -> None:
    rp = RobotParams(max_linear_speed_mps=speed_mps)
    sim = RobotSim(_world(), rp, PhysicsParams())
    sim.reset((1.0, 1.0, 0.3))
    rng = np.random.default_rng(0)
    min_clear = math.inf
    for _ in range(10_000):
        turn = rng.uniform(-1, 1)
        sim.step(
            speed_mps * (1.0 if rng.random() < 0.7 else -1.0),
            turn * rp.max_angular_speed_radps,
            0.2,
        )
        x, y, _ = sim.pose
        assert 0.0 < x < 4.0 and 0.0 < y < 4.0, f"robot left the box at {(x, y)}"
        min_clear = min(min_clear, nearest_wall_distance_m(BOX, x, y))
    assert min_clear > rp.radius_m - 0.01
    assert sim.collisions > 0


def test_pickle_round_trip_keeps_state() -> None:
    sim = RobotSim(_world(), RobotParams(), PhysicsParams())
    sim.reset((1.0, 1.0, 0.0))
    for _ in range(7):
        sim.step(0.2, 0.5, 0.2)
    clone = pickle.loads(pickle.dumps(sim))
    assert clone.pose == sim.pose
    for _ in range(20):
        sim.step(0.2, -0.3, 0.2)
        clone.step(0.2, -0.3, 0.2)
    assert clone.pose == pytest.approx(sim.pose, abs=1e-9)


@pytest.mark.parametrize(
    "field,value", [("radius_m", 0.0), ("max_linear_speed_mps", float("nan")), ("mass_kg", -1.0)]
)
def test_bad_robot_params_name_the_field(field: str, value: float) -> None:
    with pytest.raises(ValueError, match=field):
        RobotParams(**{field: value})
