"""Per-step ``info``: the same keys and values every step, the static part built once."""

from __future__ import annotations

import pickle

import gymnasium as gym
import numpy as np
import pytest

import semexplore_gym  # noqa: F401
from semexplore_gym.envs.semantic_explore import FrozenInfo

STATIC = ("map_geometry", "robot", "lidar")


def test_static_entries_are_shared_read_only_and_equal_to_plain_dicts() -> None:
    env = gym.make("SemanticExplore-v0", world="maze1")
    _, info0 = env.reset(seed=0)
    _, _, _, _, info1 = env.step(np.zeros(2, np.float32))
    u = env.unwrapped
    assert info0["map_geometry"] == u.map_geometry.to_dict()
    assert dict(info1["robot"]) == {
        "radius_m": u.config.robot.radius_m,
        "max_linear_speed_mps": u.config.robot.max_linear_speed_mps,
        "max_angular_speed_radps": u.config.robot.max_angular_speed_radps,
    }
    assert info1["lidar"]["n_beams"] == 360 and info1["dt_s"] == u.config.episode.dt_s
    for k in STATIC:
        assert isinstance(info1[k], FrozenInfo) and info1[k] is info0[k]
        with pytest.raises(TypeError):
            info1[k]["x"] = 1  # type: ignore[index]
    assert info1 is not info0 and info1["reward_terms"] is not info0["reward_terms"]
    assert set(info1) == {
        *STATIC,
        "dt_s",
        "coverage",
        "explored_area_m2",
        "collisions",
        "sim_time_s",
        "path_length_m",
        "reward_terms",
    }


def test_info_pickles_and_works_in_vector_envs() -> None:
    env = gym.make("SemanticExplore-v0", world="maze1")
    _, info = env.reset(seed=0)
    clone = pickle.loads(pickle.dumps(info))
    assert clone["lidar"] == info["lidar"] and isinstance(clone["lidar"], FrozenInfo)
    venv = gym.vector.SyncVectorEnv([lambda: gym.make("SemanticExplore-v0", world="maze1")] * 2)
    try:
        venv.reset(seed=0)
        _, _, _, _, vinfo = venv.step(np.zeros((2, 2), np.float32))
        assert vinfo["lidar"].dtype == object and vinfo["lidar"][1]["max_range_m"] == 3.5
        assert vinfo["coverage"].shape == (2,) and vinfo["reward_terms"]["time"].shape == (2,)
    finally:
        venv.close()


def test_info_numbers_are_the_step_info_keys_in_order() -> None:
    # The vector env's direct path builds info from INFO_NUMBERS and info_numbers().
    from semexplore_gym.envs.semantic_explore import INFO_NUMBERS

    env = gym.make("SemanticExplore-v0", world="maze1", static_info="reset")
    env.reset(seed=0)
    _, _, _, _, info = env.step(np.ones(2, np.float32))
    assert tuple(info) == (*INFO_NUMBERS, "reward_terms")
    assert tuple(info[k] for k in INFO_NUMBERS) == env.unwrapped.info_numbers()
    env.close()
