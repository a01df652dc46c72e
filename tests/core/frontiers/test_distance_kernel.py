"""The fused frontier-distance kernel equals the composed scipy dilation + general Dijkstra."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import ndimage

from semexplore_gym.core.features.egocentric import EgocentricEncoder, EgocentricParams
from semexplore_gym.core.frontiers.detection import frontier_cell_mask
from semexplore_gym.core.frontiers.distance import (
    FrontierDistanceField,
    frontier_distance_m,
    relative_distance_image,
)
from semexplore_gym.core.grid import FREE, OCCUPIED, UNKNOWN, GridGeometry, parse_ascii_grid
from semexplore_gym.core.planning.grid_search import distance_field
from semexplore_gym.core.worlds.grid_maze import carve_maze

VALUES = np.array([OCCUPIED, UNKNOWN, FREE], np.uint8)


def _reference_distance(grid: np.ndarray, resolution_m: float, clearance_m: float) -> np.ndarray:
    """The original composition: frontier mask, clearance by dilation, multi-source Dijkstra."""
    free = grid == FREE
    frontier = frontier_cell_mask(grid, cell_convention="free")
    if not frontier.any():
        return np.full(grid.shape, np.inf)
    occupied = grid == OCCUPIED
    r = int(math.ceil(clearance_m / resolution_m))
    if occupied.any() and r > 0:
        dr, dc = np.mgrid[-r : r + 1, -r : r + 1]
        disc = np.hypot(dr, dc) * resolution_m < clearance_m - 1e-9
        passable = free & ~ndimage.binary_dilation(occupied, disc)
    else:
        passable = free
    dist, _ = distance_field(
        np.where(passable | frontier, resolution_m, np.inf), np.argwhere(frontier)
    )
    return dist


def _reference_image(
    dist: np.ndarray, geometry: GridGeometry, x_m: float, y_m: float, scale: float
) -> np.ndarray:
    """The original map-frame uint8 layer relative to the robot's cell."""
    row, col = (int(v) for v in geometry.world_to_grid(x_m, y_m))
    if geometry.contains(row, col) and math.isfinite(dist[row, col]):
        d_robot = float(dist[row, col])
    else:
        win = dist[max(0, row - 2) : max(0, row + 3), max(0, col - 2) : max(0, col + 3)]
        finite = win[np.isfinite(win)]
        d_robot = float(finite.min()) if finite.size else 0.0
    with np.errstate(invalid="ignore"):
        rel = 128.0 + scale * (dist - d_robot)
    out = np.full(dist.shape, 255, np.uint8)
    ok = np.isfinite(dist)
    out[ok] = np.clip(np.rint(rel[ok]), 0, 254).astype(np.uint8)
    return out


def _partly_explored_maze(seed: int, cells_per_maze_cell: int = 12) -> np.ndarray:
    """A rasterised maze (2-cell walls) seen only round a few visited points, with speckle."""
    rng = np.random.default_rng(seed)
    n = 6
    h_walls, v_walls = carve_maze(n, n, rng, braid=0.3)
    k = cells_per_maze_cell
    truth = np.full((n * k + 2, n * k + 2), FREE, np.uint8)
    for line, col in zip(*np.nonzero(h_walls), strict=True):
        truth[line * k : line * k + 2, col * k : (col + 1) * k + 2] = OCCUPIED
    for row, line in zip(*np.nonzero(v_walls), strict=True):
        truth[row * k : (row + 1) * k + 2, line * k : line * k + 2] = OCCUPIED
    rr, cc = np.mgrid[: truth.shape[0], : truth.shape[1]]
    seen = np.zeros(truth.shape, bool)
    for _ in range(int(rng.integers(1, 5))):
        r0, c0 = rng.integers(0, truth.shape[0], 2)
        seen |= np.hypot(rr - r0, cc - c0) < rng.uniform(8, 40)
    grid = np.where(seen, truth, UNKNOWN).astype(np.uint8)
    # Scan artefacts: isolated unknown holes and phantom obstacles inside the seen part.
    speckle = rng.random(grid.shape)
    grid[seen & (speckle < 0.01)] = UNKNOWN
    grid[seen & (speckle > 0.995)] = OCCUPIED
    return grid


