"""``FastSyncVectorEnv`` returns exactly what gymnasium's ``SyncVectorEnv`` returns."""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.vector import AutoresetMode, SyncVectorEnv

import semexplore_gym  # noqa: F401
from semexplore_gym.envs.semantic_explore import SemanticExploreEnv
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
        (AutoresetMode.NEXT_STEP, True, {"static_info": "reset", "map_observation": "shared"}),
        (AutoresetMode.SAME_STEP, True, {"map_observation": "window", "map_window_cells": 32}),
        (AutoresetMode.SAME_STEP, False, {}),
        (AutoresetMode.DISABLED, False, {}),
        (AutoresetMode.DISABLED, True, {"static_info": "reset"}),
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
        # Whole-map observations under gym.make's wrappers are stepped directly (the general
        # path only when an env resets, or for same-step autoresets and windows).
        direct = mode != AutoresetMode.SAME_STEP and kw.get("map_observation") != "window"
        assert (fast._direct is not None) == direct
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


def test_direct_steps_fall_back_to_the_general_merge_for_unusual_info_values(monkeypatch) -> None:
    # A number of an unusual type (here an int coverage) takes gymnasium's own merge rules.
    fast = FastSyncVectorEnv([_fn()] * 2)
    ref = SyncVectorEnv([_fn()] * 2)
    real = SemanticExploreEnv.info_numbers

    def int_coverage(self):
        return (int(self.sim_time_s * 10), *real(self)[1:])

    monkeypatch.setattr(SemanticExploreEnv, "info_numbers", int_coverage)
    rng = np.random.default_rng(0)
    try:
        assert _same(fast.reset(seed=1), ref.reset(seed=1))
        for _ in range(6):
            a = rng.uniform(-1, 1, size=(2, 2)).astype(np.float32)
            got, want = fast.step(a), ref.step(a)
            assert all(_same(g, w) for g, w in zip(got, want, strict=True))
            assert got[4]["coverage"].dtype == np.int64
        assert fast._direct is not None
    finally:
        fast.close()
        ref.close()


def test_other_wrappers_keep_the_general_path() -> None:
    def fn():
        return gym.wrappers.RecordEpisodeStatistics(gym.make("SemanticExplore-v0", world="maze1"))

    fast = FastSyncVectorEnv([fn] * 2)
    try:
        fast.reset(seed=0)
        for _ in range(3):
            fast.step(np.zeros((2, 2), np.float32))
        assert fast._direct is None and not fast._direct_candidates
    finally:
        fast.close()


def _step_both(fast, ref, rng, n_steps: int, *, reset_done: bool = False) -> tuple[int, int]:
    """Step both vector envs with the same random actions and compare every result; with
    ``reset_done``, reset the envs that ended (partial resets). Returns (episodes ended,
    partial resets)."""
    n_done = partial = 0
    for _ in range(n_steps):
        a = rng.uniform(-1, 1, size=(fast.num_envs, 2)).astype(np.float32)
        got, want = fast.step(a), ref.step(a)
        assert all(_same(g, w) for g, w in zip(got, want, strict=True))
        done = got[2] | got[3]
        n_done += int(done.sum())
        if reset_done and done.any():
            partial += int(not done.all())
            options = {"reset_mask": done}
            assert _same(fast.reset(options=dict(options)), ref.reset(options=dict(options)))
    return n_done, partial


@pytest.mark.parametrize("copy", [True, False])
def test_partial_resets_after_direct_steps_batch_the_current_observations(copy) -> None:
    # Episodes of different lengths end at different steps; a partial reset batches the other
    # envs' latest observations, which direct steps wrote only into the batch.
    def fn(max_time_s: float):
        cfg = {"episode": {"max_time_s": max_time_s}}
        return lambda: gym.make("SemanticExplore-v0", world="maze1", config=cfg)

    fns = [fn(2.0), fn(3.0), fn(5.0)]
    for mode in (AutoresetMode.NEXT_STEP, AutoresetMode.DISABLED):
        fast = FastSyncVectorEnv(fns, copy=copy, autoreset_mode=mode)
        ref = SyncVectorEnv(fns, copy=copy, autoreset_mode=mode)
        try:
            assert _same(fast.reset(seed=2), ref.reset(seed=2))
            disabled = mode == AutoresetMode.DISABLED
            _, partial = _step_both(fast, ref, np.random.default_rng(1), 40, reset_done=disabled)
            assert fast._direct is not None
            assert not disabled or partial >= 2
        finally:
            fast.close()
            ref.close()


