"""The grid fallback of the semantic expert: nearest frontier reachable with clearance."""

from __future__ import annotations

import numpy as np
import pytest

from semexplore_gym.core.frontiers.reachable import (
    FrontierFilter,
    clearance_field_m,
    frontier_groups,
    nearest_reachable_frontier,
    pocket_exit_path,
)
from semexplore_gym.core.grid import GridGeometry, parse_ascii_grid

# 0.1 m cells. A room on the left; a wide corridor (5 free cells) to unknown on the right; a
# narrow slot (1 free cell) at the top leading to unknown as well.
MAP = """
##########?????
#........#?????
#........######
#.............?
#.............?
#.............?
#.............?
#.............?
###############
"""


def test_bfs_reaches_the_frontier_through_the_wide_corridor_only():
    grid = parse_ascii_grid(MAP)
    geom = GridGeometry(0.1, 0.0, 0.0, *grid.shape)
    f = nearest_reachable_frontier(
        grid, geom, (0.25, 0.35), clearance_m=0.2, frontiers=FrontierFilter(reach_m=0.0)
    )
    assert f is not None
    # The goal is a frontier cell of the corridor's open end (column 13), usable (>= 0.2 m from walls).
    row, col = geom.world_to_grid(*f.goal_xy_m)
    assert int(col) == 13 and 2 <= int(row) <= 4
    assert f.n_frontier_cells == 5
    np.testing.assert_allclose(f.path_m[0], (0.25, 0.35))
    assert f.path_length_m >= 13 * 0.1 - 0.35
    # Every cell of the path keeps the clearance.
    dist = clearance_field_m(grid, 0.1)
    r, c = geom.world_to_grid(f.path_m[1:, 0], f.path_m[1:, 1])
    assert (dist[r, c] >= 0.2 - 1e-9).all()


SLOT = """
???????????
#####.#####
#.........#
#.........#
#.........#
#.........#
#.........#
###########
"""


def test_frontier_behind_a_narrow_slot_is_reachable_only_within_reach():
    grid = parse_ascii_grid(SLOT)
    geom = GridGeometry(0.1, 0.0, 0.0, *grid.shape)
    labels, n = frontier_groups(grid, 1)
    assert n == 1 and labels[6, 5] > 0 and labels.astype(bool).sum() == 1
    # The slot cell itself is 0.1 m from the walls: the robot cannot stand in it.
    assert (
        nearest_reachable_frontier(
            grid, geom, (0.55, 0.35), clearance_m=0.2, frontiers=FrontierFilter(1, reach_m=0.0)
        )
        is None
    )
    # It can get within 0.3 m of it (row 3, the first such cell on its way), close enough to
    # look through.
    f = nearest_reachable_frontier(
        grid, geom, (0.55, 0.35), clearance_m=0.2, frontiers=FrontierFilter(1, reach_m=0.3)
    )
    assert f is not None
    assert tuple(int(v) for v in geom.world_to_grid(*f.goal_xy_m)) == (3, 5)
    # Excluding it (the blacklist) leaves nothing.
    assert (
        nearest_reachable_frontier(
            grid, geom, (0.55, 0.35), 0.2, FrontierFilter(1, 0.3, excluded_xy_m=[(0.55, 0.7)])
        )
        is None
    )


def test_small_groups_are_ignored_and_reach_extends_the_goal():
    grid = parse_ascii_grid(MAP)
    geom = GridGeometry(0.1, 0.0, 0.0, *grid.shape)
    assert nearest_reachable_frontier(grid, geom, (0.25, 0.35), 0.2, FrontierFilter(6)) is None
    near = nearest_reachable_frontier(grid, geom, (0.25, 0.35), 0.2, FrontierFilter(reach_m=0.5))
    far = nearest_reachable_frontier(grid, geom, (0.25, 0.35), 0.2, FrontierFilter(reach_m=0.0))
    assert near is not None and far is not None
    assert near.path_length_m < far.path_length_m - 0.3


def test_start_next_to_a_wall_and_validation():
    grid = parse_ascii_grid(MAP)
    geom = GridGeometry(0.1, 0.0, 0.0, *grid.shape)
    f = nearest_reachable_frontier(grid, geom, (0.15, 0.15), clearance_m=0.2)
    assert f is not None
    with pytest.raises(ValueError, match="clearance_m"):
        nearest_reachable_frontier(grid, geom, (0.25, 0.35), clearance_m=-0.1)
    with pytest.raises(ValueError, match="shape"):
        nearest_reachable_frontier(grid, GridGeometry(0.1, 0.0, 0.0, 3, 3), (0.25, 0.35), 0.2)


