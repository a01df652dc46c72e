"""The branch bound (core/coverage_tour/branch_bound.py): its tree knapsack against brute force,
its merge tree, its visibility superset, and the bound on hand-made worlds (never above a
feasible drive; above the route bound where a world is a tree of many dead ends)."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from semexplore_gym.core.coverage_tour import LowerBoundParams, lower_bound
from semexplore_gym.core.coverage_tour.bound_geometry import group_parents
from semexplore_gym.core.coverage_tour.branch_kernels import (
    branch_route,
    coarse_region,
    coarse_region_among,
    merge_tree,
    preorder,
    region_extremes,
    set_levels,
)
from semexplore_gym.core.coverage_tour.lower_bound import (
    mask_groups,
)
from semexplore_gym.core.grid import GridGeometry
from semexplore_gym.core.worlds.build import world_from_free_mask

RES = 0.05
RANGE_M = 1.0


def _facts(privileged_world, rects, size_m, start):
    """The privileged facts of a world whose free space is ``rects`` (a 1 m LiDAR)."""
    h, w = int(round(size_m[1] / RES)), int(round(size_m[0] / RES))
    free = np.zeros((h, w), dtype=bool)
    for x0, y0, x1, y1 in rects:
        rows = slice(int(round(y0 / RES)), int(round(y1 / RES)))
        free[rows, int(round(x0 / RES)) : int(round(x1 / RES))] = True
    world = world_from_free_mask("test", free, GridGeometry(RES, 0.0, 0.0, h, w), start_pose=start)
    return privileged_world(world, start, 0.105, RANGE_M, RES)


def _brute_force(parent, edge, weight, budget, leaf_m=0.0):
    """The least drive over every parent-closed node set holding the root, by enumeration, less
    ``leaf_m`` for each of its leaves but one."""
    m = parent.size
    root = m - 1
    best = np.inf
    for bits in itertools.product((False, True), repeat=m - 1):
        inside = np.array([*bits, True])
        if any(inside[v] and not inside[parent[v]] for v in range(m)):
            continue
        skipped = sum(weight[v] for v in range(m) if not inside[v] and inside[parent[v]])
        if skipped > budget:
            continue
        depth = np.zeros(m)
        for v in range(m - 1, -1, -1):
            depth[v] = edge[v] + (depth[parent[v]] if v != root else 0.0)
        drive = 2 * edge[inside].sum() - max(depth[v] for v in range(m) if inside[v])
        has_child = np.zeros(m, dtype=bool)
        has_child[parent[:-1][inside[:-1]]] = True
        leaves = int(np.sum(inside[:-1] & ~has_child[:-1]))
        best = min(best, drive - leaf_m * max(leaves - 1, 0))
    return best


@pytest.mark.parametrize("leaf_m", [0.0, 0.7])
@pytest.mark.parametrize("seed", range(12))
def test_the_tree_knapsack_equals_brute_force(seed, leaf_m):
    rng = np.random.default_rng(seed)
    m = int(rng.integers(2, 9))
    parent = np.array([int(rng.integers(v + 1, m)) for v in range(m - 1)] + [m - 1])
    edge = np.append(rng.uniform(0.1, 3.0, m - 1), 0.0)
    own = rng.integers(0, 6, m)
    weight = own.copy()
    for v in range(m - 1):  # a subtree's weight: its own and its children's
        weight[parent[v]] += weight[v]
    budget = int(rng.integers(0, 8))
    got = branch_route(parent, edge, weight.astype(np.int64), budget, leaf_m)
    assert got == pytest.approx(_brute_force(parent, edge, weight, budget, leaf_m))


def _line_moves(n):
    """Move bits of a 1 x n row of cells, each passing to its left and right neighbour."""
    moves = np.full((1, n), 1 << 4, dtype=np.uint16)
    moves[0, 1:] |= np.uint16(1 << 3)  # (0, -1)
    moves[0, :-1] |= np.uint16(1 << 5)  # (0, +1)
    return moves


def test_the_merge_tree_joins_two_arms_at_the_level_of_their_meeting_cell():
    # A row of 7 cells, the start in the middle: two arms whose levels rise away from it.
    phi = np.array([3.0, 2.0, 1.0, 0.0, 1.5, 2.5, 3.5])
    cells, node_of, parent, level = merge_tree(_line_moves(7), phi)
    assert cells.size == 7 and int(np.sum(parent == np.arange(parent.size))) == 1
    sets = [[0, 1], [0, 6], [5, 6], [2]]
    flat = np.array([node_of[c] for s in sets for c in s], dtype=np.int64)
    starts = np.cumsum([0] + [len(s) for s in sets]).astype(np.int64)
    _, levels = set_levels(parent, level, flat, starts)
    # The same arm: one branch until the lower cell's level; the two arms: only at the start.
    assert levels.tolist() == [2.0, 0.0, 2.5, 1.0]


def test_a_row_split_by_an_unreachable_cell_makes_two_trees():
    phi = np.array([0.0, 1.0, np.inf, 1.0])
    moves = _line_moves(4)
    _, node_of, parent, level = merge_tree(moves, phi)
    assert node_of[2] == -1 and int(np.sum(parent == np.arange(parent.size))) == 2
    flat = np.array([node_of[0], node_of[3]], dtype=np.int64)
    lca, levels = set_levels(parent, level, flat, np.array([0, 2], dtype=np.int64))
    assert lca[0] == -1 and levels[0] == -np.inf


def _ancestors(parent, v):
    out = [v]
    while parent[out[-1]] != out[-1]:
        out.append(int(parent[out[-1]]))
    return out


def test_common_branches_of_random_sets_are_the_brute_force_ones():
    """Random levels on a 12 x 12 grid with two unreachable walls (a forest of merge trees):
    each set's common ancestor (from its first and last leaf in preorder) is the deepest node
    on every leaf's path to its root, or none when the leaves lie in different trees."""
    rng = np.random.default_rng(7)
    n = 12
    moves = np.full((n, n), 1 << 4, dtype=np.uint16)
    for dr, dc in itertools.product((-1, 0, 1), repeat=2):
        if (dr, dc) != (0, 0):
            moves |= np.uint16(1 << (3 * (dr + 1) + dc + 1))
    phi = rng.random(n * n)
    phi[5 * n : 6 * n] = np.inf  # a row nothing passes: two trees
    _, node_of, parent, level = merge_tree(moves, phi)
    tin, size = preorder(parent)
    assert sorted(tin.tolist()) == list(range(parent.size))
    cells = np.flatnonzero(node_of >= 0)
    sets = [rng.choice(cells, size=k, replace=False) for k in (1, 2, 3, 5, 9, 20) * 5]
    flat = np.concatenate([node_of[c] for c in sets]).astype(np.int64)
    starts = np.cumsum([0] + [len(c) for c in sets]).astype(np.int64)
    lca, levels = set_levels(parent, level, flat, starts)
    split = 0
    for g, c in enumerate(sets):
        paths = [_ancestors(parent, int(node_of[x])) for x in c]
        common = set(paths[0]).intersection(*paths[1:])
        if not common:
            split += 1
            assert lca[g] == -1 and levels[g] == -np.inf
            continue
        deepest = next(v for v in paths[0] if v in common)
        assert lca[g] == deepest and levels[g] == level[deepest]
        for v in paths[0]:  # the preorder numbers an ancestor's subtree as one range
            assert tin[v] <= tin[int(node_of[c[0]])] < tin[v] + size[v]
    assert 0 < split < len(sets)