@pytest.mark.parametrize(
    ("resolution_m", "clearance_m"),
    [(0.05, 0.1), (0.05, 0.12), (0.05, 0.0), (0.1, 0.1), (0.025, 0.1), (0.05, 1e-12)],
)
def test_kernel_equals_reference_on_explored_mazes(resolution_m: float, clearance_m: float) -> None:
    for seed in range(6):
        grid = _partly_explored_maze(seed)
        expected = _reference_distance(grid, resolution_m, clearance_m)
        got = frontier_distance_m(grid, resolution_m, clearance_m)
        assert got.dtype == np.float64 and got.shape == grid.shape
        assert np.isfinite(expected).any()  # the case is not trivial
        np.testing.assert_array_equal(got, expected)  # bit for bit, inf included


def test_kernel_equals_reference_on_random_grids() -> None:
    rng = np.random.default_rng(7)
    for _ in range(200):
        h, w = (int(v) for v in rng.integers(1, 30, 2))
        grid = rng.choice(VALUES, size=(h, w), p=rng.dirichlet([1.0, 1.0, 2.0]))
        res = float(rng.choice([0.025, 0.05, 0.1, 0.3]))
        clearance = float(rng.choice([0.0, 0.05, 0.1, 0.15, 0.3]))
        np.testing.assert_array_equal(
            frontier_distance_m(grid, res, clearance), _reference_distance(grid, res, clearance)
        )


def test_kernel_edge_cases() -> None:
    # No frontier at all (everything known, or nothing free): all unreachable.
    closed = parse_ascii_grid("#####\n#...#\n#####")
    assert np.isinf(frontier_distance_m(closed, 0.1, 0.0)).all()
    assert np.isinf(frontier_distance_m(np.full((4, 5), UNKNOWN, np.uint8), 0.1, 0.1)).all()
    # Frontier cells on every map edge: the grid border is neither unknown nor a wall.
    edges = parse_ascii_grid(
        """
        ?..?
        ....
        ....
        ?..?
        """
    )
    np.testing.assert_array_equal(
        frontier_distance_m(edges, 0.1, 0.1), _reference_distance(edges, 0.1, 0.1)
    )
    # A one-row map and a one-cell map.
    row = np.array([[FREE, FREE, UNKNOWN, FREE]], np.uint8)
    np.testing.assert_allclose(frontier_distance_m(row, 0.1, 0.0)[0], [0.1, 0.0, np.inf, 0.0])
    assert np.isinf(frontier_distance_m(np.array([[FREE]], np.uint8), 0.1, 0.0)).all()
    # Diagonal steps may not cut a wall corner: frontier (1, 1) (unknown above it on the map
    # edge) reaches (2, 2) only through (2, 1), in two side steps, never in one diagonal.
    corner = np.full((5, 5), OCCUPIED, np.uint8)
    corner[0, 1] = UNKNOWN
    corner[1, 1] = corner[2, 1:4] = corner[3, 2:4] = FREE
    d = frontier_distance_m(corner, 1.0, 0.0)
    assert d[1, 1] == 0.0 and d[2, 1] == 1.0 and d[2, 2] == 2.0 and d[2, 3] == 3.0
    corner[2, 1] = OCCUPIED  # both sides of the diagonal walled: (2, 2) is cut off
    assert np.isinf(frontier_distance_m(corner, 1.0, 0.0)[2:4, 2:4]).all()


def _edit(grid: np.ndarray, rng: np.random.Generator, truth: np.ndarray) -> None:
    """Change ``grid`` in place the way mapping does, and the ways it should not."""
    h, w = grid.shape
    kind = rng.integers(0, 4)
    r0, c0 = int(rng.integers(0, h)), int(rng.integers(0, w))
    rad = int(rng.integers(0, 12))
    rr, cc = np.mgrid[:h, :w]
    disc = np.hypot(rr - r0, cc - c0) <= rad
    if kind == 0:  # a scan: reveal the truth round a point
        grid[disc] = truth[disc]
    elif kind == 1:  # a few cells, any value (phantom walls, forgotten cells, new frontiers)
        for _ in range(int(rng.integers(1, 6))):
            r, c = int(rng.integers(0, h)), int(rng.integers(0, w))
            grid[r, c] = rng.choice(VALUES)
    elif kind == 2:  # a patch falls back to unknown
        grid[disc & (rng.random((h, w)) < 0.5)] = UNKNOWN
    else:  # a wall segment appears
        grid[r0, max(0, c0 - rad) : c0 + rad + 1] = OCCUPIED


