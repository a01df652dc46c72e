"""The reward terms say what they are: ``free_area_change`` is the net change of free area."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import semexplore_gym  # noqa: F401  (registers the env)
from semexplore_gym.config import ConfigError


def test_free_area_change_is_the_net_change_of_the_maps_free_area() -> None:
    env = gym.make("SemanticExplore-v0", world="maze1")
    _, info = env.reset(seed=3)
    assert info["reward_terms"]["free_area_change"] == 0.0
    area = info["explored_area_m2"]
    rng = np.random.default_rng(0)
    changes = []
    for _ in range(300):
        _, reward, _, _, info = env.step(rng.uniform(-1, 1, 2).astype(np.float32))
        term = info["reward_terms"]["free_area_change"]
        assert term == pytest.approx(info["explored_area_m2"] - area, abs=1e-9)
        assert reward == pytest.approx(sum(info["reward_terms"].values()))
        area = info["explored_area_m2"]
        changes.append(term)
    changes_a = np.asarray(changes)
    # Net, as documented: free cells re-marked occupied make some steps negative.
    assert (changes_a < 0).any() and changes_a.sum() > 0


def test_free_area_change_weight_scales_the_term() -> None:
    env = gym.make(
        "SemanticExplore-v0", world="maze1", overrides=["reward.free_area_change_weight=2.5"]
    )
    _, info = env.reset(seed=0)
    area = info["explored_area_m2"]
    for _ in range(10):
        _, _, _, _, info = env.step(np.array([1.0, 0.0], np.float32))
        change = info["explored_area_m2"] - area
        area = info["explored_area_m2"]
        assert info["reward_terms"]["free_area_change"] == pytest.approx(2.5 * change, abs=1e-9)
        assert info["reward_terms"]["time"] == pytest.approx(-0.01 * 0.2)
    assert area > 0


@pytest.mark.parametrize(
    "kwargs",
    [
        {"config": {"reward": {"new_area_weight": 2.0}}},
        {"overrides": ["reward.new_area_weight=2"]},
    ],
)
def test_the_old_new_area_key_fails_naming_the_new_one(kwargs) -> None:
    with pytest.raises(ConfigError, match=r"renamed 'reward\.free_area_change_weight'.*net change"):
        gym.make("SemanticExplore-v0", world="maze1", **kwargs)
