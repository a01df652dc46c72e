"""The speed options of ``SemanticExplore-v0`` (issue #17), all off by default:

``map_observation="window"`` (a window of the map around the robot), ``map_observation="shared"``
(a read-only live view of the env's map) and ``static_info="reset"`` (static ``info``
entries only at reset). They change only how observations and ``info`` are handed out: the same
seeds and actions give the same maps, scans, poses and rewards as the default env.
"""

from __future__ import annotations

import warnings

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import semexplore_gym  # noqa: F401
from semexplore_gym.core.grid import UNKNOWN
from semexplore_gym.wrappers import FixedSizeMap

STATIC = ("map_geometry", "robot", "lidar", "dt_s")


def _actions(n: int) -> np.ndarray:
    return np.random.default_rng(5).uniform(-1, 1, size=(n, 2)).astype(np.float32)


def test_reset_info_option_gives_the_default_trajectory_and_dynamic_info() -> None:
    ref = gym.make("SemanticExplore-v0", world="maze1")
    fast = gym.make("SemanticExplore-v0", world="maze1", static_info="reset")
    o_ref, i_ref = ref.reset(seed=4)
    o_fast, i_fast = fast.reset(seed=4)
    assert i_fast == i_ref  # reset info keeps the static entries
    assert np.array_equal(o_fast["map"], o_ref["map"])
    for a in _actions(200):
        o_ref, r_ref, term_ref, trunc_ref, i_ref = ref.step(a)
        o_fast, r_fast, term_fast, trunc_fast, i_fast = fast.step(a)
        for k in ("map", "pose", "scan"):
            assert np.array_equal(o_fast[k], o_ref[k]), k
        assert (r_fast, term_fast, trunc_fast) == (r_ref, term_ref, trunc_ref)
        assert i_fast == {k: v for k, v in i_ref.items() if k not in STATIC}
    ref.close()
    fast.close()


def test_copy_stays_the_default_and_bad_options_fail() -> None:
    env = gym.make("SemanticExplore-v0", world="maze1")
    obs0, info0 = env.reset(seed=0)
    obs1, *_, info1 = env.step(np.zeros(2, np.float32))
    assert obs1["map"] is not obs0["map"] and obs1["map"].flags.writeable
    assert all(k in info1 for k in STATIC)
    env.close()
    with pytest.raises(ValueError, match="map_observation"):
        gym.make("SemanticExplore-v0", world="maze1", map_observation="view")
    with pytest.raises(ValueError, match="static_info"):
        gym.make("SemanticExplore-v0", world="maze1", static_info="never")
    for bad in (4, 5000, 16.0, True):
        with pytest.raises(ValueError, match="map_window_cells"):
            gym.make("SemanticExplore-v0", world="maze1", map_window_cells=bad)


@pytest.mark.parametrize(
    "kwargs",
    [
        {"map_observation": "window", "map_window_cells": 48},
        {"static_info": "reset"},
    ],
)
def test_gymnasium_check_env_passes_with_the_options(kwargs: dict) -> None:
    env = gym.make("SemanticExplore-v0", world="maze1", **kwargs)
    with warnings.catch_warnings():
        warnings.simplefilter("error", category=UserWarning)
        check_env(env.unwrapped)
    env.close()


def _window_matches(win: np.ndarray, offset: np.ndarray, full: np.ndarray) -> bool:
    r0, c0 = int(offset[0]), int(offset[1])
    s = win.shape[0]
    h, w = full.shape
    rows = slice(max(r0, 0), min(r0 + s, h))
    cols = slice(max(c0, 0), min(c0 + s, w))
    inside = np.zeros(win.shape, bool)
    inside[rows.start - r0 : rows.stop - r0, cols.start - c0 : cols.stop - c0] = True
    return bool(
        np.array_equal(win[inside], full[rows, cols].ravel()) and np.all(win[~inside] == UNKNOWN)
    )


def test_window_observation_is_the_part_of_the_full_map_around_the_robot() -> None:
    full = gym.make("SemanticExplore-v0", world="maze1")
    win = gym.make(
        "SemanticExplore-v0", world="maze1", map_observation="window", map_window_cells=100
    )
    ref = FixedSizeMap(gym.make("SemanticExplore-v0", world="maze1"), map_size=100, anchor="robot")
    space = win.observation_space
    assert space["map"].shape == (100, 100) and space["map_offset_cells"].dtype == np.int32
    o_full, _ = full.reset(seed=2)
    o_win, _ = win.reset(seed=2)
    o_ref, _ = ref.reset(seed=2)
    g = full.unwrapped.map_geometry
    offsets = set()
    for a in [np.zeros(2, np.float32), *_actions(150)]:
        if a.any():
            o_full, r_full, *_ = full.step(a)
            o_win, r_win, *_ = win.step(a)
            o_ref, *_, i_ref = ref.step(a)
            assert r_win == r_full
        assert space.contains(o_win) and o_win["map"].shape == (100, 100)
        assert np.array_equal(o_win["pose"], o_full["pose"])
        assert np.array_equal(o_win["scan"], o_full["scan"])
        assert _window_matches(o_win["map"], o_win["map_offset_cells"], o_full["map"])
        row, col = (int(v[()]) for v in g.world_to_grid(o_win["pose"][0], o_win["pose"][1]))
        assert tuple(o_win["map_offset_cells"]) == (row - 50, col - 50)
        assert np.array_equal(o_win["map"], o_ref["map"][0])
        offsets.add(tuple(o_win["map_offset_cells"]))
    assert len(offsets) > 1  # the window follows the robot
    # Near the border the window is padded with UNKNOWN (maze1's map is 164 cells wide).
    assert any(min(o) < 0 for o in offsets) or any(max(o) + 100 > 164 for o in offsets)
    for e in (full, win, ref):
        e.close()