@pytest.mark.parametrize("clearance_m", [0.1, 0.0, 0.15])
def test_incremental_field_equals_a_fresh_search(clearance_m: float) -> None:
    """Repairing after each edit gives the field of a search from scratch, bit for bit."""
    rng = np.random.default_rng(11)
    for seed in range(3):
        truth = _partly_explored_maze(seed + 20)
        truth[truth == UNKNOWN] = FREE
        grid = _partly_explored_maze(seed + 20)
        field = FrontierDistanceField(grid.shape, 0.05, clearance_m)
        assert field.update(grid) and not field.update(grid.copy())  # unchanged: skipped
        for _ in range(60):
            _edit(grid, rng, truth)
            field.update(grid)
            np.testing.assert_array_equal(
                field.distance_m(), frontier_distance_m(grid, 0.05, clearance_m)
            )
        # A whole new map (searched afresh rather than repaired).
        grid = _partly_explored_maze(seed + 40)
        field.update(grid)
        np.testing.assert_array_equal(
            field.distance_m(), frontier_distance_m(grid, 0.05, clearance_m)
        )
        # A bad value raises and the next valid map is searched afresh.
        bad = grid.copy()
        bad[0, 0] = 7
        with pytest.raises(ValueError, match="value 7"):
            field.update(bad)
        field.update(grid)
        np.testing.assert_array_equal(
            field.distance_m(), frontier_distance_m(grid, 0.05, clearance_m)
        )


def test_kernel_rejects_bad_grids() -> None:
    with pytest.raises(ValueError, match="value 7"):
        frontier_distance_m(np.array([[FREE, 7]], np.uint8), 0.1, 0.1)
    with pytest.raises(TypeError, match="uint8"):
        frontier_distance_m(np.zeros((3, 3), np.int32), 0.1, 0.1)
    with pytest.raises(ValueError, match="2-D"):
        frontier_distance_m(np.zeros(3, np.uint8), 0.1, 0.1)
    with pytest.raises(ValueError, match="resolution_m"):
        frontier_distance_m(np.zeros((3, 3), np.uint8), 0.0, 0.1)
    with pytest.raises(ValueError, match="clearance_m"):
        frontier_distance_m(np.zeros((3, 3), np.uint8), 0.1, -1.0)


def test_relative_image_equals_reference() -> None:
    """Robot on a reachable cell, beside a wall, in unknown space and outside the map."""
    # 0.025 m cells at 20 levels/m put exact half levels on the map: rounding must agree too.
    for resolution_m in (0.05, 0.025):
        grid = _partly_explored_maze(3)
        geometry = GridGeometry(resolution_m, -0.5, -0.5, *grid.shape)
        dist = frontier_distance_m(grid, resolution_m, 0.1)
        rng = np.random.default_rng(1)
        rows = [*rng.integers(0, grid.shape[0], 40), -1, -3, grid.shape[0], grid.shape[0] + 4]
        cols = [*rng.integers(0, grid.shape[1], 40), 0, -2, grid.shape[1] + 1, 3]
        kinds = set()
        for row, col in zip(rows, cols, strict=True):
            x_m, y_m = geometry.grid_to_world(row, col)
            inside = geometry.contains(row, col)
            kinds.add("outside" if not inside else int(grid[row, col]))
            expected = _reference_image(dist, geometry, float(x_m), float(y_m), 20.0)
            got = relative_distance_image(dist, int(row), int(col), 20.0)
            np.testing.assert_array_equal(got, expected)
        assert {"outside", UNKNOWN, FREE, OCCUPIED} <= kinds


def test_encoder_channel_uses_the_kernel() -> None:
    grid = _partly_explored_maze(2)
    geometry = GridGeometry(0.05, 0.0, 0.0, *grid.shape)
    info = {"map_geometry": geometry.to_dict(), "lidar": {"max_range_m": 3.5, "n_beams": 360}}
    params = EgocentricParams(crop_cells=32, channels=("frontier_distance",))
    enc = EgocentricEncoder.from_info(params, info)
    x_m, y_m = 1.23, 2.34
    layer = enc.frontier_distance_image(grid, x_m, y_m)
    expected = _reference_image(
        _reference_distance(grid, 0.05, params.frontier_clearance_m), geometry, x_m, y_m, 20.0
    )
    np.testing.assert_array_equal(layer, expected)
