"""Rays against robot discs, and merging robots' occupancy grids."""

from __future__ import annotations

import math

import numpy as np
import pytest

from semexplore_gym.core.grid import FREE, OCCUPIED, UNKNOWN, GridGeometry
from semexplore_gym.core.mapping.disc_cast import cast_discs
from semexplore_gym.core.mapping.map_merge import merge_grids
from semexplore_gym.core.mapping.occupancy_grid import OccupancyGrid


def test_cast_discs_against_geometry() -> None:
    th = np.deg2rad(np.arange(360.0))
    d = cast_discs(0.0, 0.0, np.cos(th), np.sin(th), [[1.0, 0.0], [0.0, -2.0]], 0.1)
    assert d[0] == pytest.approx(0.9)
    assert d[270] == pytest.approx(1.9)
    assert math.isinf(d[90]) and math.isinf(d[180])
    # A ray at angle a meets the disc of radius r at distance c at along - sqrt(r^2 - miss^2).
    a = math.radians(3.0)
    assert d[3] == pytest.approx(math.cos(a) - math.sqrt(0.01 - math.sin(a) ** 2))
    # The nearer disc wins.
    d2 = cast_discs(0.0, 0.0, np.ones(1), np.zeros(1), [[2.0, 0.0], [1.0, 0.0]], 0.1)
    assert d2[0] == pytest.approx(0.9)


def test_merge_grids_keeps_the_more_certain_cell() -> None:
    g = GridGeometry(origin_x_m=0.0, origin_y_m=0.0, resolution_m=0.1, height=20, width=20)
    a, b = OccupancyGrid(g), OccupancyGrid(g)
    beams = np.array([0.0])
    a.integrate_scan(0.05, 0.55, 0.0, beams, np.array([1.0]), 3.0)  # free row, wall at x=1.05
    b.integrate_scan(0.05, 1.55, 0.0, beams, np.array([0.5]), 3.0)
    merge_grids([a, b])
    assert np.array_equal(a.encoded, b.encoded)
    assert a.encoded[5, 3] == FREE and a.encoded[15, 3] == FREE
    assert a.encoded[5, 10] == OCCUPIED and a.encoded[15, 5] == OCCUPIED
    assert a.encoded[10, 3] == UNKNOWN
    assert a.n_free_cells == int((a.encoded == FREE).sum()) == b.n_free_cells
    before = a.encoded.copy()
    merge_grids([a, b])  # merging again changes nothing
    assert np.array_equal(a.encoded, before)
