"""Gymnasium's env checker passes out of the box with the [dev] extra, "human" rendering included
(SB3's checker: ``test_semantic_explore.py``)."""

from __future__ import annotations

import os
import warnings

import gymnasium as gym
import pytest
from gymnasium.utils.env_checker import check_env

import semexplore_gym  # noqa: F401  (registers the env)


@pytest.fixture
def headless(monkeypatch):
    # pygame draws "human" frames into a dummy video driver: no screen on CI.
    monkeypatch.setenv("SDL_VIDEODRIVER", "dummy")
    monkeypatch.setenv("SDL_AUDIODRIVER", "dummy")
    os.environ.setdefault("PYGAME_HIDE_SUPPORT_PROMPT", "1")


@pytest.mark.parametrize("render_mode", [None, "rgb_array", "human"])
def test_gymnasium_check_env(render_mode, headless) -> None:
    env = gym.make("SemanticExplore-v0", world="maze1", render_mode=render_mode)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error", category=UserWarning)
            check_env(env.unwrapped, skip_render_check=False)
    finally:
        env.close()
