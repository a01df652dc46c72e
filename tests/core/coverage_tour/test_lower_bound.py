"""The certified lower bound on worlds whose optimum is known, and its proof steps one by one.

Every check is one-sided where the bound's guarantee is (never above a feasible drive, the
K-hop metric never above a true path, every cell a scan maps FREE inside a region holding the
scan's cell) and loose on the other side: the bound is a relaxation, not an estimate.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import dijkstra

from semexplore_gym.core.coverage_tour import LowerBoundParams, lower_bound
from semexplore_gym.core.coverage_tour.khop_kernels import khop_balls, khop_distances
from semexplore_gym.core.coverage_tour.lower_bound import (
    _Problem,
    allowed_cells,
    coarse_moves,
    mask_groups,
    merge_walls,
    skip_budget_cells,
)
from semexplore_gym.core.coverage_tour.lower_bound_kernels import held_karp_entries, held_karp_route
from semexplore_gym.core.grid import GridGeometry
from semexplore_gym.core.worlds.build import world_from_free_mask

RES = 0.05
RADIUS = 0.105
RANGE_M = 1.0


def _khop(moves, sources, k, res, depth_step=0.0):
    """The full K-hop field (no targets to stop at)."""
    none = np.full(moves.shape, -1, dtype=np.int64)
    src = np.asarray(sources, dtype=np.int64)
    return khop_distances(moves, src, k, res, none, 0, np.inf, depth_step)


def _eight_connected_lengths(allowed, source, res):
    """Shortest centre-to-centre polylines over touching allowed cells (a diagonal step passes
    through the corner the two squares share): each is a drive the robot's centre could make."""
    h, w = allowed.shape
    idx = np.arange(h * w).reshape(h, w)
    rows, cols, vals = [], [], []
    for dr, dc in ((0, 1), (1, 0), (1, 1), (1, -1)):
        a = idx[: h - dr, max(0, -dc) : w - max(0, dc)]
        b = idx[dr:, max(0, dc) : w + min(0, dc)]
        ok = allowed.reshape(-1)[a] & allowed.reshape(-1)[b]
        rows.append(a[ok])
        cols.append(b[ok])
        vals.append(np.full(int(ok.sum()), res * math.hypot(dr, dc)))
    graph = coo_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))))
    graph = graph.tocsr()
    graph.resize(h * w, h * w)
    return dijkstra(graph, directed=False, indices=source).reshape(h, w)


def _world(rects, size_m, start):
    h, w = int(round(size_m[1] / RES)), int(round(size_m[0] / RES))
    free = np.zeros((h, w), dtype=bool)
    for x0, y0, x1, y1 in rects:
        rows = slice(int(round(y0 / RES)), int(round(y1 / RES)))
        free[rows, int(round(x0 / RES)) : int(round(x1 / RES))] = True
    return world_from_free_mask("test", free, GridGeometry(RES, 0.0, 0.0, h, w), start_pose=start)


def _facts(pw, rects, size_m, start, range_m=RANGE_M):
    return pw(_world(rects, size_m, start), start, RADIUS, range_m, RES)


def test_a_straight_corridor_bound_is_below_its_one_way_drive_and_close(privileged_world):
    # 8 m x 0.6 m, start 0.3 m from the left end: the far end's cells are seen from R before
    # it, so a drive of 8 - 0.3 - R reaches full coverage; 99 % needs a little less.
    facts = _facts(privileged_world, [(0.0, 0.0, 8.0, 0.6)], (8.0, 0.6), (0.3, 0.3, 0.0))
    b = lower_bound(facts)
    drive = 8.0 - 0.3 - RANGE_M
    assert 0.6 * drive <= b.distance_m <= drive
    assert b.time_s == pytest.approx(b.distance_m / facts.max_linear_speed_mps)
    assert b.n_groups >= 1 and len(b.route) >= 1


def test_a_ring_bound_is_below_driving_round_once(privileged_world):
    # A square ring corridor 0.6 m wide around a 4 m x 4 m block; its centre line is 4 x 4.6
    # m long. Driving once round (less what the LiDAR sees ahead and behind) covers it all.
    rects = [(0.0, 0.0, 5.2, 0.6), (0.0, 4.6, 5.2, 5.2), (0.0, 0.0, 0.6, 5.2), (4.6, 0.0, 5.2, 5.2)]
    facts = _facts(privileged_world, rects, (5.2, 5.2), (2.6, 0.3, 0.0))
    b = lower_bound(facts)
    once_round = 4 * 4.6 - 2 * RANGE_M
    assert 0.0 < b.distance_m <= once_round
    # A route first enters each region at one of its entry pieces: a large region no longer
    # carries the route across itself for free (that gave about a third of the round).
    assert b.distance_m >= 0.55 * once_round


