"""The SemanticExplore-v0 env: API checks, determinism, pickling, vector envs, bad input."""

from __future__ import annotations

import math
import pickle

import gymnasium as gym
import numpy as np
import pytest

import semexplore_gym
from semexplore_gym import FREE, OCCUPIED, UNKNOWN
from semexplore_gym.config import ConfigError


def _make(**kw):
    kw.setdefault("world", "maze1")
    return gym.make("SemanticExplore-v0", **kw)


def _rollout(env, seed: int, n: int) -> tuple[list[tuple[float, float, float]], list[float]]:
    obs, info = env.reset(seed=seed)
    rng = np.random.default_rng(seed)
    poses, rewards = [tuple(obs["pose"])], []
    for _ in range(n):
        obs, r, term, trunc, info = env.step(rng.uniform(-1, 1, 2).astype(np.float32))
        poses.append(tuple(obs["pose"]))
        rewards.append(r)
        if term or trunc:
            break
    return poses, rewards


def test_registered_and_constants_exported() -> None:
    assert "SemanticExplore-v0" in gym.registry
    assert {UNKNOWN, FREE, OCCUPIED} == {128, 255, 0}
    semexplore_gym.register_envs()  # idempotent


def test_gymnasium_check_env() -> None:
    from gymnasium.utils.env_checker import check_env

    env = _make()
    check_env(env.unwrapped, skip_render_check=True)


def test_sb3_check_env() -> None:
    sb3 = pytest.importorskip("stable_baselines3")
    from stable_baselines3.common.env_checker import check_env

    check_env(_make().unwrapped, warn=True)
    assert sb3.__version__


def test_observation_contents_after_reset() -> None:
    env = _make()
    obs, info = env.reset(seed=0)
    assert env.observation_space.contains(obs)
    g = info["map_geometry"]
    assert obs["map"].shape == (g["height"], g["width"])
    assert obs["map"].dtype == np.uint8
    assert set(np.unique(obs["map"])) <= {UNKNOWN, FREE, OCCUPIED}
    assert (obs["map"] == FREE).sum() > 100, "the first scan must map free space"
    assert (obs["map"] == OCCUPIED).sum() > 10
    assert obs["scan"].shape == (360,)
    assert 0 < info["coverage"] < 0.5
    assert info["explored_area_m2"] == pytest.approx(
        (obs["map"] == FREE).sum() * g["resolution_m"] ** 2
    )
    for key in (
        "robot",
        "lidar",
        "dt_s",
        "collisions",
        "sim_time_s",
        "path_length_m",
        "reward_terms",
    ):
        assert key in info


def test_same_seed_same_trajectory_and_different_seed_differs() -> None:
    a = _rollout(_make(config={"episode": {"random_start": True}}), seed=3, n=60)
    b = _rollout(_make(config={"episode": {"random_start": True}}), seed=3, n=60)
    c = _rollout(_make(config={"episode": {"random_start": True}}), seed=4, n=60)
    assert a == b
    assert a[0] != c[0]


def test_noise_and_dropouts_are_seeded() -> None:
    cfg = {
        "lidar": {"range_noise_std_m": 0.01, "dropout_prob": 0.05},
        "odometry": {"trans_from_trans": 0.05},
    }
    e1, e2 = _make(config=cfg), _make(config=cfg)
    o1, _ = e1.reset(seed=11)
    o2, _ = e2.reset(seed=11)
    assert np.array_equal(o1["scan"], o2["scan"])
    assert (o1["scan"] == 0).sum() > 0, "dropouts must produce invalid (0) beams"
    for _ in range(10):
        o1, *_ = e1.step(np.array([1.0, 0.2], np.float32))
        o2, *_ = e2.step(np.array([1.0, 0.2], np.float32))
    assert np.array_equal(o1["map"], o2["map"]) and np.array_equal(o1["pose"], o2["pose"])


def test_reward_terms_sum_to_reward_and_new_area_is_positive_while_exploring() -> None:
    env = _make()
    env.reset(seed=0)
    total_new = 0.0
    spin = []
    for _ in range(5):  # a 360-degree LiDAR sees nothing new by turning on the spot
        _, r, _, _, info = env.step(np.array([0.0, 1.0], np.float32))
        spin.append(info["reward_terms"]["free_area_change"])
    assert info["path_length_m"] == pytest.approx(0.0, abs=1e-9)
    assert sum(spin) == pytest.approx(0.0, abs=0.05)
    for _ in range(15):
        _, r, _, _, info = env.step(np.array([1.0, 0.0], np.float32))
        assert r == pytest.approx(sum(info["reward_terms"].values()))
        total_new += info["reward_terms"]["free_area_change"]
    assert total_new > 0.0
    assert info["sim_time_s"] == pytest.approx(4.0)
    assert info["path_length_m"] > 0.2


