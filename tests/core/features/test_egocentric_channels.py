"""Extra egocentric channels (frontier distance, trail), centred scan bins and mirroring."""

from __future__ import annotations

import math

import numpy as np
import pytest

from semexplore_gym.core.features.egocentric import (
    EgocentricEncoder,
    EgocentricParams,
    frontier_distance_m,
    mirror_observations,
)
from semexplore_gym.core.grid import FREE, OCCUPIED, GridGeometry, parse_ascii_grid

RES_M = 0.1
GEOM = GridGeometry(RES_M, 0.0, 0.0, 41, 41)
INFO = {"map_geometry": GEOM.to_dict(), "lidar": {"max_range_m": 3.5, "n_beams": 360}}
CROP = 25  # odd: the robot on a cell centre puts every sample on a cell centre


def _obs(grid: np.ndarray, x_m: float, y_m: float, yaw_rad: float, scan=None) -> dict:
    return {
        "map": grid,
        "pose": np.array([x_m, y_m, yaw_rad], np.float32),
        "scan": np.full(360, 3.5, np.float32) if scan is None else scan,
    }


def test_default_params_keep_the_original_encoding() -> None:
    old = EgocentricParams.from_dict(
        {"crop_cells": 64, "crop_resolution_m": 0.1, "n_scan_bins": 60}
    )
    assert old == EgocentricParams() and old.channels == ("occupancy",) and old.n_channels == 1
    back = EgocentricParams.from_dict(EgocentricParams(channels=["occupancy", "trail"]).to_dict())
    assert back.channels == ("occupancy", "trail")
    for bad in (("occupancy", "occupancy"), ("walls",), (), "occupancy"):
        with pytest.raises(ValueError, match="channels"):
            EgocentricParams(channels=bad)  # type: ignore[arg-type]


def test_frontier_distance_on_a_corridor() -> None:
    # Row 0 of the text is the top (largest y). Frontier cells: FREE next to UNKNOWN, i.e. the
    # free cell at the corridor's east end (text row 1, col 5).
    grid = parse_ascii_grid(
        """
        #######
        #.....?
        #######
        """
    )
    d = frontier_distance_m(grid, RES_M, clearance_m=0.0)
    row = 1  # the corridor (middle text row is grid row 1)
    np.testing.assert_allclose(d[row, 1:6], [0.4, 0.3, 0.2, 0.1, 0.0], atol=1e-12)
    assert np.isinf(d[0]).all() and np.isinf(d[2]).all() and np.isinf(d[row, 6])
    # Clearance 0.1 m: every corridor cell is 0.1 m from a wall, so all stay usable; 0.15 m
    # leaves only the frontier cell itself.
    assert np.isfinite(frontier_distance_m(grid, RES_M, 0.1)[row, 1:6]).all()
    d_far = frontier_distance_m(grid, RES_M, 0.15)
    assert d_far[row, 5] == 0.0 and np.isinf(d_far[row, 1:5]).all()
    # No frontier at all: everything unreachable.
    closed = parse_ascii_grid("###\n#.#\n###")
    assert np.isinf(frontier_distance_m(closed, RES_M, 0.0)).all()


def test_frontier_distance_channel_runs_downhill_to_the_frontier() -> None:
    grid = np.full(GEOM.shape, FREE, np.uint8)
    grid[0, :] = grid[-1, :] = grid[:, 0] = OCCUPIED
    grid[1:-1, 40] = 128  # unknown east edge: frontier along column 39
    params = EgocentricParams(
        crop_cells=CROP, crop_resolution_m=None, channels=("frontier_distance",)
    )
    enc = EgocentricEncoder.from_info(params, INFO)
    img = enc.encode(_obs(grid, 2.05, 2.05, 0.0))["image"]
    assert img.shape == (1, CROP, CROP)
    layer = img[0]
    assert layer[12, 12] == 128  # the robot's own cell
    # Facing east: one cell ahead (row 11) is 0.1 m nearer the frontier (-2 levels at 20/m);
    # one cell behind (row 13) is farther; left and right are level.
    assert layer[11, 12] == 126 and layer[13, 12] == 130
    assert layer[12, 11] == layer[12, 13] == 128
    # Facing west, the frontier lies behind: ahead is uphill.
    layer_w = enc.encode(_obs(grid, 2.05, 2.05, math.pi))["image"][0]
    assert layer_w[11, 12] == 130 and layer_w[13, 12] == 126


def test_trail_marks_visited_cells_and_reset_clears_it() -> None:
    grid = np.full(GEOM.shape, FREE, np.uint8)
    params = EgocentricParams(
        crop_cells=CROP, crop_resolution_m=None, channels=("occupancy", "trail"), trail_radius_m=0.0
    )
    enc = EgocentricEncoder.from_info(params, INFO)
    enc.encode(_obs(grid, 1.05, 2.05, 0.0))
    img = enc.encode(_obs(grid, 2.05, 2.05, 0.0))["image"]
    assert img.shape == (2, CROP, CROP)
    trail = img[1]
    # Facing east from (2.05, 2.05): the first pose is 10 cells behind, on the centre column.
    assert sorted(zip(*np.nonzero(trail == 0), strict=True)) == [(12, 12), (22, 12)]
    enc.reset()
    trail = enc.encode(_obs(grid, 2.05, 2.05, 0.0))["image"][1]
    assert np.count_nonzero(trail == 0) == 1 and trail[12, 12] == 0