def test_a_comb_bound_is_below_a_drive_that_visits_every_tooth(privileged_world):
    # A spine 7 m long (y in [0, 0.6]) with 4 teeth 3 m deep every 2 m; start at the spine's
    # left end. Feasible: along the spine, into and out of each tooth to R of its end, the
    # last one not driven back.
    teeth = [(x, 0.0, x + 0.6, 3.6) for x in (0.0, 2.0, 4.0, 6.0)]
    facts = _facts(privileged_world, [(0.0, 0.0, 6.6, 0.6), *teeth], (6.6, 3.6), (0.3, 0.3, 0.0))
    b = lower_bound(facts)
    depth = 3.3 - RANGE_M
    feasible = 6.0 + 2 * depth * 4 - depth
    assert 0.45 * feasible <= b.distance_m <= feasible


def test_khop_distance_never_exceeds_the_geodesic_on_an_l_corridor():
    # L of two 0.6 m corridors; cells 0.05 m. The true shortest path between the two far ends'
    # centres hugs the inner corner: at most the polyline through the corner's cell.
    h, w = 120, 120
    allowed = np.zeros((h, w), dtype=bool)
    allowed[0:12, 0:120] = True
    allowed[0:120, 108:120] = True
    a = (6, 2)
    b = (117, 114)
    k = 8
    d = _khop(coarse_moves(allowed, 1), np.array([a[0] * w + a[1]]), k, RES)
    corner = np.array([11.0, 108.0])
    path_cells = np.hypot(*(corner - a)) + np.hypot(*(np.array(b) - corner))
    assert 0.7 * path_cells * RES <= d[b] <= path_cells * RES


