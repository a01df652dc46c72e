"""Groups grown from small blocks for the route bound: a partition of the blocks, each group's
region the union of its blocks', grown by the least widening while it stays under the growth
share; and on a loop with rooms a higher route than the lattice's, still below a real tour."""

from __future__ import annotations

import numpy as np
import pytest

from semexplore_gym.core.coverage_tour import LowerBoundParams, lower_bound, plan_coverage_tour
from semexplore_gym.core.coverage_tour.grown_groups import (
    block_neighbours,
    group_region,
    grow_groups,
)
from tests.core.coverage_tour.test_lower_bound import _facts


def _grown(nb, cells, regions, n_cells, target, growth):
    """The partition and every group's region."""
    group_of = grow_groups(nb, cells, regions, n_cells, target, growth)[0]
    n = int(group_of.max()) + 1
    return group_of, [group_region(group_of, regions, g) for g in range(n)]


def test_block_neighbours_are_the_four_lattice_steps_and_minus_one_off_the_blocks():
    # Blocks at (0,0) (0,1) (0,2) (1,0) (1,2): (1,1) is missing.
    rc = np.array([[0, 0], [0, 1], [0, 2], [1, 0], [1, 2]])
    nb = block_neighbours(rc)
    # columns: up (row + 1), down (row - 1), right (col + 1), left (col - 1)
    assert nb.tolist() == [
        [3, -1, 1, -1],
        [-1, -1, 2, 0],
        [4, -1, -1, 1],
        [-1, 0, -1, -1],
        [-1, 2, -1, -1],
    ]
    assert block_neighbours(np.zeros((0, 2), dtype=np.int64)).shape == (0, 4)


def _random_blocks(seed, n_side=7, n_cells=60):
    rng = np.random.default_rng(seed)
    rc = np.array([(r, c) for r in range(n_side) for c in range(n_side) if rng.random() > 0.15])
    regions = [np.unique(rng.integers(0, n_cells, rng.integers(1, 12))) for _ in range(len(rc))]
    cells = rng.integers(4, 17, len(rc))
    return rc, cells, regions, n_cells


@pytest.mark.parametrize("seed", range(5))
def test_grown_groups_partition_the_blocks_and_hold_the_union_of_their_regions(seed):
    rc, cells, regions, n_cells = _random_blocks(seed)
    nb = block_neighbours(rc)
    target, growth = 40.0, 0.5
    group_of, group_regions = _grown(nb, cells, regions, n_cells, target, growth)
    assert group_of.shape == (len(rc),) and group_of.min() == 0
    assert set(group_of.tolist()) == set(range(len(group_regions)))
    for g, region in enumerate(group_regions):
        members = np.flatnonzero(group_of == g)
        union = np.unique(np.concatenate([regions[b] for b in members]))
        assert np.array_equal(region, union)
        # one piece of the lattice: every member reached from the first by neighbour steps
        reach, todo = {int(members[0])}, [int(members[0])]
        while todo:
            for j in nb[todo.pop()]:
                if j >= 0 and group_of[j] == g and int(j) not in reach:
                    reach.add(int(j))
                    todo.append(int(j))
        assert reach == set(members.tolist())
        # a group short of the target stopped because no free neighbour was cheap enough
        if cells[members].sum() < target:
            inside = set(region.tolist())
            for b in members:
                for j in nb[b]:
                    if j >= 0 and group_of[j] != g:
                        widen = len(set(regions[j].tolist()) - inside)
                        later = group_of[j] > g  # still free when this group grew
                        assert not later or widen > growth * len(inside)


def test_a_group_takes_the_neighbour_that_widens_its_region_least_within_the_growth_share():
    # Four blocks in a row, 10 cells each; block 1 is seen from the fewest cells (4), so it
    # seeds the first group. Block 0 widens it by 1 cell, block 2 by 3: block 0 joins. Then
    # block 2 widens the 5 cells by 3, block 3 (from block 2's side) would add 3 more.
    rc = np.array([[0, 0], [0, 1], [0, 2], [0, 3]])
    regions = [np.array([0, 1, 2, 3, 4]), np.array([0, 1, 2, 3]), np.array([2, 3, 5, 6, 7]),
               np.array([6, 7, 8, 9, 10])]  # fmt: skip
    cells = np.array([10, 10, 10, 10])
    nb = block_neighbours(rc)
    # growth 0.7: 3 of 5 and then 3 of 8 are within it; one group, the union of all four
    group_of, group_regions = _grown(nb, cells, regions, 11, 35.0, 0.7)
    assert group_of.tolist() == [0, 0, 0, 0]
    assert group_regions[0].tolist() == list(range(11))
    # growth 0.5: block 2's 3 of 5 is too much; block 2 then seeds a group, and block 3's
    # 3 new cells of block 2's 5 are too much again
    group_of, group_regions = _grown(nb, cells, regions, 11, 35.0, 0.5)
    assert group_of.tolist() == [0, 0, 1, 2]
    assert group_regions[0].tolist() == [0, 1, 2, 3, 4]
    # the target: a group stops once it holds 20 cells
    group_of, _ = _grown(nb, cells, regions, 11, 20.0, 0.7)
    assert group_of.tolist() == [0, 0, 1, 1]


