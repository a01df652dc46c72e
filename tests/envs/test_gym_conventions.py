"""Gymnasium conventions a user expects: ``gym.make_vec`` gives the fast vector env, RecordVideo
works with the ``render`` extra, rendering is quiet on a headless machine, and bad values are
one clear error."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.vector import SyncVectorEnv

import semexplore_gym  # noqa: F401  (registers the env)
from semexplore_gym.envs.vector import FastSyncVectorEnv

REPO = Path(__file__).resolve().parents[2]


def test_make_vec_gives_the_fast_vector_env_by_default() -> None:
    venv = gym.make_vec("SemanticExplore-v0", num_envs=3, static_info="reset")
    try:
        assert isinstance(venv, FastSyncVectorEnv) and venv.num_envs == 3
        obs, _ = venv.reset(seed=0)
        assert obs["map"].shape[0] == obs["scan"].shape[0] == 3
        obs, reward, terminated, truncated, info = venv.step(np.zeros((3, 2), np.float32))
        assert reward.shape == (3,) and "coverage" in info
        assert all(e.unwrapped.static_info == "reset" for e in venv.envs)  # kwargs reach the env
        assert venv.spec is not None and venv.spec.id == "SemanticExplore-v0"
    finally:
        venv.close()
    sync = gym.make_vec("SemanticExplore-v0", num_envs=2, vectorization_mode="sync")
    try:
        assert type(sync) is SyncVectorEnv
    finally:
        sync.close()


def test_make_vec_takes_one_world_per_env() -> None:
    venv = gym.make_vec("SemanticExplore-v0", num_envs=3, world=["maze1", "maze2"], copy=False)
    try:
        assert [e.unwrapped.world.name for e in venv.envs] == ["maze1", "maze2", "maze1"]
        assert venv.copy is False
    finally:
        venv.close()
    with pytest.raises(ValueError, match="num_envs"):
        gym.make_vec("SemanticExplore-v0", num_envs=0)


def test_record_video_writes_a_video(tmp_path: Path) -> None:
    pytest.importorskip("moviepy")
    from gymnasium.wrappers import RecordVideo

    env = gym.make("SemanticExplore-v0", world="maze:seed=0,size_m=3", render_mode="rgb_array")
    env = RecordVideo(env, str(tmp_path), episode_trigger=lambda _: True, disable_logger=True)
    env.reset(seed=0)
    for _ in range(3):
        env.step(np.array([1.0, 0.0], np.float32))
    env.close()
    videos = list(tmp_path.glob("*.mp4"))
    assert videos and videos[0].stat().st_size > 1000


def test_check_env_and_rendering_are_quiet_on_a_headless_machine() -> None:
    """No ALSA (audio) or XDG (display) errors: pygame opens only its display, and without
    X11/Wayland SDL's dummy driver."""
    pytest.importorskip("pygame")
    code = (
        "import gymnasium as gym, semexplore_gym\n"
        "from gymnasium.utils.env_checker import check_env\n"
        "check_env(gym.make('SemanticExplore-v0', world='maze:seed=0,size_m=3').unwrapped)\n"
        "env = gym.make('SemanticExplore-v0', world='maze:seed=0,size_m=3', render_mode='rgb_array')\n"
        "env.reset(seed=0); assert env.render().ndim == 3; env.close()\n"
        "env = gym.make('SemanticExplore-v0', world='maze:seed=0,size_m=3', render_mode='human')\n"
        "env.reset(seed=0); env.step(env.action_space.sample()); env.close()\n"
        "print('ok')\n"
    )
    env = {
        k: v
        for k, v in os.environ.items()
        if k not in ("DISPLAY", "WAYLAND_DISPLAY", "SDL_VIDEODRIVER", "SDL_AUDIODRIVER")
    }
    env["PYTHONPATH"] = str(REPO)
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=300
    )
    assert out.returncode == 0, out.stderr[-2000:]
    assert out.stdout.strip().endswith("ok")
    assert out.stderr.strip() == "", out.stderr[-2000:]


def test_an_absurd_lidar_range_is_one_clear_error() -> None:
    with pytest.raises(ValueError, match=r"lidar\.max_range_m must be at most 1000 m, got 1e\+300"):
        gym.make("SemanticExplore-v0", world="maze1", overrides=["lidar.max_range_m=1e300"])


@pytest.mark.parametrize("digits", [400, 5000], ids=["1e400", "-1e5000"])
def test_an_action_holding_a_huge_int_is_one_clear_error(digits: int) -> None:
    value = 10**digits if digits < 1000 else -(10**digits)  # past float64, and past str()
    env = gym.make("SemanticExplore-v0", world="maze:seed=0,size_m=3")
    try:
        env.reset(seed=0)
        with pytest.raises(ValueError, match=r"action must be 2 numbers \[v, omega\]"):
            env.step([value, 0])
    finally:
        env.close()