def test_window_option_in_a_vector_env() -> None:
    fn = lambda: gym.make(  # noqa: E731
        "SemanticExplore-v0", world="maze1", map_observation="window", map_window_cells=64
    )
    venv = gym.vector.SyncVectorEnv([fn] * 3)
    try:
        obs, _ = venv.reset(seed=0)
        assert obs["map"].shape == (3, 64, 64) and obs["map_offset_cells"].shape == (3, 2)
        for a in _actions(30).reshape(10, 3, 2)[:, :, :]:
            obs, *_ = venv.step(a)
        for i, env in enumerate(venv.envs):
            assert _window_matches(
                obs["map"][i], obs["map_offset_cells"][i], env.unwrapped.grid.encoded
            )
    finally:
        venv.close()


@pytest.mark.parametrize("copy", [True, False])
def test_vector_envs_over_reset_info_batch_the_same_data(copy: bool) -> None:
    def fn(**kw):
        return lambda: gym.make("SemanticExplore-v0", world="maze1", **kw)

    ref_v = gym.vector.SyncVectorEnv([fn()] * 2)
    fast_v = gym.vector.SyncVectorEnv([fn(static_info="reset")] * 2, copy=copy)
    try:
        ref_v.reset(seed=1)
        _, vinfo0 = fast_v.reset(seed=1)
        assert vinfo0["lidar"].shape == (2,)  # reset info: static entries present
        for a in _actions(40).reshape(20, 2, 2):
            o_ref, r_ref, _, _, i_ref = ref_v.step(a)
            o_fast, r_fast, _, _, i_fast = fast_v.step(a)
            assert np.array_equal(o_fast["map"], o_ref["map"]) and o_fast["map"].shape[0] == 2
            assert np.array_equal(o_fast["scan"], o_ref["scan"])
            assert np.array_equal(r_fast, r_ref)
            assert np.array_equal(i_fast["coverage"], i_ref["coverage"])
            assert "lidar" not in i_fast and "map_geometry" not in i_fast
    finally:
        ref_v.close()
        fast_v.close()


def test_shared_map_is_a_read_only_live_view_of_the_default_map() -> None:
    ref = gym.make("SemanticExplore-v0", world="maze1")
    shared = gym.make("SemanticExplore-v0", world="maze1", map_observation="shared")
    o_ref, _ = ref.reset(seed=2)
    o_sh, _ = shared.reset(seed=2)
    first = o_sh["map"]
    assert not first.flags.writeable and first.dtype == np.uint8
    with pytest.raises(ValueError, match="read-only"):
        first[0, 0] = 0
    assert shared.observation_space["map"].shape == first.shape
    for a in _actions(120):
        o_ref, r_ref, *_ = ref.step(a)
        o_sh, r_sh, *_ = shared.step(a)
        assert np.array_equal(o_sh["map"], o_ref["map"])
        assert np.array_equal(o_sh["scan"], o_ref["scan"]) and r_sh == r_ref
        assert np.array_equal(o_sh["pose"], o_ref["pose"])
    # Live: the reset observation's map is the current map, not the map at reset.
    assert np.shares_memory(first, o_sh["map"]) and np.array_equal(first, o_ref["map"])
    final = np.array(o_sh["map"])
    # A new episode maps into a new array: the last episode's view keeps its final map.
    o_new, _ = shared.reset(seed=3)
    assert not np.shares_memory(first, o_new["map"])
    assert np.array_equal(first, final)
    ref.close()
    shared.close()


def test_shared_map_option_is_named_in_the_error() -> None:
    with pytest.raises(ValueError, match="shared"):
        gym.make("SemanticExplore-v0", world="maze1", map_observation="live")


def test_the_options_object_and_the_keywords_are_one_setting() -> None:
    from semexplore_gym.envs.observation_options import ObservationOptions

    opts = ObservationOptions(map_observation="window", map_window_cells=40)
    a = gym.make("SemanticExplore-v0", world="maze1", observation_options=opts)
    b = gym.make("SemanticExplore-v0", world="maze1", map_observation="window", map_window_cells=40)
    assert a.unwrapped.observation_options == b.unwrapped.observation_options == opts
    oa, _ = a.reset(seed=2)
    ob, _ = b.reset(seed=2)
    assert oa["map"].shape == (40, 40)
    for k in oa:
        np.testing.assert_array_equal(oa[k], ob[k])
    # A keyword replaces the field of a given object.
    c = gym.make("SemanticExplore-v0", world="maze1", observation_options=opts, static_info="reset")
    assert c.unwrapped.observation_options.static_info == "reset"
    assert c.unwrapped.observation_options.map_window_cells == 40
    with pytest.raises(ValueError, match="map_observation must be one of"):
        ObservationOptions(map_observation="full")
    with pytest.raises(TypeError):
        gym.make("SemanticExplore-v0", world="maze1", map_obs="copy")


def test_a_misspelled_keyword_names_itself_and_the_envs_keywords() -> None:
    with pytest.raises(TypeError) as info:
        gym.make("SemanticExplore-v0", wrold="maze1")
    message = str(info.value)
    assert "unexpected keyword argument 'wrold' (did you mean 'world'?)" in message
    assert "ObservationOptions" not in message and "__init__" not in message
    keywords = "world, config, overrides, render_mode, observation_options, privileged"
    assert keywords in message and "map_observation, static_info, map_window_cells" in message
