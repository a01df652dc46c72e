"""Costmap inflation, the Navfn-like planner and Dijkstra distance fields on small grids."""

from __future__ import annotations

import math

import numpy as np
import pytest

from semexplore_gym.core.grid import FREE, OCCUPIED, UNKNOWN, GridGeometry, parse_ascii_grid
from semexplore_gym.core.planning.grid_search import (
    INSCRIBED_COST,
    LETHAL_COST,
    NO_INFORMATION,
    CostmapParams,
    NavfnParams,
    cells_near_occupied,
    distance_field,
    geodesic_distance_m,
    inflate_costmap,
    inflation_cost,
    navfn_cell_costs,
    plan_path,
    shortest_path_cells,
)

SQRT2 = math.sqrt(2.0)


def _path_is_8_connected(cells: np.ndarray) -> bool:
    steps = np.abs(np.diff(cells, axis=0))
    return bool((steps.max(axis=1) == 1).all())


@pytest.mark.parametrize("use_astar", [False, True])
def test_uniform_grid_diagonal_and_straight_costs(use_astar: bool) -> None:
    cost = np.ones((5, 7))
    cells, total = shortest_path_cells(cost, (0, 0), (4, 4), use_astar=use_astar)
    assert total == pytest.approx(4 * SQRT2)
    assert cells.tolist() == [[0, 0], [1, 1], [2, 2], [3, 3], [4, 4]]
    # 4 rows and 6 cols apart: 4 diagonal + 2 straight steps.
    cells, total = shortest_path_cells(cost, (0, 0), (4, 6), use_astar=use_astar)
    assert total == pytest.approx(4 * SQRT2 + 2)
    assert len(cells) == 7 and _path_is_8_connected(cells)


@pytest.mark.parametrize("use_astar", [False, True])
def test_detour_around_a_wall_without_corner_cutting(use_astar: bool) -> None:
    cost = np.ones((5, 5))
    cost[2, :4] = np.inf  # wall with a gap at column 4
    cells, total = shortest_path_cells(cost, (0, 0), (4, 0), use_astar=use_astar)
    # Diagonal into row 1, along it to column 4 (no diagonal past the wall end), down, back.
    assert total == pytest.approx(8 + 2 * SQRT2)
    assert [2, 4] in cells.tolist()
    assert not np.isinf(cost[cells[:, 0], cells[:, 1]]).any()


def test_weighted_cells_are_avoided_when_cheaper() -> None:
    cost = np.ones((3, 5))
    cost[1, 1:4] = 10.0  # expensive middle row
    cells, total = shortest_path_cells(cost, (1, 0), (1, 4))
    # Straight through: 40. Around (row 0 or 2): diagonal, 2 straight, diagonal = 2 + 2*sqrt(2).
    assert total == pytest.approx(2 + 2 * SQRT2)
    assert all(r != 1 for r, c in cells[1:-1].tolist())


def test_unreachable_returns_none() -> None:
    cost = np.ones((5, 5))
    cost[2, :] = np.inf
    assert shortest_path_cells(cost, (0, 0), (4, 4)) is None
    assert shortest_path_cells(cost, (0, 0), (2, 2)) is None  # goal is itself a wall


def test_distance_field_matches_octile_and_marks_unreachable() -> None:
    cost = np.ones((4, 6))
    cost[:, 3] = np.inf
    dist, parent = distance_field(cost, (0, 0))
    assert dist[3, 2] == pytest.approx(2 * SQRT2 + 1)
    assert dist[0, 2] == pytest.approx(2.0)
    assert np.isinf(dist[:, 3:]).all()
    assert parent[0, 0] == -1 and parent[0, 1] == 0


