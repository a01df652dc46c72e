"""FixedSizeMap: one observation shape for every world; checkers and mixed-world vector envs."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import semexplore_gym  # noqa: F401
from semexplore_gym import UNKNOWN
from semexplore_gym.wrappers import FixedSizeMap


@pytest.mark.parametrize("anchor", ["world", "robot"])
def test_image_is_the_map_window_padded_with_unknown(anchor: str) -> None:
    env = FixedSizeMap(gym.make("SemanticExplore-v0", world="maze1"), map_size=96, anchor=anchor)
    obs, info = env.reset(seed=0)
    rng = np.random.default_rng(0)
    for _ in range(20):
        obs, *_, info = env.step(rng.uniform(-1, 1, 2).astype(np.float32))
    assert obs["map"].shape == (1, 96, 96) and obs["map"].dtype == np.uint8
    assert env.observation_space.contains(obs)
    dr, dc = info["map_offset_cells"]
    # Reconstruct from a second, unwrapped env stepped identically.
    raw = gym.make("SemanticExplore-v0", world="maze1")
    robs, _ = raw.reset(seed=0)
    rng = np.random.default_rng(0)
    for _ in range(20):
        robs, *_ = raw.step(rng.uniform(-1, 1, 2).astype(np.float32))
    m = robs["map"]
    for r in range(0, 96, 7):
        for c in range(0, 96, 5):
            rr, cc = r + dr, c + dc
            want = m[rr, cc] if 0 <= rr < m.shape[0] and 0 <= cc < m.shape[1] else UNKNOWN
            assert obs["map"][0, r, c] == want
    if anchor == "robot":
        row, col = env.unwrapped.map_geometry.world_to_grid(*obs["pose"][:2])
        assert (int(row) - dr, int(col) - dc) == (48, 48)


def test_mixed_worlds_share_one_vector_env_and_pass_the_checkers() -> None:
    worlds = ["maze1", "cave:seed=1,size_m=10", "forest:seed=2"]
    envs = gym.vector.SyncVectorEnv(
        [
            lambda w=w: FixedSizeMap(gym.make("SemanticExplore-v0", world=w), map_size=64)
            for w in worlds
        ]
    )
    obs, _ = envs.reset(seed=0)
    assert obs["map"].shape == (3, 1, 64, 64)
    obs, *_ = envs.step(np.zeros((3, 2), dtype=np.float32))
    assert obs["map"].shape == (3, 1, 64, 64)
    envs.close()
    vec = gym.make_vec(
        "SemanticExplore-v0",
        num_envs=2,
        vectorization_mode="sync",
        wrappers=[lambda e: FixedSizeMap(e, map_size=64, anchor="robot")],
    )
    assert vec.reset(seed=1)[0]["map"].shape == (2, 1, 64, 64)
    vec.close()
    import warnings

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        check_env(
            FixedSizeMap(gym.make("SemanticExplore-v0", world="maze2"), map_size=64),
            skip_render_check=True,
        )
    # The checker only notes that it was given a wrapper (which is the point here).
    assert [str(w.message) for w in caught if "unwrapped" not in str(w.message)] == []


def test_sb3_takes_it_without_warnings() -> None:
    sb3 = pytest.importorskip("stable_baselines3")
    import warnings

    from stable_baselines3.common.env_checker import check_env as sb3_check_env

    env = FixedSizeMap(gym.make("SemanticExplore-v0", world="maze1"), map_size=64)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        sb3_check_env(env, warn=True)
    model = sb3.PPO("MultiInputPolicy", env, n_steps=8, batch_size=8, n_epochs=1, device="cpu")
    model.learn(8)
    action, _ = model.predict(env.reset(seed=1)[0], deterministic=True)
    assert action.shape == (2,)


@pytest.mark.parametrize(
    "kwargs, needle",
    [({"map_size": 4}, "map_size"), ({"map_size": 64.5}, "map_size"), ({"anchor": "up"}, "anchor")],
)
def test_bad_arguments_are_named(kwargs: dict, needle: str) -> None:
    with pytest.raises(ValueError, match=needle):
        FixedSizeMap(gym.make("SemanticExplore-v0", world="maze1"), **kwargs)