def test_a_regions_blocks_give_its_cells_count_and_preorder_ends():
    """Blocks of 2 x 2 cells of a 4 x 6 grid: the count holds only allowed cells, a cell
    outside the tree marks the region, and the ends are its first and last tree node."""
    allowed = np.ones((4, 6), dtype=bool)
    allowed[0, 0] = False
    node_of = np.arange(24, dtype=np.int64)
    node_of[23] = -1  # (3, 5): not in the tree
    tin = np.arange(24, dtype=np.int64)[::-1].copy()  # preorder: the reverse of the cell order
    blocks = np.array([0, 2, 5], dtype=np.int64)  # (0,0), (0,4) | (1,4) in a 3-block-wide grid
    count, bad, ends = region_extremes(blocks, np.array([0, 2, 3]), 2, allowed, node_of, tin)
    assert count.tolist() == [7, 4]  # 3 of block (0,0) + 4 of block (0,4); block (1,4)
    assert bad.tolist() == [False, True]
    assert ends.tolist() == [11, 1, 22, 16]  # cell (0, 0) is not allowed


@pytest.mark.parametrize("spec", ["maze:seed=1,size_m=5", "office:seed=2,size_m=10"])
def test_a_distance_cells_region_holds_every_distance_cell_of_the_map_cell_region(
    spec, bound_problem
):
    """The branch bound tests distance cells, not map cells: it must keep every one that holds
    a map cell of the route bound's (proven) region, so the same visibility proof carries."""
    facts, allowed, prob = bound_problem(spec, 3, 2, 8)
    geo = facts.geometry
    frame = np.array(
        [geo.origin_x_m, geo.origin_y_m, geo.resolution_m, prob.reach_m, 1e-6, 1e-6, 3, 10**6]
    )
    rects, _, _ = mask_groups(facts.reachable_mask, geo, 8)
    grew = 0
    for g in range(0, rects.shape[0], 5):
        proven = set(prob.region(rects[g]).tolist())
        ours = set(coarse_region(allowed, 2, rects[g], prob.walls, frame, prob.corners).tolist())
        assert proven <= ours
        grew += len(ours - proven)
        # Past the wall cap, every block within reach is in, untested: a superset again.
        capped = frame.copy()
        capped[7] = 0
        assert ours <= set(
            coarse_region(allowed, 2, rects[g], prob.walls, capped, prob.corners).tolist()
        )
    # A distance cell's box is at most a map cell wider than its map cells: few extra cells.
    assert grew <= 0.05 * sum(prob.region(rects[g]).size for g in range(0, rects.shape[0], 5))