def test_direct_steps_match_over_worlds_drawn_at_every_reset() -> None:
    # An unseeded procedural spelling draws a new world at each reset (new map, same shape).
    def fn():
        cfg = {"episode": {"max_time_s": 3.0}}
        return gym.make("SemanticExplore-v0", world="cave:size_m=5", config=cfg)

    fast, ref = FastSyncVectorEnv([fn] * 3), SyncVectorEnv([fn] * 3)
    try:
        assert _same(fast.reset(seed=9), ref.reset(seed=9))
        n_done, _ = _step_both(fast, ref, np.random.default_rng(2), 40)
        assert n_done >= 6 and fast._direct is not None
    finally:
        fast.close()
        ref.close()


@pytest.mark.parametrize("copy", [True, False])
def test_direct_steps_keep_each_env_map_in_its_batch_row(copy) -> None:
    # The envs' grids keep their cells in the batch rows, so no map is copied per step;
    # copy=True still hands out frozen copies, copy=False a read-only batch.
    fast = FastSyncVectorEnv([_fn(static_info="reset")] * 2, copy=copy)
    ref = SyncVectorEnv([_fn(static_info="reset")] * 2, copy=copy)
    rng = np.random.default_rng(4)
    try:
        first, _ = fast.reset(seed=1)
        ref.reset(seed=1)
        if not copy:  # no writable handle to the batch, even before the first step
            with pytest.raises(ValueError, match="read-only"):
                first["map"][0, 0, 0] = 0
        kept_fast, kept_ref = [], []
        for _ in range(12):
            a = rng.uniform(0, 1, size=(2, 2)).astype(np.float32)
            got, want = fast.step(a)[0], ref.step(a)[0]
            kept_fast.append(got["map"])
            kept_ref.append(want["map"].copy())
        assert fast._direct is not None
        grids = [env.unwrapped.grid for env in fast.envs]
        batch_maps = fast._observations["map"]
        for i, grid in enumerate(grids):
            assert np.shares_memory(grid.encoded, batch_maps[i])
            np.testing.assert_array_equal(got["map"][i], grid.encoded)
        if copy:  # every step's copy is frozen at that step's maps
            assert all(_same(f, r) for f, r in zip(kept_fast, kept_ref, strict=True))
            assert not np.array_equal(kept_fast[0], kept_fast[-1])
        else:
            with pytest.raises(ValueError, match="read-only"):
                got["map"][0, 0, 0] = 0
            obs, _ = fast.reset(seed=2)
            with pytest.raises(ValueError, match="read-only"):
                obs["map"][1] = 0
    finally:
        fast.close()
        ref.close()


def _fixed_size(env: gym.Env) -> gym.Env:
    from semexplore_gym.wrappers import FixedSizeMap

    return FixedSizeMap(env, map_size=96)


def test_make_vec_without_wrappers_keeps_the_batched_entry_point() -> None:
    venv = gym.make_vec("SemanticExplore-v0", num_envs=2, world="maze:seed=3,size_m=4")
    try:
        assert type(venv) is FastSyncVectorEnv
    finally:
        venv.close()


@pytest.mark.parametrize("mode", ["sync", "async", "make_vector_env"])
def test_wrapped_envs_batch_in_every_mode_with_the_same_results(mode) -> None:
    """``wrappers=`` in gymnasium's sync and async modes and in ``make_vector_env`` (the
    project's batching) give the same wrapped batches as a loop over wrapped envs."""
    from semexplore_gym.envs.vector import make_vector_env

    world = "maze:seed=3,size_m=4"
    if mode == "make_vector_env":
        venv = make_vector_env(2, wrappers=[_fixed_size], world=world)
        assert isinstance(venv, FastSyncVectorEnv)
    else:
        venv = gym.make_vec(
            "SemanticExplore-v0",
            num_envs=2,
            vectorization_mode=mode,
            wrappers=[_fixed_size],
            world=world,
        )
    singles = [_fixed_size(gym.make("SemanticExplore-v0", world=world)) for _ in range(2)]
    try:
        obs, _ = venv.reset(seed=[3, 4])
        expected = [e.reset(seed=s)[0] for e, s in zip(singles, (3, 4), strict=True)]
        assert obs["map"].shape == (2, 1, 96, 96)
        actions = np.tile(np.array([[0.6, 0.3]], dtype=np.float32), (2, 1))
        for _ in range(5):
            obs, *_ = venv.step(actions)
            expected = [e.step(a)[0] for e, a in zip(singles, actions, strict=True)]
        for key in obs:
            assert np.array_equal(obs[key], np.stack([o[key] for o in expected])), key
    finally:
        venv.close()
        for e in singles:
            e.close()
