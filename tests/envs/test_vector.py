"""``FastSyncVectorEnv`` returns exactly what gymnasium's ``SyncVectorEnv`` returns."""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.vector import AutoresetMode, SyncVectorEnv

import semexplore_gym  # noqa: F401
from semexplore_gym.envs.vector import FastSyncVectorEnv


def _same(a: Any, b: Any) -> bool:
    if isinstance(a, dict):
        return isinstance(b, dict) and a.keys() == b.keys() and all(_same(a[k], b[k]) for k in a)
    if isinstance(a, tuple | list):
        return type(a) is type(b) and len(a) == len(b) and all(map(_same, a, b))
    if isinstance(a, np.ndarray):
        if not (isinstance(b, np.ndarray) and a.dtype == b.dtype and a.shape == b.shape):
            return False
        if a.dtype == object:
            return all(_same(x, y) for x, y in zip(a, b, strict=True))
        return bool(np.array_equal(a, b))
    return bool(a == b)


def _fn(**kw: Any):
    # A 4 s episode, so the 30 steps below cross autoresets.
    cfg = {"episode": {"max_time_s": 4.0}}
    return lambda: gym.make("SemanticExplore-v0", world="maze1", config=cfg, **kw)


@pytest.mark.parametrize(
    ("mode", "copy", "kw"),
    [
        (AutoresetMode.NEXT_STEP, True, {}),
        (AutoresetMode.NEXT_STEP, False, {"static_info": "reset"}),
        (AutoresetMode.SAME_STEP, True, {"map_observation": "window", "map_window_cells": 32}),
        (AutoresetMode.DISABLED, False, {}),
    ],
)
def test_fast_sync_vector_env_matches_sync_vector_env(mode, copy, kw) -> None:
    fast = FastSyncVectorEnv([_fn(**kw)] * 3, copy=copy, autoreset_mode=mode)
    ref = SyncVectorEnv([_fn(**kw)] * 3, copy=copy, autoreset_mode=mode)
    rng = np.random.default_rng(3)
    try:
        assert _same(fast.reset(seed=5), ref.reset(seed=5))
        kept = []
        n_done = 0
        for _ in range(30):
            a = rng.uniform(-1, 1, size=(3, 2)).astype(np.float32)
            got, want = fast.step(a), ref.step(a)
            assert len(got) == 5 and all(_same(g, w) for g, w in zip(got, want, strict=True))
            kept.append(got[0])
            done = got[2] | got[3]
            n_done += int(done.sum())
            if mode == AutoresetMode.DISABLED and done.any():
                fast.reset(options={"reset_mask": done})
                ref.reset(options={"reset_mask": done})
        assert n_done >= 3  # the episodes ended and restarted along the way
        if copy:  # each step's batch is its own copy
            assert not np.array_equal(kept[0]["scan"], kept[-1]["scan"])
    finally:
        fast.close()
        ref.close()


def test_fast_sync_vector_env_rejects_wrong_action_count() -> None:
    fast = FastSyncVectorEnv([_fn()] * 2)
    try:
        fast.reset(seed=0)
        with pytest.raises(ValueError):
            fast.step(np.zeros((3, 2), np.float32))
    finally:
        fast.close()
