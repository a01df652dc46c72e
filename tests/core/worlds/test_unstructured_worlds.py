"""Unstructured families: forests (open ground with round trunks) and cluttered offices."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import ndimage

from semexplore_gym.core.worlds.forest import ForestParams, place_trunks
from semexplore_gym.core.worlds.procedural import list_world_names
from semexplore_gym.maps import make_world


def _components(mask: np.ndarray) -> int:
    return int(ndimage.label(mask, structure=ndimage.generate_binary_structure(2, 1))[1])


@pytest.mark.parametrize("seed", range(60))
def test_forest_gaps_are_at_least_min_gap_and_free_space_is_one_piece(seed: int) -> None:
    size = float(6 + seed % 5 * 6)
    params = ForestParams(
        seed=seed, size_m=size, density=4 + seed % 4 * 6, min_gap_m=0.45 + 0.05 * (seed % 4)
    )
    trunks = place_trunks(params, np.random.default_rng(seed))
    assert len(trunks) > 0
    x, y, r = trunks.T
    d = np.hypot(x[:, None] - x, y[:, None] - y) - r[:, None] - r
    np.fill_diagonal(d, np.inf)
    assert d.min() >= params.min_gap_m
    assert np.minimum.reduce([x - r, y - r, size - x - r, size - y - r]).min() >= params.min_gap_m
    world = make_world(
        f"forest:seed={seed},size_m={size:g},density={params.density:g},min_gap_m={params.min_gap_m:g}"
    )
    assert world.metadata["n_trunks"] == len(trunks)
    assert _components(world.free_mask) == 1


def test_forest_is_deterministic_and_listed() -> None:
    a, b = make_world("forest:seed=5"), make_world("forest:seed=5")
    assert np.array_equal(a.segments_m, b.segments_m) and a.start_pose == b.start_pose
    assert not np.array_equal(a.segments_m, make_world("forest:seed=6").segments_m)
    assert "forest" in list_world_names()


@pytest.mark.parametrize(
    "spec, needle",
    [
        ("forest:density=-1", "density=-1.0"),
        ("forest:min_gap_m=0.1", "min_gap_m=0.1"),
        ("forest:trunk_radius_min_m=0.5,trunk_radius_max_m=0.2", "trunk_radius_max_m=0.2"),
        ("forest:trees=3", "'trees'"),
    ],
)
def test_forest_bad_parameters_are_named(spec: str, needle: str) -> None:
    with pytest.raises(ValueError, match=needle.replace("(", r"\(").replace(".", r"\.")):
        make_world(spec)


@pytest.mark.parametrize("seed", range(12))
def test_office_clutter_keeps_the_plan_and_every_room_reachable(seed: int) -> None:
    plain = make_world(f"office:seed={seed},size_m=14")
    cluttered = make_world(f"office:seed={seed},size_m=14,clutter=1.5")
    assert plain.free_mask.shape == cluttered.free_mask.shape
    # Clutter only removes free cells (same floor plan), and removes some.
    assert not (cluttered.free_mask & ~plain.free_mask).any()
    assert cluttered.free_mask.sum() < plain.free_mask.sum()
    assert _components(cluttered.free_mask) == _components(plain.free_mask) == 1
    assert cluttered.start_pose == plain.start_pose
