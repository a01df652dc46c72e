"""EgocentricObservation: heading-up crops on hand-built maps, scan pooling, env integration."""

from __future__ import annotations

import math

import numpy as np
import pytest

from semexplore_gym.core.grid import FREE, OCCUPIED, UNKNOWN, GridGeometry
from semexplore_gym.wrappers.egocentric import (
    EgocentricEncoder,
    EgocentricParams,
    egocentric_features,
    egocentric_observation_space,
)

RES_M = 0.1
GEOM = GridGeometry(RES_M, 0.0, 0.0, 41, 41)
INFO = {"map_geometry": GEOM.to_dict(), "lidar": {"max_range_m": 3.5, "n_beams": 360}}
# Robot on the centre of cell (20, 20); an odd crop puts every sample on a cell centre.
X_M = Y_M = 2.05
CROP = 25  # centre row/col 12


def _east_wall_map() -> np.ndarray:
    """Free map with a wall along column 30 (x in [3.0, 3.1)), 1 m east of the robot."""
    grid = np.full(GEOM.shape, FREE, np.uint8)
    grid[:, 30] = OCCUPIED
    return grid


def _crop(grid: np.ndarray, x_m: float, y_m: float, yaw_rad: float, **kw: object) -> np.ndarray:
    params = EgocentricParams(
        crop_cells=CROP, crop_resolution_m=kw.pop("crop_resolution_m", None), n_scan_bins=60
    )
    obs = {
        "map": grid,
        "pose": np.array([x_m, y_m, yaw_rad], np.float32),
        "scan": np.full(360, 3.5, np.float32),
    }
    return egocentric_features(obs, INFO, params)["image"][0]


@pytest.mark.parametrize(
    ("yaw_rad", "where"),
    [
        (0.0, "top"),
        (math.pi / 2, "right"),
        (math.pi, "bottom"),
        (-math.pi / 2, "left"),
        (-math.pi, "bottom"),
    ],
)
def test_wall_lands_on_the_side_the_heading_implies(yaw_rad: float, where: str) -> None:
    img = _crop(_east_wall_map(), X_M, Y_M, yaw_rad)
    expected = np.full((CROP, CROP), FREE, np.uint8)
    # 1.0 m at 0.1 m per cell = 10 cells from the centre index 12.
    if where == "top":
        expected[2, :] = OCCUPIED
    elif where == "bottom":
        expected[22, :] = OCCUPIED
    elif where == "right":
        expected[:, 22] = OCCUPIED
    else:
        expected[:, 2] = OCCUPIED
    np.testing.assert_array_equal(img, expected)


@pytest.mark.parametrize("yaw_rad", [0.3, 1.2, 2.5, -0.7, -2.9])
def test_wall_ahead_is_at_the_top_for_any_heading(yaw_rad: float) -> None:
    # Draw a wall 1 m ahead of the robot, perpendicular to its heading, 1 m long.
    grid = np.full(GEOM.shape, FREE, np.uint8)
    c, s = math.cos(yaw_rad), math.sin(yaw_rad)
    for t in np.linspace(-0.5, 0.5, 101):
        x, y = X_M + 1.0 * c - t * s, Y_M + 1.0 * s + t * c
        row, col = GEOM.world_to_grid(x, y)
        grid[int(row), int(col)] = OCCUPIED
    img = _crop(grid, X_M, Y_M, yaw_rad)
    rows, cols = np.nonzero(img == OCCUPIED)
    assert rows.size >= 8
    # Ahead = rows above the centre at ~10 cells (+-1 for rasterisation), centred left-right.
    assert rows.min() >= 1 and rows.max() <= 3
    assert abs(cols.mean() - 12) <= 1.0
    assert cols.min() >= 12 - 6 and cols.max() <= 12 + 6


def test_outside_the_map_reads_unknown() -> None:
    grid = np.full(GEOM.shape, FREE, np.uint8)
    # Robot 0.25 m from the west edge, facing west: the map ends 2-3 cells ahead.
    img = _crop(grid, 0.25, Y_M, math.pi)
    # Ahead sample rows i sit at x = 0.25 + (12 - i) * 0.1 west... x < 0 for i <= 9.
    assert (img[:10] == UNKNOWN).all()
    assert (img[10:] == FREE).all()


def test_coarse_crop_keeps_thin_walls() -> None:
    # 0.3 m crop cells over a 0.1 m map: a one-cell wall must survive (min over sub-samples).
    img = _crop(_east_wall_map(), X_M, Y_M, 0.0, crop_resolution_m=0.3)
    occupied_rows = np.unique(np.nonzero(img == OCCUPIED)[0])
    assert occupied_rows.tolist() == [9]  # 1.0 m ahead -> 3.33 crop cells above the centre 12
    # Columns 5..19 hold a wall sample inside the map; farther out the map ends (UNKNOWN).
    np.testing.assert_array_equal(np.nonzero(img[9] == OCCUPIED)[0], np.arange(5, 20))