@pytest.mark.parametrize("spec", ["maze:seed=1,size_m=5", "office:seed=2,size_m=10"])
def test_a_region_sought_within_its_larger_groups_region_is_the_meet_of_both(spec, bound_problem):
    """``branch_nested``: a group's region tested only among the blocks of the region of the
    block of twice the side that holds it. Every segment to the group is one to the larger
    group, so both regions are supersets of what sees the group, and so is their meet: the
    nested search must give exactly the meet (no block lost to the order of the tests)."""
    facts, allowed, prob = bound_problem(spec, 3, 2, 8)
    geo, mask = facts.geometry, facts.reachable_mask
    frame = np.array(
        [geo.origin_x_m, geo.origin_y_m, geo.resolution_m, prob.reach_m, 1e-6, 1e-6, 3, 10**6]
    )
    rects, _, _ = mask_groups(mask, geo, 4)
    outer_rects, _, _ = mask_groups(mask, geo, 8)
    parent = group_parents(mask, 4)
    assert parent.shape == (rects.shape[0],) and np.unique(parent).size == outer_rects.shape[0]
    # each group's mask cells lie in its parent's
    inside = (rects[:, :2] >= outer_rects[parent, :2]) & (rects[:, 2:] <= outer_rects[parent, 2:])
    assert inside.all()
    every = np.arange(prob.coarse.size, dtype=np.int64)
    for g in range(0, rects.shape[0], 7):
        alone = coarse_region(allowed, 2, rects[g], prob.walls, frame, prob.corners)
        outer = coarse_region(allowed, 2, outer_rects[parent[g]], prob.walls, frame, prob.corners)
        nested = coarse_region_among(allowed, 2, rects[g], prob.walls, frame, outer, prob.corners)
        assert np.array_equal(nested, np.intersect1d(alone, outer))
        # among every block of the map, the test is coarse_region's own
        among_all = coarse_region_among(
            allowed, 2, rects[g], prob.walls, frame, every, prob.corners
        )
        assert np.array_equal(among_all, alone)


