"""The fast tier (``pytest -m "not slow"``) stays fast: ``tests/conftest.py`` counts the
simulated seconds of the env missions each test runs and fails a test not marked ``slow`` that
goes over ``FAST_TIER_SIMULATED_S`` (DEVELOPERS.md, "Tests")."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import semexplore_gym  # noqa: F401  (registers the env)


def test_the_guard_counts_the_simulated_time_of_env_steps(_simulated_clock) -> None:
    env = gym.make("SemanticExplore-v0", world="maze:seed=0,size_m=3")
    env.reset(seed=0)
    before = _simulated_clock.seconds
    for _ in range(5):
        env.step(np.zeros(2, dtype=np.float32))
    dt_s = env.unwrapped.config.episode.dt_s
    assert _simulated_clock.seconds - before == pytest.approx(5 * dt_s)
    env.close()


def test_the_guard_counts_the_multi_robot_env_per_team_step(_simulated_clock) -> None:
    pytest.importorskip("pettingzoo")
    from semexplore_gym.envs.multi_robot import make_multi

    env = make_multi(world="maze:seed=0,size_m=4", n_robots=2)
    env.reset(seed=0)
    before = _simulated_clock.seconds
    env.step({a: np.zeros(2, dtype=np.float32) for a in env.agents})
    assert _simulated_clock.seconds - before == pytest.approx(env.config.episode.dt_s)
    env.close()