def test_a_hop_counts_its_breadth_first_depth_round_corners_and_stays_below_a_drive():
    # A serpentine corridor 0.3 m wide, five runs of 3 m joined at alternate ends: a hop's
    # straight gap round each of the eight corners cuts through the wall between two runs, the
    # breadth-first depth of its far cell does not, so counting it raises the distance to the
    # far end by metres; it stays below a drive there (centre polyline less a cell).
    wd, runs, w = 6, 5, 60
    allowed = np.zeros((runs * 2 * wd, w), dtype=bool)
    for i in range(runs):
        allowed[2 * i * wd : 2 * i * wd + wd, :] = True
        if i < runs - 1:
            cols = slice(w - wd, w) if i % 2 == 0 else slice(0, wd)
            allowed[2 * i * wd + wd : 2 * i * wd + 2 * wd, cols] = True
    src = (wd // 2) * w
    end = (2 * (runs - 1) * wd + wd // 2, w - 1)
    moves = coarse_moves(allowed, 1)
    plain = _khop(moves, [src], 8, RES)
    deep = _khop(moves, [src], 8, RES, depth_step=RES)
    drive = _eight_connected_lengths(allowed, src, RES) - RES
    assert plain[end] + 2.0 <= deep[end] <= drive[end]
    assert np.all(deep[np.isfinite(plain)] >= plain[np.isfinite(plain)])


@pytest.mark.parametrize("seed", range(4))
def test_a_depth_counting_khop_distance_is_never_above_a_drive_on_random_grids(seed):
    # A drive from anywhere in the source's square to anywhere in a cell's square is at most
    # the centre-to-centre polyline less half a cell at each end (h in all). Counting a cell
    # size per breadth-first move beyond the first stays below it on cluttered grids with
    # pinches; counting one per move (one more) would not, even along an open row.
    rng = np.random.default_rng(seed)
    allowed = rng.random((48, 48)) > 0.3 + 0.05 * seed
    allowed[24, :] = True
    src = 24 * 48 + int(rng.integers(0, 48))
    moves = coarse_moves(allowed, 1)
    drive = _eight_connected_lengths(allowed, src, RES) - RES
    for k in (3, 8):
        d = _khop(moves, [src], k, RES, depth_step=RES)
        reached = np.isfinite(drive) & (drive > 0)
        assert np.all(d[reached] <= drive[reached] + 1e-9)
        assert np.array_equal(np.isfinite(d), np.isfinite(drive))
    over = _khop(moves, [src], 8, RES, depth_step=RES * 8 / 7)  # as if D rather than D - 1
    assert np.any(over[reached] > drive[reached] + 1e-9)


def test_khop_distance_is_exact_along_a_row_and_never_above_the_squares_gap():
    # Open space: every hop of a straight chain starts on the side of its checkpoint's square
    # that the chain crossed, so along a row the K-hop distance is the gap between the two
    # squares exactly (the square-to-square measure of every hop would lose a cell a hop);
    # nowhere is it above the straight-line gap between the source's square and the cell's.
    k = 8
    n = 120
    d = _khop(coarse_moves(np.ones((n, n), dtype=bool), 1), np.array([60 * n + 3]), k, RES)
    assert d[60, n - 1] == pytest.approx((n - 1 - 3 - 1) * RES)
    rows, cols = np.mgrid[0:n, 0:n]
    gap = RES * np.hypot(np.maximum(np.abs(rows - 60) - 1, 0), np.maximum(np.abs(cols - 3) - 1, 0))
    assert np.all(d <= gap + 1e-12)
    assert np.median(d[gap > 20 * RES] / gap[gap > 20 * RES]) > 0.9


def test_coarse_distance_cells_do_not_join_across_a_thin_wall():
    # Two corridors 10 cells wide, a band of 2 forbidden cells between them (a wall with the
    # robot's clearance), joined only at the right end: with 2 x 2 distance cells the band
    # lies inside blocks whose cells on either side are allowed, yet no move crosses it.
    allowed = np.zeros((22, 100), dtype=bool)
    allowed[0:10, :] = True
    allowed[12:22, :] = True
    allowed[:, 90:100] = True
    moves = coarse_moves(allowed, 2)
    d = _khop(moves, np.array([2 * moves.shape[1] + 0]), 4, 2 * RES)
    assert d[8, 0] >= 0.7 * 2 * 90 * RES  # around the wall's end, not through it


def test_stopping_at_the_targets_keeps_their_least_distance_exact():
    rng = np.random.default_rng(1)
    allowed = rng.random((60, 60)) > 0.25
    allowed[30, :] = True
    moves = coarse_moves(allowed, 1)
    src = np.array([30 * 60 + 0])
    full = _khop(moves, src, 5, RES)
    targets = [np.array([30 * 60 + 59, 10 * 60 + 40]), np.array([31 * 60 + 5])]
    target_of = np.full(allowed.shape, -1, dtype=np.int64)
    for j, t in enumerate(targets):
        target_of.reshape(-1)[t] = j
    early = khop_distances(moves, src, 5, RES, target_of, 2).reshape(-1)
    for t in targets:
        assert early[t].min() == full.reshape(-1)[t].min()


def test_cached_balls_give_the_same_distances_bit_for_bit():
    # A grid with walls, holes and a corridor: the searches of each kind (full field, several
    # sources, a limit, targets, the depth step) give the same field with the balls computed
    # once as with each search's own breadth-first search.
    rng = np.random.default_rng(7)
    allowed = rng.random((70, 64)) > 0.3
    allowed[35, :] = True
    allowed[:, 10] = False
    allowed[5, 10] = True
    moves = coarse_moves(allowed, 1)
    k = 5
    balls = khop_balls(moves, k)
    assert balls[0].size == moves.size + 1 and balls[1].size == balls[2].size
    inside = np.flatnonzero((moves.reshape(-1) >> 4) & 1)
    assert np.all(np.diff(balls[0])[inside] > 0)  # every allowed cell's ball holds itself
    none = np.full(moves.shape, -1, dtype=np.int64)
    target_of = none.copy()
    target_of.reshape(-1)[[35 * 64 + 63, 60 * 64 + 2]] = 0
    for src, limit, step, targets in (
        ([35 * 64], np.inf, 0.0, (none, 0)),
        ([35 * 64, 3 * 64 + 3], np.inf, RES, (none, 0)),
        ([35 * 64 + 30], 0.6, RES, (none, 0)),
        ([35 * 64], np.inf, RES, (target_of, 1)),
    ):
        src = np.asarray(src, dtype=np.int64)
        own = khop_distances(moves, src, k, RES, *targets, limit, step)
        cached = khop_distances(moves, src, k, RES, *targets, limit, step, balls)
        assert np.isfinite(own).sum() > 100
        np.testing.assert_array_equal(cached, own)


def test_balls_are_only_cached_within_the_memory_cap():
    facts, prob, _ = _maze_problem(0)
    assert prob.balls is None
    assert prob.with_balls().balls is not None
    assert prob.with_balls(max_entries=10).balls is None


def test_skip_budget_matches_the_missions_coverage_rule():
    for n in (1, 99, 100, 101, 18481, 147300):
        b = skip_budget_cells(n, 0.99)
        assert (n - b) / n >= 0.99 - 1e-12
        assert b == n or (n - b - 1) / n < 0.99 - 1e-12


def test_collinear_touching_walls_merge_and_others_do_not():
    walls = np.array(
        [[0, 0, 1, 0], [1, 0, 2, 0], [2.5, 0, 3, 0], [0, 1, 0, 2], [0, 0, 0, 1], [1, 1, 2, 2]],
        dtype=np.float64,
    )
    merged = {tuple(np.round(s, 9)) for s in merge_walls(walls)}
    assert (0.0, 0.0, 2.0, 0.0) in merged and (2.5, 0.0, 3.0, 0.0) in merged
    assert (0.0, 0.0, 0.0, 2.0) in merged and len(merged) == 4


def test_held_karp_takes_the_cheapest_feasible_subset():
    first = np.array([1.0, 5.0, 2.0])
    legs = np.array([[0.0, 1.0, 10.0], [1.0, 0.0, 10.0], [10.0, 10.0, 0.0]])
    cells = np.array([10, 10, 3], dtype=np.int64)
    # budget 3: group 2 may be skipped, 0 and 1 not: start -> 0 -> 1 = 2
    length, order = held_karp_route(first, legs, cells, 3)
    assert length == pytest.approx(2.0) and list(order) == [0, 1]
    length, order = held_karp_route(first, legs, cells, 0)
    assert length == pytest.approx(12.0)
    assert held_karp_route(first, legs, cells, 23)[0] == 0.0


def test_held_karp_over_entry_pieces_leaves_each_group_where_it_entered_it():
    # Group 0 has two entry pieces: near the start but far from group 1 (node 0), or far from
    # the start and next to group 1 (node 1); group 1 one piece (node 2), far from the start.
    first = np.array([1.0, 5.0, 20.0])
    legs = np.array([[0.0, 0.0, 10.0], [0.0, 0.0, 1.0], [10.0, 1.0, 0.0]])
    group_of = np.array([0, 0, 1], dtype=np.int64)
    cells = np.array([10, 10], dtype=np.int64)
    length, order = held_karp_entries(first, legs, group_of, cells, 3)
    assert length == pytest.approx(6.0) and list(order) == [0, 1]
    # group 1 may be left unseen: the nearest piece of group 0 alone
    assert held_karp_entries(first, legs, group_of, np.array([10, 3]), 3)[0] == 1.0
    assert held_karp_entries(first, legs, group_of, cells, 20)[0] == 0.0


def _maze_problem(split_depth):
    from semexplore_gym.core.coverage_tour import PRIVILEGED_INFO_KEY
    from semexplore_gym.envs.semantic_explore import SemanticExploreEnv

    env = SemanticExploreEnv(
        "maze:seed=1,size_m=5", privileged=True, overrides=["episode.random_start=true"]
    )
    try:
        facts = env.reset(seed=4)[1][PRIVILEGED_INFO_KEY]
    finally:
        env.close()
    allowed, start = allowed_cells(facts, 0.01)
    prob = _Problem(
        allowed=allowed,
        coarse=coarse_moves(allowed, 2),
        factor=2,
        walls=merge_walls(facts.world.segments_m),
        geometry=facts.geometry,
        reach_m=facts.sensor.max_range_m + 1e-6,
        widen_m=1e-6,
        hop_cells=8,
        split_depth=split_depth,
    )
    return facts, prob, start


def test_quartering_a_group_only_drops_cells_and_drops_some():
    facts, whole, _ = _maze_problem(0)
    _, split, _ = _maze_problem(3)
    rects, _, _ = mask_groups(facts.reachable_mask, facts.geometry, 14)
    dropped = 0
    for rect in rects[::3]:
        a, b = set(whole.region(rect).tolist()), set(split.region(rect).tolist())
        assert b <= a
        dropped += len(a - b)
    assert dropped > 0


def test_a_region_entered_at_the_start_has_the_start_as_its_one_entry():
    facts, prob, (sr, sc) = _maze_problem(3)
    start = int(prob.to_coarse(np.array([sr * facts.geometry.width + sc]))[0])
    rects, _, _ = mask_groups(facts.reachable_mask, facts.geometry, 14)
    hc, wc = prob.coarse.shape
    n_with, n_without = 0, 0
    for rect in rects:
        region = prob.region(rect)
        pieces = prob.entry_pieces(region, start, 10, 3)
        if start in set(region.tolist()):
            assert [q.tolist() for q in pieces] == [[start]]
            n_with += 1
            continue
        n_without += 1
        assert 1 <= len(pieces) <= 3
        inside = np.zeros(hc * wc, dtype=bool)
        inside[region] = True
        for q in pieces:  # entry cells lie in the region and next to a cell outside it
            assert inside[q].all()
            r, c = np.divmod(q, wc)
            ring = [(r + dr) * wc + (c + dc) for dr in (-1, 0, 1) for dc in (-1, 0, 1)]
            assert (~inside[np.clip(np.array(ring), 0, hc * wc - 1)]).any(axis=0).all()
    assert n_with > 0 and n_without > 0


@pytest.mark.parametrize(
    "spec",
    [
        "maze:seed=1,size_m=5",
        "maze:seed=8,size_m=6,braid=0.3",
        "office:seed=2,size_m=10",
        "office:seed=9,size_m=8",
        "cave:seed=3,size_m=8",
        "forest:seed=4,size_m=6",
    ],
)
@pytest.mark.parametrize("corners", [False, True])
def test_every_cell_a_scan_maps_free_lies_in_a_group_seen_from_the_scans_cell(
    spec, corners, bound_problem
):
    from dataclasses import replace

    from semexplore_gym.core.coverage_tour.bound_geometry import wall_corners
    from semexplore_gym.core.coverage_tour.viewpoints import visible_sets

    facts, allowed, prob = bound_problem(spec, 4, 1, 4)
    if corners:  # two walls that meet block a view together (LowerBoundParams.wall_corners)
        prob = replace(prob, corners=wall_corners(facts.world.segments_m, prob.walls))
    geo = facts.geometry
    block = 10
    rects, _, _ = mask_groups(facts.reachable_mask, geo, block)
    rows, cols = np.nonzero(facts.reachable_mask)
    _, group_of = np.unique(
        (rows // block) * -(-geo.width // block) + cols // block, return_inverse=True
    )
    group_at = np.full(geo.height * geo.width, -1)
    group_at[rows * geo.width + cols] = group_of
    rng = np.random.default_rng(0)
    ar, ac = np.nonzero(allowed & facts.reachable_mask)
    pick = rng.choice(ar.size, 25, replace=False)
    poses = np.column_stack([ar[pick], ac[pick]])
    seen = visible_sets(facts.world, geo, poses, facts.sensor, facts.reachable_mask)
    flat = np.flatnonzero(facts.reachable_mask)
    regions: dict[int, set[int]] = {}  # a group's region, computed once for all poses
    checked = 0
    for i, (r, c) in enumerate(poses):
        for g in np.unique(group_at[flat[seen[i].indices]]):
            if g not in regions:
                regions[g] = set(prob.region(rects[g]).tolist())
            assert r * geo.width + c in regions[g]
            checked += 1
    assert checked > 25


def test_a_start_inside_a_wall_is_one_clear_error(privileged_world):
    facts = _facts(privileged_world, [(0.0, 0.0, 4.0, 0.6)], (4.0, 0.6), (0.3, 0.3, 0.0))
    moved = type(facts)(**{**facts.__dict__, "start_pose": (0.3, 0.02, 0.0)})
    with pytest.raises(ValueError, match="inside a wall"):
        lower_bound(moved)


def test_nothing_to_cover_is_one_clear_error(privileged_world):
    facts = _facts(privileged_world, [(0.0, 0.0, 4.0, 0.6)], (4.0, 0.6), (0.3, 0.3, 0.0))
    empty = type(facts)(**{**facts.__dict__, "reachable_mask": np.zeros_like(facts.reachable_mask)})
    with pytest.raises(ValueError, match="nothing to cover"):
        lower_bound(empty)


def test_a_map_larger_than_its_grid_is_one_clear_error(privileged_world):
    facts = _facts(privileged_world, [(0.0, 0.0, 4.0, 0.6)], (4.0, 0.6), (0.3, 0.3, 0.0))
    g = facts.geometry
    small = GridGeometry(g.resolution_m, g.origin_x_m + 0.6, g.origin_y_m, g.height, g.width - 30)
    cut = type(facts)(
        **{**facts.__dict__, "geometry": small, "reachable_mask": facts.reachable_mask[:, 12:-18]}
    )
    with pytest.raises(ValueError, match="edge of the map grid"):
        lower_bound(cut)


def test_params_reject_bad_values():
    with pytest.raises(ValueError, match="hop_cells"):
        LowerBoundParams(hop_cells=0)
    with pytest.raises(ValueError, match="coverage_share"):
        LowerBoundParams(coverage_share=1.5)
    with pytest.raises(ValueError, match="threads must be an integer in 1..256, got 0"):
        LowerBoundParams(threads=0)
    assert math.isfinite(LowerBoundParams().group_scales[0])


def test_the_bound_is_the_same_on_one_thread_or_several(privileged_world):
    # The searches spread over threads are independent: the same route, groups and branches.
    teeth = [(x, 0.0, x + 0.6, 3.6) for x in (0.0, 2.0, 4.0, 6.0)]
    facts = _facts(privileged_world, [(0.0, 0.0, 6.6, 0.6), *teeth], (6.6, 3.6), (0.3, 0.3, 0.0))
    one = lower_bound(facts, LowerBoundParams(threads=1))
    three = lower_bound(facts, LowerBoundParams(threads=3))
    assert one.distance_m > 0 and len(one.route) >= 2
    assert (one.distance_m, one.branch_m, one.route, one.group_cells, one.region_cells) == (
        three.distance_m,
        three.branch_m,
        three.route,
        three.group_cells,
        three.region_cells,
    )


@pytest.mark.slow
@pytest.mark.parametrize(
    "spec",
    [
        "maze:seed=1,size_m=5",
        "office:seed=2,size_m=8",
        "cave:seed=3,size_m=6",
        "forest:seed=4,size_m=6",
    ],
)
def test_missions_never_reach_99_percent_sooner_or_shorter_than_the_bound(spec, short_mission):
    from semexplore_gym.cli.oracle import certified_bound

    seed = 5
    bound = certified_bound(spec, seed, env_overrides=["episode.random_start=true"])
    assert bound.distance_m > 0
    reached = 0
    for policy in ("semantic", "nearest"):
        res, _ = short_mission(spec, policy, seed, 600.0)
        if res.t99_s is None:  # stopped short of 99 %: nothing to compare
            continue
        reached += 1
        assert res.t99_s >= bound.time_s, (spec, policy, res.t99_s, bound.time_s)
        hit = next(i for i, (_, c, _) in enumerate(res.coverage_trace) if c >= 0.99 - 1e-12)
        steps = np.diff(res.trajectory[: hit + 1, :2], axis=0)
        drive_m = float(np.hypot(steps[:, 0], steps[:, 1]).sum())
        assert drive_m >= bound.distance_m, (spec, policy, drive_m, bound.distance_m)
    assert reached >= 1


@pytest.mark.parametrize("factor", [1, 2])
def test_every_diagonal_move_is_kept_the_south_east_one_too(factor):
    # Cells touching only at corners, in a chain going down and right: a path passes along it,
    # so the K-hop search must reach its far end (the move by (+1, +1) is the mask's bit 8).
    allowed = np.zeros((40, 40), dtype=bool)
    for i in range(2, 38):
        allowed[i, i] = True
    moves = coarse_moves(allowed, factor)
    rows, cols = np.nonzero(moves & (1 << 4))
    for dr, dc in ((1, 1), (-1, -1)):
        bit = 3 * (dr + 1) + dc + 1
        inner = (rows + dr < moves.shape[0]) & (cols + dc < moves.shape[1])
        joined = (moves[rows, cols] >> bit) & 1
        assert joined[inner & (moves[rows + dr * inner, cols + dc * inner] & (1 << 4) > 0)].all()
    start = (2 // factor) * moves.shape[1] + 2 // factor
    d = _khop(moves, [start], 4, RES * factor)
    assert np.isfinite(d[37 // factor, 37 // factor])