POCKET = """
##############
#............#
#............#
#..###.###...#
#..#?????#...#
#..#######...#
#............#
##############
"""


def test_thin_unknown_pockets_can_be_ignored():
    grid = parse_ascii_grid(POCKET)
    geom = GridGeometry(0.1, 0.0, 0.0, *grid.shape)
    # The only frontier cell is the gap in the pocket's top wall; the pocket is one cell thick.
    labels, n = frontier_groups(grid, 1)
    assert n == 1 and labels[4, 6] > 0
    assert frontier_groups(grid, 1, min_unknown_depth_cells=1.0)[1] == 1
    assert frontier_groups(grid, 1, min_unknown_depth_cells=1.5)[1] == 0
    # Unknown space running off the grid's edge is deep.
    edge = grid.copy()
    edge[3, 0] = 128
    labels, n = frontier_groups(edge, 1, min_unknown_depth_cells=4.0)
    assert n == 1 and labels[3, 1] > 0
    assert (
        nearest_reachable_frontier(
            grid, geom, (0.25, 0.25), 0.05, FrontierFilter(1, 0.2, min_unknown_depth_cells=2.0)
        )
        is None
    )
    assert (
        nearest_reachable_frontier(grid, geom, (0.25, 0.25), 0.05, FrontierFilter(1, 0.2))
        is not None
    )


# 0.1 m cells: a 3 x 3 nook whose only way out is a one-cell slot into the room on the right.
NOOK = """
###########
#...#.....#
#.........#
#...#.....#
###########
"""


def test_pocket_exit_path_leads_out_of_a_pocket_only():
    grid = parse_ascii_grid(NOOK)
    geom = GridGeometry(0.1, 0.0, 0.0, *grid.shape)
    # With 0.12 m only cells without a wall beside them are usable, and the slot (walls above
    # and below) is not: the nook keeps 2 of the 6 usable cells, the room 4 (its middle row).
    path = pocket_exit_path(grid, geom, (0.25, 0.25), 0.12, 0.1, 0.5)
    assert path is not None
    np.testing.assert_allclose(path[0], (0.25, 0.25))
    np.testing.assert_allclose(path[-1], (0.55, 0.25))  # the room's nearest usable cell
    assert pocket_exit_path(grid, geom, (0.75, 0.25), 0.12, 0.1, 0.5) is None  # not a pocket
    assert pocket_exit_path(grid, geom, (0.25, 0.25), 0.12, 0.1, 0.3) is None  # 1/3 >= 0.3
    # No way out over cells as clear as the pocket's own: the slot needs the thinner clearance.
    assert pocket_exit_path(grid, geom, (0.25, 0.25), 0.12, 0.12, 0.5) is None
    # No usable cell within 0.5 m of the start counts as a pocket of its own.
    far = pocket_exit_path(grid, geom, (0.15, 0.15), 0.12, 0.0, 0.5)
    assert far is not None and far[-1][0] > 0.5
    with pytest.raises(ValueError, match="exit_clearance_m"):
        pocket_exit_path(grid, geom, (0.25, 0.25), 0.12, 0.2, 0.5)
    with pytest.raises(ValueError, match="max_share"):
        pocket_exit_path(grid, geom, (0.25, 0.25), 0.12, 0.1, 1.5)
    with pytest.raises(ValueError, match="shape"):
        pocket_exit_path(grid[:, :5], geom, (0.25, 0.25), 0.12, 0.1, 0.5)


