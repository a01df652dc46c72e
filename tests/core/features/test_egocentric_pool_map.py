"""``EgocentricParams.pool_map``: the crops sampled once per crop cell on the min-pooled map."""

from __future__ import annotations

import dataclasses

import gymnasium as gym
import numpy as np
import pytest

import semexplore_gym  # noqa: F401
from semexplore_gym.core.features.egocentric import EgocentricEncoder, EgocentricParams
from semexplore_gym.core.features.egocentric_kernels import min_pool
from semexplore_gym.core.grid import FREE, OCCUPIED, UNKNOWN, GridGeometry

TRAIN = EgocentricParams(
    n_scan_bins=72,
    scan_bins_centred=True,
    channels=("occupancy", "frontier_distance", "trail"),
    pool_map=True,
)


def test_min_pool_is_the_block_minimum_with_unknown_beyond_the_map() -> None:
    rng = np.random.default_rng(0)
    values = np.array([OCCUPIED, UNKNOWN, FREE], np.uint8)
    for _ in range(200):
        h, w = (int(v) for v in rng.integers(1, 60, size=2))
        f = int(rng.integers(1, 5))
        grid = rng.choice(values, size=(h, w), p=[0.1, 0.3, 0.6])
        ho, wo = -(-h // f), -(-w // f)
        out = np.empty((ho, wo), np.uint8)
        min_pool(grid, f, out)
        padded = np.full((ho * f, wo * f), UNKNOWN, np.uint8)
        padded[:h, :w] = grid
        np.testing.assert_array_equal(out, padded.reshape(ho, f, wo, f).min(axis=(1, 3)))


def test_pool_map_is_the_plain_encoder_on_the_pooled_map() -> None:
    """Along a random walk (trail and incremental frontier field included): encoding the map
    with ``pool_map`` equals encoding its 2 x 2 minimum with the plain encoder."""
    env = gym.make("SemanticExplore-v0", world="maze1")
    obs, info = env.reset(seed=1)
    fine = GridGeometry.from_dict(info["map_geometry"])
    f = round(TRAIN.crop_resolution_m / fine.resolution_m)
    coarse = GridGeometry(
        fine.resolution_m * f,
        fine.origin_x_m,
        fine.origin_y_m,
        -(-fine.height // f),
        -(-fine.width // f),
    )
    n_beams = int(info["lidar"]["n_beams"])
    pooled_enc = EgocentricEncoder(TRAIN, fine, 3.5, n_beams)
    plain_enc = EgocentricEncoder(dataclasses.replace(TRAIN, pool_map=False), coarse, 3.5, n_beams)
    assert pooled_enc.supersample == 1 and plain_enc.supersample == 1
    rng = np.random.default_rng(2)
    pooled = np.empty(coarse.shape, np.uint8)
    n_fd_levels = set()
    for step in range(120):
        min_pool(obs["map"], f, pooled)
        got = pooled_enc.encode(obs)
        want = plain_enc.encode({**obs, "map": pooled})
        for key in ("image", "scan", "features"):
            np.testing.assert_array_equal(got[key], want[key])
        n_fd_levels.update(np.unique(got["image"][1]).tolist())
        if step % 30 == 0:  # now and then: the public helpers read the same grid
            x, y, yaw = (float(v) for v in obs["pose"])
            np.testing.assert_array_equal(
                pooled_enc.crop(obs["map"], x, y, yaw), plain_enc.crop(pooled, x, y, yaw)
            )
            np.testing.assert_array_equal(
                pooled_enc.frontier_distance_image(obs["map"], x, y),
                plain_enc.frontier_distance_image(pooled, x, y),
            )
        obs, *_ = env.step(np.array([rng.uniform(0.3, 1.0), rng.uniform(-1, 1)], np.float32))
    env.close()
    assert len(n_fd_levels) > 10  # the frontier channel carried a real field, not a constant


def test_pool_map_parameters() -> None:
    assert EgocentricParams().pool_map is False  # models trained before it keep their encoding
    assert EgocentricParams.from_dict({"crop_cells": 64}).pool_map is False
    assert EgocentricParams.from_dict(TRAIN.to_dict()) == TRAIN
    with pytest.raises(ValueError, match="pool_map must be a bool"):
        EgocentricParams(pool_map="yes")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="crop_resolution_m"):
        EgocentricParams(crop_resolution_m=None, pool_map=True)
    geom = GridGeometry(0.05, 0.0, 0.0, 40, 40)
    with pytest.raises(ValueError, match="whole multiple"):
        EgocentricEncoder(EgocentricParams(crop_resolution_m=0.125, pool_map=True), geom, 3.5, 360)
    # A factor of 3 and a map that is not a whole number of blocks.
    enc = EgocentricEncoder(
        EgocentricParams(crop_cells=16, crop_resolution_m=0.15, pool_map=True), geom, 3.5, 360
    )
    grid = np.full((40, 40), FREE, np.uint8)
    grid[:, 20] = OCCUPIED
    out = enc.encode(
        {
            "map": grid,
            "pose": np.array([0.5, 1.0, 0.0], np.float32),
            "scan": np.full(360, 2.0, np.float32),
        }
    )
    assert out["image"].shape == (1, 16, 16) and (out["image"] == OCCUPIED).any()