def test_centred_scan_bins() -> None:
    params = EgocentricParams(crop_cells=16, n_scan_bins=72, scan_bins_centred=True)
    enc = EgocentricEncoder.from_info(params, INFO)
    scan = np.full(360, 3.5, np.float32)
    scan[358] = 0.7  # 2 degrees right of the heading: bin 0 covers beams -2..2
    scan[3] = 1.75  # beam 3 starts bin 1 (beams 3..7)
    pooled = enc.pool_scan(scan)
    expected = np.ones(72, np.float32)
    expected[0], expected[1] = 0.2, 0.5
    np.testing.assert_allclose(pooled, expected, rtol=1e-6)


def test_mirror_twice_is_identity_and_mirrors_symmetric_worlds() -> None:
    rng = np.random.default_rng(0)
    params = EgocentricParams(
        crop_cells=CROP,
        crop_resolution_m=None,
        n_scan_bins=72,
        scan_bins_centred=True,
        channels=("occupancy", "frontier_distance"),
    )
    batch = {
        "image": rng.integers(0, 256, (4, 2, CROP, CROP), dtype=np.uint8),
        "scan": rng.random((4, 72), dtype=np.float32),
        "features": rng.random((4, 3), dtype=np.float32),
    }
    actions = rng.uniform(-1, 1, (4, 2)).astype(np.float32)
    m_obs, m_act = mirror_observations(batch, actions, params)
    np.testing.assert_array_equal(m_act[:, 0], actions[:, 0])
    np.testing.assert_array_equal(m_act[:, 1], -actions[:, 1])
    twice, twice_act = mirror_observations(m_obs, m_act, params)
    for k in batch:
        np.testing.assert_array_equal(twice[k], batch[k])
    np.testing.assert_array_equal(twice_act, actions)

    # A world symmetric about the robot's heading axis (y = 2.05 m, facing east) and a scan
    # symmetric about the heading encode to their own mirror images.
    grid = np.full(GEOM.shape, FREE, np.uint8)
    grid[[15, 25], 22:35] = OCCUPIED  # two walls 0.5 m left and right
    grid[20, 30] = OCCUPIED  # a post straight ahead
    grid[15:26, 37:] = 128  # unknown beyond: a symmetric frontier
    beams = np.arange(360)
    scan = (1.0 + 2.0 * np.abs(np.sin(np.deg2rad(beams)))).astype(np.float32)
    enc = EgocentricEncoder.from_info(params, INFO)
    f = enc.encode(_obs(grid, 2.05, 2.05, 0.0, scan))
    batch1 = {k: v[None] for k, v in f.items()}
    mirrored, _ = mirror_observations(batch1, np.zeros((1, 2), np.float32), params)
    for k in batch1:
        np.testing.assert_array_equal(mirrored[k], batch1[k])
    assert (f["image"][0] == OCCUPIED).any() and (f["image"][1] < 128).any()

    # Mirroring an asymmetric scan equals encoding the mirrored scan.
    scan2 = rng.uniform(0.2, 3.5, 360).astype(np.float32)
    a = enc.pool_scan(scan2)
    b = enc.pool_scan(scan2[(-beams) % 360])
    m, _ = mirror_observations(
        {"image": f["image"][None], "scan": a[None]}, np.zeros((1, 2), np.float32), params
    )
    np.testing.assert_array_equal(m["scan"][0], b)


def test_mirror_needs_centred_bins() -> None:
    obs = {"image": np.zeros((1, 1, 8, 8), np.uint8), "scan": np.zeros((1, 60), np.float32)}
    with pytest.raises(ValueError, match="scan_bins_centred"):
        mirror_observations(obs, np.zeros((1, 2), np.float32), EgocentricParams())


def test_encoder_pickles_mid_episode_and_encodes_on_alike() -> None:
    import pickle

    grid = np.full((41, 41), 128, np.uint8)
    grid[10:30, 10:30] = FREE
    grid[20, 12:28] = OCCUPIED
    params = EgocentricParams(crop_cells=CROP, channels=("occupancy", "frontier_distance", "trail"))
    enc = EgocentricEncoder.from_info(params, INFO)
    enc.encode(_obs(grid, 1.5, 1.5, 0.3))
    grid2 = grid.copy()
    grid2[25:30, 25:35] = FREE
    twin = pickle.loads(pickle.dumps(enc))
    a, b = enc.encode(_obs(grid2, 1.8, 1.6, 0.5)), twin.encode(_obs(grid2, 1.8, 1.6, 0.5))
    for k in a:
        np.testing.assert_array_equal(a[k], b[k])
    assert (a["image"][2] == 0).sum() > 0  # the trail survived the round trip
    assert len(pickle.dumps(enc)) < 20_000  # the frontier search's buffers are not pickled
