"""Wavefront frontier detection on hand-drawn ASCII maps ('#' wall, '.' free, '?' unknown)."""

from __future__ import annotations

import numpy as np
import pytest

from semexplore_gym.core.frontiers.detection import (
    GridFrontier,
    detect_frontiers,
    frontier_cell_mask,
)
from semexplore_gym.core.grid import GridGeometry, parse_ascii_grid


def _setup(text: str, resolution_m: float = 1.0) -> tuple[np.ndarray, GridGeometry]:
    grid = parse_ascii_grid(text)
    return grid, GridGeometry(resolution_m, 0.0, 0.0, *grid.shape)


def _centre(row: int, col: int) -> tuple[float, float]:
    return (col + 0.5, row + 0.5)


# Row 0 is the *bottom* text line. Two openings into unknown space: a 3-cell one on the right
# (col 8, rows 1-3) and a 2-cell one at the top (row 4, cols 2-3).
ROOM = """
##??#####
#.......?
#.......?
#.......?
#########
"""


def test_room_with_two_openings_exact_cells() -> None:
    grid, geo = _setup(ROOM)
    fronts = detect_frontiers(grid, geo, _centre(1, 1), min_frontier_cells=1)
    assert sorted(f.size for f in fronts) == [2, 3]
    by_size = {f.size: f for f in fronts}
    assert sorted(map(tuple, by_size[3].cells.tolist())) == [(1, 8), (2, 8), (3, 8)]
    assert sorted(map(tuple, by_size[2].cells.tolist())) == [(4, 2), (4, 3)]
    # Centroid is the mean of cell centres.
    assert by_size[3].centroid_m == pytest.approx((8.5, 2.5))
    assert by_size[2].centroid_m == pytest.approx((3.0, 4.5))


def test_discovery_order_follows_the_wavefront() -> None:
    grid, geo = _setup(ROOM)
    # From the left the top opening is nearer; from the right the right-hand one is.
    left = detect_frontiers(grid, geo, _centre(1, 1), min_frontier_cells=1)
    right = detect_frontiers(grid, geo, _centre(2, 7), min_frontier_cells=1)
    assert [f.size for f in left] == [2, 3]
    assert [f.size for f in right] == [3, 2]
    assert [f.discovery_index for f in right] == [0, 1]


def test_nearest_initial_and_middle_cells() -> None:
    grid, geo = _setup(ROOM)
    robot = _centre(1, 6)
    right = next(f for f in detect_frontiers(grid, geo, robot, 1) if f.size == 3)
    assert right.nearest_cell == (1, 8)
    assert right.min_distance_m == pytest.approx(2.0)
    assert right.middle_cell == (2, 8)
    # The first-contact cell is the one the wavefront touched first: from (1, 6) the BFS reaches
    # (1, 7) before (2, 7) and (3, 7), so (1, 8) is met first.
    assert right.initial_cell == (1, 8)
    assert right.cell_xy_m(geo, "middle") == pytest.approx((8.5, 2.5))


def test_min_size_filter_keeps_discovery_index() -> None:
    grid, geo = _setup(ROOM)
    fronts = detect_frontiers(grid, geo, _centre(1, 1), min_frontier_cells=3)
    assert [f.size for f in fronts] == [3]
    assert fronts[0].discovery_index == 1
    assert detect_frontiers(grid, geo, _centre(1, 1), min_frontier_cells=4) == []


def test_frontier_behind_a_wall_is_not_found() -> None:
    # The right room touches unknown space but is sealed off from the robot by a wall.
    grid, geo = _setup(
        """
        #########
        #...#...?
        #...#...?
        #########
        """
    )
    assert detect_frontiers(grid, geo, _centre(1, 1), 1) == []
    # From inside the right room the same frontier is found.
    fronts = detect_frontiers(grid, geo, _centre(1, 6), 1)
    assert [f.size for f in fronts] == [2]
    # frontier_cell_mask ignores reachability.
    assert int(frontier_cell_mask(grid).sum()) == 2


def test_diagonal_gap_does_not_leak_the_outer_bfs() -> None:
    # Free cells touching only diagonally: the 4-connected outer BFS must not pass.
    grid, geo = _setup(
        """
        #####
        #.#??
        ##.??
        #####
        """
    )
    assert detect_frontiers(grid, geo, _centre(2, 1), 1) == []
    # From the other side: (1, 3) is the only unknown cell with a free 4-neighbour.
    assert [f.cells.tolist() for f in detect_frontiers(grid, geo, _centre(1, 2), 1)] == [[[1, 3]]]


def test_robot_on_unknown_or_occupied_cell_starts_at_nearest_free_cell() -> None:
    grid, geo = _setup(
        """
        ???????
        ???????
        ##...##
        ##...##
        #######
        """
    )
    # Robot on an unknown cell two rows above the free patch: the search starts at the nearest
    # free cell and finds the 3-cell frontier above the patch.
    fronts = detect_frontiers(grid, geo, _centre(4, 3), 1)
    assert len(fronts) == 1
    assert sorted(map(tuple, fronts[0].cells.tolist())) == [(3, 2), (3, 3), (3, 4)]
    # Robot on a wall cell: same result.
    on_wall = detect_frontiers(grid, geo, _centre(0, 3), 1)
    assert [f.size for f in on_wall] == [3]


def test_no_free_cell_means_no_frontier() -> None:
    grid, geo = _setup("???\n?#?\n???")
    assert detect_frontiers(grid, geo, _centre(1, 1), 1) == []


def test_free_cell_convention() -> None:
    grid, geo = _setup(ROOM)
    fronts = detect_frontiers(grid, geo, _centre(1, 1), 1, cell_convention="free")
    cells = sorted(tuple(c) for f in fronts for c in f.cells.tolist())
    # Free cells with an unknown 4-neighbour: col 7 rows 1-3, and row 3 cols 2-3.
    assert cells == [(1, 7), (2, 7), (3, 2), (3, 3), (3, 7)]
    # (3, 3) and the right column are not 8-connected, so these are two frontiers.
    assert sorted(f.size for f in fronts) == [2, 3]


def test_8_connected_grouping() -> None:
    # Two unknown cells touching only diagonally, each next to free space: one frontier.
    grid, geo = _setup(
        """
        #?####
        #.?..#
        #....#
        ######
        """
    )
    fronts = detect_frontiers(grid, geo, _centre(1, 1), 1)
    assert len(fronts) == 1
    assert sorted(map(tuple, fronts[0].cells.tolist())) == [(2, 2), (3, 1)]
    assert isinstance(fronts[0], GridFrontier)


def test_bad_input_raises_clear_errors() -> None:
    grid, geo = _setup(ROOM)
    with pytest.raises(ValueError, match="outside the grid"):
        detect_frontiers(grid, geo, (100.0, 0.5))
    with pytest.raises(ValueError, match="min_frontier_cells"):
        detect_frontiers(grid, geo, (1.5, 1.5), min_frontier_cells=0)
    with pytest.raises(ValueError, match="cell_convention"):
        detect_frontiers(grid, geo, (1.5, 1.5), cell_convention="both")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="does not match"):
        detect_frontiers(grid[:, :5], geo, (1.5, 1.5))
    with pytest.raises(TypeError, match="uint8"):
        detect_frontiers(grid.astype(np.int32), geo, (1.5, 1.5))
    with pytest.raises(ValueError, match="robot_xy_m"):
        detect_frontiers(grid, geo, (np.nan, 1.0))