def test_scan_pooling_ignores_invalid_and_normalises() -> None:
    params = EgocentricParams(crop_cells=16, crop_resolution_m=None, n_scan_bins=60)
    enc = EgocentricEncoder.from_info(params, INFO)
    scan = np.full(360, 3.5, np.float32)
    scan[0] = 0.0  # invalid return: ignored
    scan[7] = 0.7  # bin 1 (beams 6..11)
    scan[359] = 1.75  # bin 59
    pooled = enc.pool_scan(scan)
    expected = np.ones(60, np.float32)
    expected[1] = 0.2
    expected[59] = 0.5
    np.testing.assert_allclose(pooled, expected, rtol=1e-6)


def test_features_and_space() -> None:
    params = EgocentricParams(crop_cells=16, crop_resolution_m=None, n_scan_bins=60)
    grid = np.full(GEOM.shape, UNKNOWN, np.uint8)
    grid[:, :21] = FREE  # west half known free (cols 0..20)
    # Robot on a cell corner so the even crop samples cell centres.
    obs = {
        "map": grid,
        "pose": np.array([2.0, 2.0, 0.0], np.float32),
        "scan": np.full(360, 3.5, np.float32),
    }
    obs["scan"][:30] = 1.0  # bins 0..4 see a wall
    out = egocentric_features(obs, INFO, params)
    assert egocentric_observation_space(params).contains(out)
    # Facing east, crop row i samples map column 27 - i: rows 7..15 (9 of 16) are known free.
    np.testing.assert_allclose(out["features"], [9 / 16, 9 / 16, 55 / 60], rtol=1e-6)


def test_bad_inputs_raise_clear_errors() -> None:
    with pytest.raises(ValueError, match="crop_cells"):
        EgocentricParams(crop_cells=3)
    with pytest.raises(ValueError, match="n_scan_bins=7 must divide"):
        EgocentricEncoder.from_info(EgocentricParams(n_scan_bins=7), INFO)
    enc = EgocentricEncoder.from_info(EgocentricParams(crop_cells=16), INFO)
    with pytest.raises(ValueError, match="shape"):
        enc.crop(np.zeros((5, 5), np.uint8), 0.0, 0.0, 0.0)
    with pytest.raises(ValueError, match="map_geometry"):
        egocentric_features({}, {}, EgocentricParams())


def _make_env(**kw: object):
    gym = pytest.importorskip("gymnasium")
    try:
        import semexplore_gym  # noqa: F401

        return gym.make("SemanticExplore-v0", world="maze:size_m=5,seed=1", **kw)
    except ImportError as e:  # the env's dependencies may still be landing
        pytest.skip(f"SemanticExplore-v0 not importable: {e}")


def test_wrapper_on_the_env_matches_the_pure_function() -> None:
    from semexplore_gym.wrappers.egocentric import EgocentricObservation

    raw_env = _make_env()
    env = EgocentricObservation(raw_env, crop_cells=48, crop_resolution_m=0.1, n_scan_bins=60)
    obs, info = env.reset(seed=3)
    assert env.observation_space.contains(obs)
    assert obs["image"].shape == (1, 48, 48) and obs["image"].dtype == np.uint8
    assert obs["scan"].shape == (60,) and obs["scan"].dtype == np.float32
    # Same seed, same raw observation: the wrapper equals the pure function of it.
    raw, raw_info = raw_env.reset(seed=3)
    ref = egocentric_features(raw, raw_info, env.params)
    for k in ref:
        np.testing.assert_array_equal(obs[k], ref[k])
    assert obs["features"][0] > 0.05  # the first scan mapped part of the crop
    assert (obs["image"] == FREE).any() and (obs["image"] == OCCUPIED).any()
    for _ in range(3):
        obs, _r, _te, _tr, info = env.step(np.array([0.5, 0.2], np.float32))
        assert env.observation_space.contains(obs)
    env.close()


def test_wrapped_env_passes_the_sb3_env_checker() -> None:
    pytest.importorskip("torch")
    env_checker = pytest.importorskip("stable_baselines3.common.env_checker")
    from semexplore_gym.wrappers.egocentric import EgocentricObservation

    env = EgocentricObservation(_make_env(), crop_cells=36, crop_resolution_m=0.15)
    env_checker.check_env(env, warn=False)
    env.close()


def test_wrapper_with_extra_channels_resets_the_trail() -> None:
    from semexplore_gym.wrappers.egocentric import EgocentricObservation

    params = EgocentricParams(
        crop_cells=36,
        crop_resolution_m=0.1,
        channels=("occupancy", "frontier_distance", "trail"),
        trail_radius_m=0.0,
    )
    env = EgocentricObservation(_make_env(), params=params)
    assert env.observation_space["image"].shape == (3, 36, 36)
    obs, _ = env.reset(seed=3)
    assert env.observation_space.contains(obs)
    assert np.count_nonzero(obs["image"][2] == 0) == 1  # only the start cell is on the trail
    # At the start most of the maze is unknown: some cells lie downhill towards a frontier.
    assert (obs["image"][1] < 128).any()
    for _ in range(5):
        obs, *_ = env.step(np.array([1.0, 0.0], np.float32))
    assert np.count_nonzero(obs["image"][2] == 0) >= 3  # driving ahead leaves a trail behind
    obs, _ = env.reset(seed=3)
    assert np.count_nonzero(obs["image"][2] == 0) == 1
    env.close()
