"""Value-noise caves (``noisecave:``): determinism, one enclosed piece, openness, narrow passages."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import ndimage

from semexplore_gym.core.grid import GridGeometry
from semexplore_gym.core.worlds.noise_cave import (
    NoiseCaveParams,
    bilinear_weights,
    carve_noise_cave,
)
from semexplore_gym.core.worlds.procedural import list_world_names, world_family_parameters
from semexplore_gym.core.worlds.raster import rasterize_free
from semexplore_gym.core.worlds.start import reachable_free_mask
from semexplore_gym.maps import make_world

FOUR = ndimage.generate_binary_structure(2, 1)
RADIUS_M = 0.105
ENV_CLEARANCE_M = RADIUS_M + 0.01  # the env's coverage clearance
PLANNER_CLEARANCE_M = RADIUS_M + 0.05  # the semantic expert's


def _n_components(mask: np.ndarray) -> int:
    return int(ndimage.label(mask, structure=FOUR)[1])


def _area_m2(mask: np.ndarray, resolution_m: float = 0.05) -> float:
    return float(mask.sum()) * resolution_m**2


def test_listed_with_defaults_and_spelled_back() -> None:
    assert "noisecave" in list_world_names()
    defaults = world_family_parameters("noisecave")
    assert defaults == {"seed": 0, "size_m": 12.0, "threshold": 0.44, "lattice_m": 0.6}
    world = make_world("noisecave:seed=4,size_m=8,threshold=0.4")
    assert world.metadata["family"] == "noisecave"
    assert world.metadata["spec"] == "noisecave:seed=4,size_m=8,threshold=0.4,lattice_m=0.6"
    assert make_world(world.metadata["spec"]).segments_m.tobytes() == world.segments_m.tobytes()


def test_same_seed_same_cave_other_seed_other_cave() -> None:
    a, b = make_world("noisecave:seed=3,size_m=8"), make_world("noisecave:seed=3,size_m=8")
    assert np.array_equal(a.segments_m, b.segments_m) and a.start_pose == b.start_pose
    assert np.array_equal(a.free_mask, b.free_mask)
    c = make_world("noisecave:seed=4,size_m=8")
    assert a.free_mask.shape != c.free_mask.shape or not np.array_equal(a.free_mask, c.free_mask)
    # The box does not depend on the seed (an env redraws unseeded worlds on one map grid).
    assert {make_world(f"noisecave:seed={s},size_m=8").bounds_m for s in range(3)} == {
        (0.0, 0.0, 8.0, 8.0)
    }


def test_bilinear_weights_interpolate() -> None:
    w = bilinear_weights(16, 0.05, 0.4)
    assert w.shape == (16, 3) and np.allclose(w.sum(axis=1), 1.0)
    assert (np.count_nonzero(w, axis=1) <= 2).all()
    # A linear ramp on the lattice comes back as the same ramp at the cell centres.
    lattice = np.arange(3) * 0.4
    assert np.allclose(w @ lattice, (np.arange(16) + 0.5) * 0.05)


@pytest.mark.parametrize(
    ("size_m", "threshold", "seed"),
    [(6, 0.40, 1), (6, 0.48, 2), (10, 0.44, 3), (16, 0.46, 4), (30, 0.44, 5), (8, 0.52, 6)],
)
def test_free_space_is_one_enclosed_four_connected_piece(
    size_m: float, threshold: float, seed: int
) -> None:
    params = NoiseCaveParams(seed=seed, size_m=size_m, threshold=threshold)
    free = carve_noise_cave(params, np.random.default_rng(seed))
    assert free.shape == (round(size_m / 0.05),) * 2
    assert not (free[0].any() or free[-1].any() or free[:, 0].any() or free[:, -1].any())
    assert _n_components(free) == 1

    world = make_world(f"noisecave:seed={seed},size_m={size_m},threshold={threshold}")
    assert world.free_space_source == "raster" and _n_components(world.free_mask) == 1
    # On a grid with a margin round the box (as the env's map), the walls hold it in.
    geometry = GridGeometry.covering(*world.bounds_m, resolution_m=0.05, margin_m=0.3)
    on_map = rasterize_free(world, geometry)
    assert _n_components(on_map) == 1
    assert _area_m2(on_map) == pytest.approx(_area_m2(world.free_mask))
    rim = np.ones(on_map.shape, dtype=bool)
    rim[6:-6, 6:-6] = False  # the 0.3 m margin
    assert not (on_map & rim).any()
    # The world's start pose has room for the robot and reaches a good part of the cave.
    reach = reachable_free_mask(
        world, geometry, world.start_pose[:2], RADIUS_M, ENV_CLEARANCE_M, free_mask=on_map
    )
    assert _area_m2(reach) > 0.1 * _area_m2(on_map)


def test_a_lower_threshold_opens_the_cave() -> None:
    free_m2, reach_m2 = {}, {}
    for threshold in (0.40, 0.44, 0.48):
        worlds = [
            make_world(f"noisecave:seed={s},size_m=10,threshold={threshold}") for s in range(6)
        ]
        free_m2[threshold] = np.mean([_area_m2(w.free_mask) for w in worlds])
        reach_m2[threshold] = np.mean(
            [
                _area_m2(
                    reachable_free_mask(
                        w, w.free_geometry, w.start_pose[:2], RADIUS_M, ENV_CLEARANCE_M
                    )
                )
                for w in worlds
            ]
        )
    assert free_m2[0.40] > free_m2[0.44] > free_m2[0.48]
    assert reach_m2[0.40] > reach_m2[0.44] > reach_m2[0.48]
    # Same seed, same noise: the free cells at a higher threshold are free at a lower one.
    p = NoiseCaveParams(seed=2, size_m=10, threshold=0.48)
    high = carve_noise_cave(p, np.random.default_rng(2))
    low = carve_noise_cave(
        NoiseCaveParams(seed=2, size_m=10, threshold=0.40), np.random.default_rng(2)
    )
    assert not (high & ~low).any()


def test_passages_range_from_wide_down_to_the_robots_width() -> None:
    """Chambers wider than a metre, and chambers the env counts as reachable (gaps of 0.23 m
    and wider) behind passages narrower than the expert's planning clearance (0.31 m)."""
    behind_narrow = 0
    for seed in range(8):
        world = make_world(f"noisecave:seed={seed},size_m=10")
        free = world.free_mask
        widest_m = (float(ndimage.distance_transform_edt(free).max()) - 0.5) * 0.05
        assert widest_m > 0.6
        start = world.start_pose[:2]
        env_reach = reachable_free_mask(
            world, world.free_geometry, start, RADIUS_M, ENV_CLEARANCE_M, free_mask=free
        )
        planner_reach = reachable_free_mask(
            world, world.free_geometry, start, RADIUS_M, PLANNER_CLEARANCE_M, free_mask=free
        )
        labels, n = ndimage.label(env_reach & ~planner_reach, structure=FOUR)
        if n and np.bincount(labels.ravel())[1:].max() * 0.05**2 >= 0.5:
            behind_narrow += 1
        # Free space narrower than the robot too (counted by no one).
        assert _area_m2(free & ~env_reach) > 1.0
    assert behind_narrow >= 4