def test_grown_groups_raise_the_route_on_a_loop_with_rooms_and_stay_below_a_tour(
    privileged_world,
):
    # A square ring corridor with a room inside (through a passage) and one outside: a loop,
    # where the branch bound is weak and the route carries the bound; a room's far side is
    # seen only from inside it, a region the lattice's large blocks do not isolate.
    ring = [(0.0, 0.0, 5.2, 0.6), (0.0, 4.6, 5.2, 5.2), (0.0, 0.0, 0.6, 5.2), (4.6, 0.0, 5.2, 5.2)]
    rooms = [(1.6, 1.6, 3.6, 3.6), (2.0, 0.5, 2.6, 1.7), (5.1, 2.0, 7.1, 4.0)]
    facts = _facts(privileged_world, ring + rooms, (7.2, 5.2), (2.6, 0.3, 0.0))
    lattice = lower_bound(facts, LowerBoundParams(grown_shares=()))
    grown = lower_bound(facts)
    assert grown.branch_m == lattice.branch_m < lattice.distance_m
    assert grown.distance_m >= 1.05 * lattice.distance_m
    tour = plan_coverage_tour(facts)  # a real drive that sees 99.3 % (an upper bound)
    assert tour.covered_share >= 0.99
    assert grown.distance_m <= tour.length_m
    with pytest.raises(ValueError, match="grown_shares"):
        LowerBoundParams(grown_shares=(0.0,))
    with pytest.raises(ValueError, match="grown_growth"):
        LowerBoundParams(grown_growth=-1.0)


@pytest.mark.parametrize(
    "spec", ["maze:seed=8,size_m=6,braid=0.3", "office:seed=9,size_m=8", "cave:seed=3,size_m=8"]
)
def test_every_cell_a_scan_maps_free_lies_in_a_grown_group_seen_from_the_scans_cell(
    spec, bound_problem
):
    # The grown groups' regions, as the bound builds them (0.2 m blocks, corners on), must
    # hold the distance cell of every pose from which a real scan maps one of their cells.
    from dataclasses import replace

    from semexplore_gym.core.coverage_tour.bound_geometry import mask_groups, wall_corners
    from semexplore_gym.core.coverage_tour.branch_kernels import coarse_region
    from semexplore_gym.core.coverage_tour.viewpoints import visible_sets

    facts, allowed, prob = bound_problem(spec, 4, 2, 8)
    prob = replace(prob, corners=wall_corners(facts.world.segments_m, prob.walls))
    geo, mask = facts.geometry, facts.reachable_mask
    frame = np.array(
        [geo.origin_x_m, geo.origin_y_m, geo.resolution_m, prob.reach_m, 1e-6, 1e-6, 3, 400]
    )
    rects, cells, centres = mask_groups(mask, geo, 4)
    found = [coarse_region(allowed, 2, r, prob.walls, frame, prob.corners) for r in rects]
    rc = np.floor((centres[:, ::-1] - (geo.origin_y_m, geo.origin_x_m)) / 0.2).astype(np.int64)
    group_of, regions = _grown(block_neighbours(rc), cells, found, prob.coarse.size, 120, 0.3)
    assert 1 < len(regions) < len(found)  # groups of several blocks
    rows, cols = np.nonzero(mask)
    block_of = np.full(mask.shape, -1, dtype=np.int64)
    keys = (rows // 4) * -(-geo.width // 4) + cols // 4
    block_of[rows, cols] = np.unique(keys, return_inverse=True)[1]
    rng = np.random.default_rng(1)
    ar, ac = np.nonzero(allowed & mask)
    pick = rng.choice(ar.size, 20, replace=False)
    poses = np.column_stack([ar[pick], ac[pick]])
    seen = visible_sets(facts.world, geo, poses, facts.sensor, mask)
    flat = np.flatnonzero(mask)
    members = [set(r.tolist()) for r in regions]
    checked = 0
    for i, (r, c) in enumerate(poses):
        here = prob.to_coarse(np.array([r * geo.width + c]))[0]
        sr, sc = np.divmod(flat[seen[i].indices], geo.width)
        for g in np.unique(group_of[block_of[sr, sc]]):
            assert here in members[g], (spec, (r, c), g)
            checked += 1
    assert checked > 20