def test_truncates_at_max_time() -> None:
    env = _make(config={"episode": {"max_time_s": 2.0}})
    env.reset(seed=0)
    for i in range(10):  # noqa: B007 (i is checked after the loop)
        *_, term, trunc, info = env.step(np.zeros(2, np.float32))
        if trunc:
            break
    assert trunc and i == 9 and info["sim_time_s"] == pytest.approx(2.0)


def test_pickle_round_trip_continues_identically() -> None:
    env = _make().unwrapped
    env.reset(seed=5)
    for _ in range(5):
        env.step(np.array([1.0, 0.3], np.float32))
    clone = pickle.loads(pickle.dumps(env))
    for _ in range(15):
        oa, ra, *_ = env.step(np.array([0.8, -0.4], np.float32))
        ob, rb, *_ = clone.step(np.array([0.8, -0.4], np.float32))
    assert np.array_equal(oa["map"], ob["map"])
    assert np.allclose(oa["pose"], ob["pose"])
    assert ra == rb


def test_sync_and_async_vector_envs() -> None:
    for cls in (gym.vector.SyncVectorEnv, gym.vector.AsyncVectorEnv):
        venv = cls([lambda: _make() for _ in range(2)])
        obs, info = venv.reset(seed=[0, 1])
        assert obs["map"].shape[0] == 2
        obs, r, term, trunc, info = venv.step(np.zeros((2, 2), np.float32))
        assert r.shape == (2,)
        venv.close()


def test_render_rgb_array_shape_and_overlay() -> None:
    env = _make(render_mode="rgb_array")
    env.reset(seed=0)
    frame = env.render()
    assert frame.ndim == 3 and frame.shape[2] == 3 and frame.dtype == np.uint8
    base = env.unwrapped
    h, w = base.map_geometry.shape
    x, y, _ = base.sim.pose
    base.set_overlay(
        {
            "goal_m": (x + 1.0, y),
            "paths_m": [np.array([[x, y], [x + 1.0, y]])],
            "area_types": np.zeros((h, w), np.int16),
        }
    )
    frame2 = env.render()
    assert frame2.shape == frame.shape and not np.array_equal(frame, frame2)


def test_paper_config_sets_the_papers_speed_limits() -> None:
    env = _make(config="paper")
    _, info = env.reset(seed=0)
    assert info["robot"]["max_linear_speed_mps"] == 0.15
    assert info["robot"]["max_angular_speed_radps"] == 2.0


def test_configs_dir_paper_yaml_matches_preset() -> None:
    from pathlib import Path

    from semexplore_gym.envs.env_config import load_env_config

    path = Path(__file__).resolve().parents[2] / "configs" / "paper.yaml"
    assert load_env_config(str(path)) == load_env_config("paper")


def test_procedural_world_without_seed_changes_each_reset_with_fixed_shape() -> None:
    env = _make(world="maze:size_m=6").unwrapped
    env.reset(seed=1)
    seg1, shape1 = env.world.segments_m.copy(), env.map_geometry.shape
    env.reset(seed=2)
    assert env.map_geometry.shape == shape1
    assert not (
        seg1.shape == env.world.segments_m.shape and np.allclose(seg1, env.world.segments_m)
    )
    env.reset(seed=1)
    assert np.array_equal(seg1, env.world.segments_m)


@pytest.mark.parametrize("action", [[math.nan, 0.0], [0.0, math.inf], [1.0], [[1.0, 0.0, 0.0]]])
def test_bad_actions_raise_naming_the_value(action) -> None:
    env = _make()
    env.reset(seed=0)
    with pytest.raises(ValueError, match="action"):
        env.step(np.array(action, dtype=np.float32) if not isinstance(action[0], list) else action)


def test_unknown_world_name() -> None:
    with pytest.raises(ValueError, match="no_such_world"):
        _make(world="no_such_world")


def test_unknown_config_key_names_the_dotted_path() -> None:
    with pytest.raises(ConfigError, match="lidar.n_beamz"):
        _make(config={"lidar": {"n_beamz": 10}})


def test_bad_config_value_names_the_field() -> None:
    with pytest.raises(ConfigError, match="n_beams"):
        _make(config={"lidar": {"n_beams": 0}})


def test_start_pose_inside_a_wall_is_rejected() -> None:
    env = _make().unwrapped
    x0, y0, x1, y1 = env.world.segments_m[0]
    with pytest.raises(ValueError, match="start"):
        env.reset(seed=0, options={"start_pose": (float(x0 + x1) / 2, float(y0 + y1) / 2, 0.0)})


def test_malformed_yaml_and_missing_image_give_clear_errors(tmp_path) -> None:
    bad = tmp_path / "bad.yaml"
    bad.write_text("image: [unclosed\n")
    with pytest.raises(ValueError, match="bad.yaml"):
        _make(world=str(bad))
    missing = tmp_path / "m.yaml"
    missing.write_text(
        "image: nothere.pgm\nresolution: 0.05\norigin: [0, 0, 0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n"
    )
    with pytest.raises(FileNotFoundError, match="nothere.pgm"):
        _make(world=str(missing))
