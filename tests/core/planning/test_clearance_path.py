"""Shortest paths at a clearance: straight lines at any angle, detours round walls."""

from __future__ import annotations

import math

import numpy as np
import pytest

from semexplore_gym.core.grid import FREE, OCCUPIED, UNKNOWN, GridGeometry
from semexplore_gym.core.planning.clearance_path import clear_cells, shortest_clear_path_m

RES = 0.05


def _room(h_m: float, w_m: float) -> tuple[np.ndarray, GridGeometry]:
    """A walled FREE room, ``h_m`` by ``w_m``, origin at its lower left corner."""
    h, w = round(h_m / RES), round(w_m / RES)
    grid = np.full((h, w), FREE, dtype=np.uint8)
    grid[[0, -1], :] = OCCUPIED
    grid[:, [0, -1]] = OCCUPIED
    return grid, GridGeometry(RES, 0.0, 0.0, h, w)


def test_clear_cells_keep_the_clearance_from_walls_and_skip_unknown() -> None:
    grid, geo = _room(1.0, 2.0)
    grid[5:8, 30:33] = UNKNOWN
    mask = clear_cells(grid, geo, 0.2)
    assert not mask[0:4, :].any() and not mask[:, 0:4].any()  # within 0.2 m of a wall
    assert mask[10, 20] and not mask[6, 31]


@pytest.mark.parametrize("angle_deg", [0.0, 22.5, 30.0, 45.0])
def test_a_straight_line_measures_its_length_at_any_angle(angle_deg: float) -> None:
    grid, geo = _room(4.0, 4.0)
    mask = clear_cells(grid, geo, 0.2)
    a = math.radians(angle_deg)
    start = (0.6, 0.6)
    end = (start[0] + 2.5 * math.cos(a), start[1] + 2.5 * math.sin(a))
    length = shortest_clear_path_m(mask, geo, start, end, snap_m=0.3)
    # 8-connected steps alone would give up to 8 % more at 22.5 degrees.
    assert length == pytest.approx(2.5, abs=0.03)


def test_a_wall_makes_the_shortest_path_go_round_it() -> None:
    grid, geo = _room(3.0, 3.0)
    grid[: round(2.0 / RES), round(1.5 / RES)] = OCCUPIED  # a wall from the bottom up to y = 2 m
    mask = clear_cells(grid, geo, 0.2)
    start, end = (0.75, 0.5), (2.25, 0.5)
    length = shortest_clear_path_m(mask, geo, start, end, snap_m=0.3)
    assert length is not None
    # Round the wall's end at clearance: two legs up to about (1.5, 2.2) and down again.
    around = 2 * math.hypot(0.75, 2.2 - 0.5)
    assert length == pytest.approx(around, rel=0.05)
    assert length > 1.5 * math.dist(start, end)


def test_no_path_through_a_closed_wall_or_from_off_the_grid() -> None:
    grid, geo = _room(2.0, 3.0)
    grid[:, round(1.5 / RES)] = OCCUPIED
    mask = clear_cells(grid, geo, 0.2)
    assert shortest_clear_path_m(mask, geo, (0.5, 1.0), (2.5, 1.0), snap_m=0.3) is None
    assert shortest_clear_path_m(mask, geo, (-1.0, 1.0), (0.8, 1.0), snap_m=0.3) is None
