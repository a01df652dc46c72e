"""The compiled wall-distance transform gives scipy's Euclidean distance transform, to the bit."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import ndimage

from semexplore_gym.core.frontiers.reachable import clearance_field_m
from semexplore_gym.core.frontiers.wall_distance import wall_distance_m
from semexplore_gym.core.grid import FREE, OCCUPIED, UNKNOWN


def _scipy(grid: np.ndarray, res: float) -> np.ndarray:
    return ndimage.distance_transform_edt(grid != OCCUPIED) * res


def test_random_grids_match_scipy_bit_for_bit() -> None:
    rng = np.random.default_rng(0)
    values = np.array([FREE, UNKNOWN, OCCUPIED], np.uint8)
    for _ in range(200):
        h, w = (int(v) for v in rng.integers(1, 90, size=2))
        p = float(rng.choice([0.0005, 0.01, 0.1, 0.6]))
        grid = rng.choice(values, size=(h, w), p=[(1 - p) / 2, (1 - p) / 2, p])
        grid[rng.integers(h), rng.integers(w)] = OCCUPIED
        res = float(rng.choice([0.05, 0.1, 0.037]))
        got = wall_distance_m(grid, res)
        assert got.dtype == np.float64 and got.shape == grid.shape
        np.testing.assert_array_equal(got, _scipy(grid, res))


@pytest.mark.parametrize(
    "shape, walls",
    [
        ((1, 1), [(0, 0)]),
        ((1, 40), [(0, 39)]),
        ((40, 1), [(0, 0), (39, 0)]),
        ((30, 30), [(r, c) for r in range(30) for c in range(30)]),  # all walls
        ((60, 50), [(59, 0)]),  # one far corner: the longest distances
    ],
)
def test_edge_shapes_match_scipy(shape, walls) -> None:
    grid = np.full(shape, FREE, np.uint8)
    for rc in walls:
        grid[rc] = OCCUPIED
    np.testing.assert_array_equal(wall_distance_m(grid, 0.05), _scipy(grid, 0.05))


def test_map_like_grid_and_clearance_field() -> None:
    # Rooms and corridors: walls in long runs, unknown space beyond them.
    grid = np.full((120, 160), UNKNOWN, np.uint8)
    grid[10:110, 10:150] = FREE
    grid[10, 10:150] = grid[109, 10:150] = OCCUPIED
    grid[10:110, 10] = grid[10:110, 149] = OCCUPIED
    grid[10:80, 70] = OCCUPIED
    grid[50, 90:149] = OCCUPIED
    np.testing.assert_array_equal(clearance_field_m(grid, 0.05), _scipy(grid, 0.05))
    # A non-contiguous view reads the same; no wall at all is inf everywhere.
    np.testing.assert_array_equal(clearance_field_m(grid.T, 0.1), _scipy(grid.T, 0.1))
    assert np.isinf(clearance_field_m(np.full((5, 6), FREE, np.uint8), 0.05)).all()
    assert np.isinf(wall_distance_m(np.full((4, 3), UNKNOWN, np.uint8), 0.05)).all()