@pytest.mark.parametrize(
    ("spec", "needle"),
    [
        ("noisecave:threshold=0.3", r"noisecave parameter threshold=0.3 is outside \[0.35, 0.55\]"),
        ("noisecave:threshold=0.9", r"threshold=0.9 is outside"),
        ("noisecave:threshold=high", r"threshold='high' must be a number"),
        ("noisecave:lattice_m=0.1", r"lattice_m=0.1 is outside \[0.3, 3.0\]"),
        ("noisecave:size_m=8,lattice_m=2.5", r"lattice_m=2.5 is outside \[0.3, 2.0\]"),
        ("noisecave:size_m=2", r"size_m=2.0 is outside \[4.0, 50.0\]"),
        ("noisecave:seed=-1", r"seed=-1 must be a non-negative integer"),
        ("noisecave:noise=3", r"unknown noisecave parameter 'noise'; valid parameters: seed, "),
    ],
)
def test_bad_parameters_give_one_clear_error(spec: str, needle: str) -> None:
    with pytest.raises(ValueError, match=needle) as exc:
        make_world(spec)
    assert "\n" not in str(exc.value)


def test_sizes_from_6_to_30_m_build() -> None:
    for size in (6, 30):
        world = make_world(f"noisecave:seed=11,size_m={size}")
        assert world.size_m == (float(size), float(size))
        assert 0.15 * size**2 < _area_m2(world.free_mask) < 0.8 * size**2


def test_an_env_redraws_an_unseeded_noise_cave_on_one_grid() -> None:
    import gymnasium as gym

    import semexplore_gym  # noqa: F401  (registers the env)

    env = gym.make("SemanticExplore-v0", world="noisecave:size_m=6")
    try:
        obs0, _ = env.reset(seed=1)
        walls0 = env.unwrapped.world.segments_m.copy()
        obs1, _ = env.reset(seed=2)
        assert obs0["map"].shape == obs1["map"].shape
        assert not np.array_equal(walls0, env.unwrapped.world.segments_m)
    finally:
        env.close()


def test_the_semantic_expert_runs_a_short_mission_in_a_small_noise_cave() -> None:
    from semexplore_gym.policies.registry import make_policy

    from semexplore_gym.evaluation.rollout import make_mission_env, run_mission

    env = make_mission_env("noisecave:seed=7,size_m=6")
    try:
        res = run_mission(env, make_policy("semantic"), seed=0, max_time_s=40.0)
    finally:
        env.close()
    assert res.steps > 0 and res.path_length_m > 0.5
    assert res.coverage > 0.2 and res.collisions == 0