def test_geodesic_distance_in_metres() -> None:
    grid = parse_ascii_grid(
        """
        .....
        ####.
        .....
        """
    )
    geo = GridGeometry(0.1, 0.0, 0.0, *grid.shape)
    d = geodesic_distance_m(grid == FREE, geo, (0.05, 0.05))  # bottom-left cell
    # To the top-left cell through the one-cell gap at column 4. The diagonals into and out of
    # the gap would cut the wall corner at (1, 3), so the path is 4 + 2 + 4 = 10 straight steps.
    assert d[2, 0] == pytest.approx(1.0)
    assert np.isinf(d[1, 0])


def test_inflation_values_follow_ros_formula() -> None:
    prm = CostmapParams(inscribed_radius_m=0.105, inflation_radius_m=0.2, cost_scaling_factor=10.0)
    assert inflation_cost(0.0, prm) == LETHAL_COST
    assert inflation_cost(0.1, prm) == INSCRIBED_COST
    assert inflation_cost(0.15, prm) == math.floor(252 * math.exp(-10 * (0.15 - 0.105)))
    assert inflation_cost(0.2001, prm) == 0
    grid = np.full((5, 9), FREE, dtype=np.uint8)
    grid[2, 4] = OCCUPIED
    grid[0, 0] = UNKNOWN
    grid[2, 3] = UNKNOWN  # next to the wall: becomes inscribed
    cm = inflate_costmap(grid, 0.05, prm)
    assert cm[2, 4] == LETHAL_COST
    assert cm[2, 2] == INSCRIBED_COST  # 0.10 m
    assert cm[2, 3] == INSCRIBED_COST
    assert cm[2, 1] == math.floor(252 * math.exp(-10 * (0.15 - 0.105)))  # 0.15 m
    assert cm[0, 0] == NO_INFORMATION
    assert cm[2, 8] == math.floor(252 * math.exp(-10 * (0.2 - 0.105)))  # 0.20 m: still inside
    assert cm[0, 8] == 0  # sqrt(20) cells = 0.224 m: beyond the inflation radius
    assert inflate_costmap(grid, 0.05, CostmapParams(track_unknown_space=False))[0, 0] == 0


def test_navfn_costs_and_unknown_handling() -> None:
    cm = np.array([[0, 100, INSCRIBED_COST, LETHAL_COST, NO_INFORMATION]], dtype=np.uint8)
    c = navfn_cell_costs(cm)
    assert c[0, 0] == 50 and c[0, 1] == pytest.approx(130)
    assert np.isinf(c[0, 2]) and np.isinf(c[0, 3])
    assert c[0, 4] == INSCRIBED_COST
    assert np.isinf(navfn_cell_costs(cm, NavfnParams(allow_unknown=False))[0, 4])


def test_plan_path_in_metres_through_a_corridor() -> None:
    grid = parse_ascii_grid(
        """
        ##########
        #........#
        #........#
        #........#
        ######...#
        #........#
        #........#
        #........#
        ##########
        """
    )
    geo = GridGeometry(0.1, 0.0, 0.0, *grid.shape)
    prm = CostmapParams(inscribed_radius_m=0.1, inflation_radius_m=0.1)
    cm = inflate_costmap(grid, 0.1, prm)
    path = plan_path(cm, geo, (0.25, 0.25), (0.25, 0.65), NavfnParams())
    assert path is not None
    assert path.points_m[0] == pytest.approx((0.25, 0.25))
    assert path.points_m[-1] == pytest.approx((0.25, 0.65))
    # Every interior cell must be passable (no inscribed/lethal cell).
    assert (cm[path.cells[1:, 0], path.cells[1:, 1]] < INSCRIBED_COST).all()
    seg = np.hypot(*np.diff(path.points_m, axis=0).T).sum()
    assert path.length_m == pytest.approx(seg)
    assert path.length_m > 1.0  # it must go round the wall through the gap on the right


