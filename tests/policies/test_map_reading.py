"""The expert's map reading: ``semantic-v4`` reads a SLAM map's wall slivers as wall, and the
perfect map as observed (so it is ``semantic-v3`` there); the experts driven by an outside
choice read every map as observed."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest
from semexplore_gym.policies.expert.map_reading import SLAM_INFO_MARK, MapReader, WallSliverFill
from semexplore_gym.policies.expert.recipes import OUTSIDE_CHOICE, SEMANTIC_V3, SEMANTIC_V4
from semexplore_gym.policies.registry import make_policy

import semexplore_gym  # noqa: F401  (registers the env ids)
from semexplore_gym.core.frontiers.wall_slivers import fill_wall_slivers
from semexplore_gym.core.grid import FREE, OCCUPIED, UNKNOWN


def _walled_room() -> np.ndarray:
    """A room whose left wall shows its inside (two faces, UNKNOWN between): a sliver."""
    g = np.full((30, 30), FREE, dtype=np.uint8)
    g[:, 0] = g[:, 2] = OCCUPIED
    g[:, 1] = UNKNOWN
    return g


def test_the_part_says_where_it_applies() -> None:
    assert WallSliverFill().applies({SLAM_INFO_MARK: (0.0, 0.0, 0.0)})
    assert not WallSliverFill().applies({"robot": {}})
    assert WallSliverFill().applies({"robot": {}}, "all")
    with pytest.raises(ValueError, match="sliver_maps must be one of.*'sometimes'"):
        WallSliverFill().applies({}, "sometimes")
    with pytest.raises(ValueError, match="semantic.*sliver_maps.*'sometimes'"):
        make_policy("semantic[sliver_maps=sometimes]")


def test_only_semantic_v4_reads_slivers() -> None:
    assert SEMANTIC_V4.map_reading == WallSliverFill()
    assert SEMANTIC_V3.map_reading is None and OUTSIDE_CHOICE.map_reading is None
    variant = SEMANTIC_V3.with_map_reading(WallSliverFill(), name="mine")
    assert variant.name == "mine" and variant.plan_sources == SEMANTIC_V3.plan_sources


def test_the_reader_fills_again_only_when_the_map_changed_even_in_place() -> None:
    grid = _walled_room()
    reader = MapReader(0.25, 0.05)
    first = reader(grid)
    assert (first[:, 1] == OCCUPIED).all() and (grid[:, 1] == UNKNOWN).all()
    assert reader(grid) is first  # unchanged: the same reading, nothing computed
    grid[10:20, 2] = FREE  # the env updates its shared map in place: a gap in the face
    assert np.array_equal(reader(grid), fill_wall_slivers(grid.copy(), 0.25, 0.05))


def test_reading_only_the_changes_reads_what_reading_it_all_does() -> None:
    rng = np.random.default_rng(2)
    values = np.array([OCCUPIED, UNKNOWN, FREE], dtype=np.uint8)
    for _ in range(20):
        grid = rng.choice(values, size=(80, 90), p=[0.2, 0.5, 0.3])
        reader = MapReader(0.25, 0.05)
        for _ in range(12):
            if rng.random() < 0.15:  # a change all over (a loop closure re-renders the map)
                grid = rng.choice(values, size=(80, 90), p=[0.2, 0.5, 0.3])
            else:  # a keyframe: a few cells change
                r, c = int(rng.integers(0, 76)), int(rng.integers(0, 86))
                grid[r : r + int(rng.integers(1, 6)), c : c + int(rng.integers(1, 6))] = rng.choice(
                    values
                )
            assert np.array_equal(reader(grid), fill_wall_slivers(grid.copy(), 0.25, 0.05))


@pytest.mark.parametrize(("config", "spec", "fills"), [
    ("slam", "semantic", True),
    ("slam", "semantic-v4[sliver_max_width_m=0.3]", True),
    ("slam", "semantic-v3", False),
    ("slam", "frontier-student", False),
    ("default", "semantic", False),
    ("default", "semantic[sliver_maps=all]", True),
    ("default", "semantic-v3[sliver_maps=all]", False),
])
def test_the_expert_reads_what_its_recipe_and_the_map_say(
    config: str, spec: str, fills: bool
) -> None:
    if config == "slam":
        pytest.importorskip("gtsam")
    env = gym.make("SemanticExplore-v0", world="maze1", config=config)
    obs, info = env.reset(seed=0)
    policy = make_policy(spec)
    policy.reset(obs, info, seed=0)
    grid = obs["map"].copy()
    grid[:, 0] = OCCUPIED  # a sliver along a wall, whatever the first scan mapped
    grid[:, 1] = UNKNOWN
    grid[:, 2] = OCCUPIED
    seen = policy.read_map({**obs, "map": grid})
    if fills:
        width = policy.params.sliver_max_width_m
        assert np.array_equal(seen, fill_wall_slivers(grid, width, policy.geometry.resolution_m))
        assert (seen[10:-10, 1] == OCCUPIED).all()  # (its ends meet the unknown beyond the map)
    else:
        assert seen is grid
    env.close()


@pytest.mark.slow
def test_on_a_slam_map_v4_is_its_own_mission_and_still_finishes() -> None:
    """A 10 m office with SLAM: the two versions part ways (the reading changes what the expert
    sees), and v4 maps the floor and stops by itself, without a collision."""
    pytest.importorskip("gtsam")
    from semexplore_gym.evaluation.rollout import run_mission

    results = {}
    for spec in ("semantic-v3", "semantic-v4"):
        env = gym.make("SemanticExplore-v0", world="office:seed=3,size_m=10", config="slam")
        results[spec] = run_mission(env, make_policy(spec), seed=0, max_time_s=600)
        env.close()
    v3, v4 = results["semantic-v3"], results["semantic-v4"]
    assert (v4.t99_s, v4.mission_time_s) != (v3.t99_s, v3.mission_time_s)
    assert v4.self_stopped and v4.coverage >= 0.99 and v4.collisions == 0