def _comb(privileged_world, n_teeth):
    """A spine 0.6 m wide with ``n_teeth`` teeth 3 m deep every 2 m, the start at its left end;
    and the drive that covers it: along the spine, into each tooth to the LiDAR's range of its
    end and back, the last one not."""
    teeth = [(2.0 * i, 0.0, 2.0 * i + 0.6, 3.6) for i in range(n_teeth)]
    length = 2.0 * (n_teeth - 1) + 0.6
    facts = _facts(
        privileged_world, [(0.0, 0.0, length, 0.6), *teeth], (length, 3.6), (0.3, 0.3, 0.0)
    )
    depth = 3.3 - RANGE_M
    return facts, length - 0.6 + 2 * depth * n_teeth - depth


def test_on_a_comb_of_many_teeth_the_branch_bound_is_below_a_feasible_drive_and_above_the_route(
    privileged_world,
):
    facts, feasible = _comb(privileged_world, 8)
    b = lower_bound(facts)
    route_only = lower_bound(facts, LowerBoundParams(branch_block_m=0.0))
    assert route_only.branch_m == 0.0
    assert b.branch_m <= feasible and b.distance_m <= feasible
    assert b.branch_m > route_only.distance_m
    assert b.distance_m == max(b.branch_m, route_only.distance_m)
    # Every tooth is driven into and out of (the last not): about half the drive even with the
    # K-hop metric's and the groups' slack; one tooth's worth of it is no longer enough.
    assert b.branch_m >= 0.45 * feasible


def test_on_a_ring_the_branch_bound_stays_below_driving_round_once(privileged_world):
    rects = [(0.0, 0.0, 5.2, 0.6), (0.0, 4.6, 5.2, 5.2), (0.0, 0.0, 0.6, 5.2), (4.6, 0.0, 5.2, 5.2)]
    facts = _facts(privileged_world, rects, (5.2, 5.2), (2.6, 0.3, 0.0))
    b = lower_bound(facts)
    assert 0.0 < b.branch_m <= 4 * 4.6 - 2 * RANGE_M


def test_a_bad_branch_block_is_one_clear_error():
    with pytest.raises(ValueError, match="branch_block_m"):
        LowerBoundParams(branch_block_m=-0.1)
    with pytest.raises(ValueError, match="branch_nested must be true or false, got 'yes'"):
        LowerBoundParams(branch_nested="yes")


def test_nested_regions_give_a_bound_as_high_and_still_below_a_feasible_drive(privileged_world):
    facts, feasible = _comb(privileged_world, 4)
    alone = lower_bound(facts)
    nested = lower_bound(facts, LowerBoundParams(branch_nested=True))
    assert alone.branch_m <= nested.branch_m <= feasible


def test_phi_jumps_between_touching_cells_by_at_most_a_cells_diagonal(bound_problem):
    """Step 2's splice: two cells that touch are a drive of length 0 apart, yet their K-hop
    distances differ (each hop is measured to a cell's near side). The branch bound allows
    sqrt(2) h per splice; more than that would break it, and none at all would be unsound."""
    facts, allowed, prob = bound_problem("maze:seed=1,size_m=5", 3, 1, 8)
    geo = facts.geometry
    row, col = (int(v) for v in geo.world_to_grid(*facts.start_pose[:2]))
    phi = prob.distances(np.array([row * geo.width + col])).reshape(allowed.shape)
    h = geo.resolution_m
    height, width = phi.shape
    worst = 0.0
    for dr, dc in ((0, 1), (1, 0), (1, 1), (1, -1)):  # each touching pair once
        a = phi[: height - dr, max(0, -dc) : width - max(0, dc)]
        b = phi[dr:, max(0, dc) : width + min(0, dc)]
        both = np.isfinite(a) & np.isfinite(b)
        worst = max(worst, float(np.max(np.abs(a[both] - b[both]))))
    assert 0.5 * h < worst <= np.sqrt(2.0) * h + 1e-9, worst / h