def test_plan_path_unreachable_and_tolerance() -> None:
    grid = parse_ascii_grid(
        """
        #######
        #..#..#
        #..#..#
        #######
        """
    )
    geo = GridGeometry(1.0, 0.0, 0.0, *grid.shape)
    cm = inflate_costmap(grid, 1.0, CostmapParams(inscribed_radius_m=0.0, inflation_radius_m=0.0))
    assert plan_path(cm, geo, (1.5, 1.5), (4.5, 1.5)) is None
    # A goal on the wall is reached with enough tolerance: the nearest reachable cell is (1, 2).
    tol = plan_path(cm, geo, (1.5, 1.5), (3.5, 1.5), NavfnParams(goal_tolerance_m=1.0))
    assert tol is not None and tuple(tol.cells[-1]) == (1, 2)
    assert plan_path(cm, geo, (1.5, 1.5), (3.5, 1.5)) is None
    assert plan_path(cm, geo, (1.5, 1.5), (40.0, 1.5)) is None


def test_escape_radius_lets_a_robot_in_the_inscribed_band_plan() -> None:
    grid = np.full((3, 12), FREE, dtype=np.uint8)
    grid[0, :] = OCCUPIED
    geo = GridGeometry(0.05, 0.0, 0.0, *grid.shape)
    prm = CostmapParams(inscribed_radius_m=0.105, inflation_radius_m=0.2)
    grid = np.vstack([grid, np.full((4, 12), FREE, dtype=np.uint8)])
    geo = GridGeometry(0.05, 0.0, 0.0, *grid.shape)
    cm = inflate_costmap(grid, 0.05, prm)
    start = (0.125, 0.075)  # row 1: 0.05 m from the wall row, inside the inscribed band
    goal = (0.525, 0.275)  # row 5: free
    assert plan_path(cm, geo, start, goal) is None
    assert plan_path(cm, geo, start, goal, NavfnParams(escape_radius_m=0.15)) is not None


def test_bad_input() -> None:
    with pytest.raises(ValueError, match="cell_cost must be > 0"):
        shortest_path_cells(np.zeros((3, 3)), (0, 0), (2, 2))
    with pytest.raises(ValueError, match="outside the grid"):
        shortest_path_cells(np.ones((3, 3)), (0, 0), (3, 2))
    with pytest.raises(ValueError, match="inflation_radius_m"):
        CostmapParams(inscribed_radius_m=0.3, inflation_radius_m=0.2)
    with pytest.raises(TypeError, match="uint8"):
        navfn_cell_costs(np.zeros((2, 2), dtype=np.int32))


def test_distance_field_from_several_sources() -> None:
    cost = np.ones((1, 7))
    dist, _ = distance_field(cost, np.array([[0, 0], [0, 6]]))
    assert dist[0].tolist() == [0, 1, 2, 3, 2, 1, 0]


def test_cells_near_occupied() -> None:
    grid = np.full((5, 7), FREE, dtype=np.uint8)
    grid[2, 3] = OCCUPIED
    cells = np.array([[2, 3], [2, 5], [2, 6], [0, 3], [4, 4], [9, 9]])
    out = cells_near_occupied(grid, cells, radius_m=0.1, resolution_m=0.05)
    # 0 m, 0.10 m (on the radius), 0.15 m, 0.10 m, sqrt(5)*0.05 = 0.11 m, outside the grid.
    assert out.tolist() == [True, True, False, True, False, True]


def test_distance_field_with_initial_source_costs() -> None:
    cost = np.ones((1, 5))
    dist, _ = distance_field(cost, np.array([[0, 0], [0, 4]]), start_cost=np.array([0.3, 2.5]))
    # Column 4 keeps its own start cost (2.5 < 0.3 + 4); column 3 gets min(0.3 + 3, 2.5 + 1).
    assert dist[0].tolist() == pytest.approx([0.3, 1.3, 2.3, 3.3, 2.5])
    with pytest.raises(ValueError, match="start_cost"):
        distance_field(cost, np.array([[0, 0]]), start_cost=np.array([-1.0]))