def test_step_cost_is_the_numpy_expression_bit_for_bit() -> None:
    from semexplore_gym.core.frontiers.reachable import step_cost_field

    rng = np.random.default_rng(0)
    for k in range(60):
        h, w = (int(v) for v in rng.integers(1, 80, size=2))
        dist = rng.random((h, w)) * float(rng.choice([0.3, 3.0]))
        dist[rng.random((h, w)) < 0.05] = np.inf
        if k % 2:
            dist = np.round(dist * 20) / 20  # on the grid's 5 cm steps: ties at the clip ends
        usable = rng.random((h, w)) < 0.7
        clearance_m, wall_cost, extra_m = (
            float(rng.choice(v)) for v in ([0, 0.155], [0, 4.0], [0, 0.15])
        )
        pref = clearance_m + extra_m
        if pref > 0 and wall_cost > 0:
            want = 1.0 + wall_cost * np.clip(1.0 - np.minimum(dist, 1e9) / pref, 0.0, 1.0)
        else:
            want = np.ones(dist.shape)
        want = np.where(usable, want, np.inf)
        np.testing.assert_array_equal(
            step_cost_field(dist, usable, clearance_m, wall_cost, extra_m), want
        )


def test_frontier_groups_depth_check_is_the_distance_transform_definition():
    """The unknown-depth check (run at every replan, through a compiled transform) keeps
    exactly the groups that scipy's Euclidean distance transform keeps, on random maps."""
    import math

    from scipy import ndimage

    from semexplore_gym.core.frontiers.detection import frontier_cell_mask
    from semexplore_gym.core.grid import FREE, OCCUPIED, UNKNOWN

    def reference(grid, depth):
        cells = frontier_cell_mask(grid, cell_convention="free")
        labels, n = ndimage.label(cells, structure=np.ones((3, 3), dtype=bool))
        pad = int(math.ceil(depth)) + 2
        deep = ndimage.distance_transform_edt(np.pad(grid == UNKNOWN, pad, constant_values=True))
        deep = deep >= depth
        near = (ndimage.distance_transform_edt(~deep) <= depth + 2.0)[pad:-pad, pad:-pad]
        return {int(v) for v in np.unique(labels[cells & near]) if v > 0}, labels

    rng = np.random.default_rng(7)
    for _ in range(60):
        h, w = (int(v) for v in rng.integers(6, 40, 2))
        coarse = rng.choice([FREE, OCCUPIED, UNKNOWN], size=(h, w), p=[0.5, 0.2, 0.3])
        grid = np.kron(coarse, np.ones((3, 3), dtype=np.uint8)).astype(np.uint8)
        depth = float(rng.choice([1.0, 2.5, 4.0]))
        kept_ref, ref_labels = reference(grid, depth)
        labels, n = frontier_groups(grid, 1, min_unknown_depth_cells=depth)
        assert n == len(kept_ref)
        assert {int(v) for v in np.unique(ref_labels[labels > 0])} == kept_ref


