"""``sb3:`` models trained on each observation variant of the env run as policies, or fail
with a message naming the wrapper they need (tiny PPO models trained for a few steps here)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

pytest.importorskip("stable_baselines3")

from semexplore_gym.policies.registry import make_policy

from semexplore_gym.evaluation.rollout import make_mission_env, run_mission

WORLD = "maze:seed=0,size_m=4"
OTHER_WORLD = "maze:seed=0,size_m=5"  # another grid size
LIMIT = ["episode.max_time_s=20"]


def _train_tiny_ppo(env: Any, path: Path) -> Path:
    from stable_baselines3 import PPO

    policy = "MultiInputPolicy" if hasattr(env.observation_space, "spaces") else "MlpPolicy"
    model = PPO(policy, env, n_steps=8, batch_size=8, n_epochs=1, seed=0, device="cpu")
    model.learn(total_timesteps=8)
    model.save(str(path))
    env.close()
    return path


def _run(spec: str, world: str = WORLD, **overrides: Any) -> Any:
    env = make_mission_env(world, overrides=LIMIT)
    try:
        return run_mission(env, make_policy(spec, **overrides), seed=1, max_time_s=2.0)
    finally:
        env.close()


@pytest.fixture(scope="module")
def raw_model(tmp_path_factory: pytest.TempPathFactory, one_torch_thread: None) -> Path:
    path = tmp_path_factory.mktemp("raw") / "model.zip"
    return _train_tiny_ppo(make_mission_env(WORLD, overrides=LIMIT), path)


def test_raw_dict_model_runs_on_its_world_size(raw_model: Path) -> None:
    res = _run(f"sb3:{raw_model}")
    assert res.steps > 0 and res.mission_time_s > 0


def test_raw_dict_model_on_another_world_size_names_fixed_size_map(raw_model: Path) -> None:
    with pytest.raises(ValueError, match="FixedSizeMap"):
        _run(f"sb3:{raw_model}", world=OTHER_WORLD)


@pytest.mark.parametrize("anchor", ["world", "robot"])
def test_fixed_size_map_model_runs_on_any_world(
    tmp_path: Path, anchor: str, one_torch_thread: None
) -> None:
    from semexplore_gym.wrappers import FixedSizeMap

    env = FixedSizeMap(make_mission_env(WORLD, overrides=LIMIT), map_size=40, anchor=anchor)
    path = _train_tiny_ppo(env, tmp_path / "model.zip")
    policy = make_policy(f"sb3:{path}", map_anchor=anchor)
    assert policy.variant == "fixed_size"
    for world in (WORLD, OTHER_WORLD):
        assert _run(f"sb3:{path}", world=world, map_anchor=anchor).steps > 0


def test_fixed_size_features_equal_the_wrapper_observation(
    tmp_path: Path, one_torch_thread: None
) -> None:
    import numpy as np

    from semexplore_gym.wrappers import FixedSizeMap

    env = FixedSizeMap(make_mission_env(WORLD, overrides=LIMIT), map_size=40, anchor="robot")
    path = _train_tiny_ppo(env, tmp_path / "model.zip")
    policy = make_policy(f"sb3:{path}", map_anchor="robot")
    wrapped = FixedSizeMap(make_mission_env(WORLD, overrides=LIMIT), map_size=40, anchor="robot")
    obs, info = wrapped.reset(seed=2)
    raw, raw_info = wrapped.env.reset(seed=2)  # the same reset, unwrapped
    policy.reset(raw, raw_info, seed=2)
    np.testing.assert_array_equal(policy._features(raw, raw_info)["map"], obs["map"])
    wrapped.close()


def test_flat_vector_model_names_the_wrappers(tmp_path: Path) -> None:
    from gymnasium.wrappers import FlattenObservation

    path = _train_tiny_ppo(
        FlattenObservation(make_mission_env(WORLD, overrides=LIMIT)), tmp_path / "model.zip"
    )
    with pytest.raises(ValueError, match="SemanticExploreFrontier-v0.*FixedSizeMap"):
        make_policy(f"sb3:{path}")