def _known_patch_maps(rng: np.random.Generator, n: int, min_free: int):
    """Up to ``n`` random maps, each with its frame and its FREE cells (those with fewer than
    ``min_free`` are skipped): a patch of 4-cell blocks (free, wall, unknown) in a wide
    unknown border."""
    from semexplore_gym.core.grid import FREE, OCCUPIED, UNKNOWN

    for _ in range(n):
        h, w = (int(v) for v in rng.integers(60, 140, 2))
        grid = np.full((h, w), UNKNOWN, dtype=np.uint8)
        r0, c0 = (int(v) for v in rng.integers(0, 20, 2))
        rh, rw = int(rng.integers(20, h - r0)), int(rng.integers(20, w - c0))
        coarse = rng.choice([FREE, OCCUPIED, UNKNOWN], size=(rh // 4, rw // 4), p=[0.7, 0.1, 0.2])
        block = np.kron(coarse, np.ones((4, 4), dtype=np.uint8))
        grid[r0 : r0 + block.shape[0], c0 : c0 + block.shape[1]] = block
        free = np.argwhere(grid == FREE)
        if len(free) >= min_free:
            yield grid, GridGeometry(0.05, -1.0, 2.0, h, w), free


def _windowed_and_whole(monkeypatch, run_all, at_least: int) -> list[tuple]:
    """``run_all()``'s results within the known window and (patched) on the whole grid, in
    pairs; both found or both not, and at least ``at_least`` found."""
    from semexplore_gym.core.frontiers import reachable

    windowed = run_all()
    monkeypatch.setattr(reachable, "known_window", lambda g, *_: (0, g.shape[0], 0, g.shape[1]))
    whole = run_all()
    assert sum(r is not None for r in whole) >= at_least
    pairs = list(zip(windowed, whole, strict=True))
    assert all((a is None) == (b is None) for a, b in pairs)
    return pairs


def test_the_search_within_the_known_window_is_the_search_on_the_whole_grid(monkeypatch):
    """The nearest reachable frontier is found within the window of the known cells (a large
    map is mostly unknown); on random maps it is the very result of the whole grid's search."""
    from semexplore_gym.core.grid import UNKNOWN

    rng = np.random.default_rng(11)
    cases = []
    for grid, geom, free in _known_patch_maps(rng, 40, min_free=1):
        r, c = free[int(rng.integers(len(free)))]
        xs, ys = geom.grid_to_world(r, c)
        start = (float(xs) + 0.01, float(ys) - 0.01)
        filt = FrontierFilter(
            int(rng.integers(1, 5)),
            reach_m=float(rng.choice([0.0, 0.1, 0.3])),
            min_unknown_depth_cells=float(rng.choice([0.0, 4.0])),
            excluded_xy_m=[start] if rng.random() < 0.3 else [],
        )
        cases.append((grid, geom, start, filt))

    def run_all():
        out = []
        for grid, geom, start, filt in cases:
            out.append(nearest_reachable_frontier(grid, geom, start, 0.1, filt))
        return out

    unseen = np.full((30, 30), UNKNOWN, dtype=np.uint8)
    off_grid = GridGeometry(0.05, 0.0, 0.0, 30, 30)
    assert nearest_reachable_frontier(unseen, off_grid, (9.0, 0.5), 0.1, FrontierFilter(1)) is None
    for a, b in _windowed_and_whole(monkeypatch, run_all, at_least=20):
        if a is not None:
            assert a.goal_xy_m == b.goal_xy_m and a.frontier_xy_m == b.frontier_xy_m
            assert a.path_length_m == b.path_length_m and a.n_frontier_cells == b.n_frontier_cells
            np.testing.assert_array_equal(a.path_m, b.path_m)


def test_a_route_within_the_known_window_is_the_route_on_the_whole_grid(monkeypatch):
    """``grid_path_to`` searches within the window of the known cells too: on random maps, to
    random goals (known, unknown, off the map), the very path of the whole grid's search."""
    from semexplore_gym.core.frontiers.reachable import clearance_field_m, grid_path_to

    rng = np.random.default_rng(12)
    cases = []
    for grid, geom, free in _known_patch_maps(rng, 40, min_free=2):
        h, w = grid.shape
        (r, c), (gr, gc) = free[rng.integers(len(free), size=2)]
        start = tuple(float(v) + 0.01 for v in geom.grid_to_world(r, c))
        goal = tuple(float(v) for v in geom.grid_to_world(gr, gc))
        if rng.random() < 0.2:  # anywhere, on the map or off it
            goal = (float(rng.uniform(-2.0, w * 0.05)), float(rng.uniform(1.0, 3.0 + h * 0.05)))
        field = clearance_field_m(grid, 0.05) if rng.random() < 0.5 else None
        cases.append((grid, geom, start, goal, float(rng.choice([0.15, 0.3])), field))

    def run_all():
        return [grid_path_to(g, geo, s, t, 0.1, rad, f) for g, geo, s, t, rad, f in cases]

    for a, b in _windowed_and_whole(monkeypatch, run_all, at_least=15):
        if a is not None:
            np.testing.assert_array_equal(a, b)


def test_near_marked_is_the_thresholded_distance_transform():
    """The depth check's disc test at a few cells answers what scipy's distance transform to the
    marked cells, thresholded, answers there (limits on and off the integer distances)."""
    from scipy import ndimage

    from semexplore_gym.core.frontiers.reachable_kernels import near_marked

    rng = np.random.default_rng(5)
    for _ in range(40):
        h, w = (int(v) for v in rng.integers(5, 50, 2))
        mask = rng.random((h, w)) < float(rng.choice([0.0, 0.01, 0.05, 0.3]))
        limit = float(rng.choice([1.0, 2.0, 3.5, 6.0, 2.0**0.5, 5.0**0.5]))
        rows, cols = (v.astype(np.int64) for v in np.nonzero(rng.random((h, w)) < 0.3))
        want = (
            (ndimage.distance_transform_edt(~mask) <= limit)[rows, cols]
            if mask.any()
            else (np.zeros(len(rows), dtype=bool))
        )
        np.testing.assert_array_equal(near_marked(mask, rows, cols, limit), want)
