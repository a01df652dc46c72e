"""The static coverage tour on worlds whose optimum is known, and its building blocks.

Tolerance: with a LiDAR of range R, a corridor's far end is seen from R before it, so the
shortest open drive that sees it is ``L - R`` (less the start's offset); the tour's viewpoints
sit on a 0.3 m lattice, at the cell farthest from the walls, and the cover may leave 0.7 % of
the cells unseen, so we accept ``[optimum - 0.6 m, optimum + 0.6 m]`` per branch.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy import sparse

from semexplore_gym.core.coverage_tour import (
    TourParams,
    greedy_cover,
    open_tour_order,
    plan_coverage_tour,
)
from semexplore_gym.core.grid import GridGeometry
from semexplore_gym.core.worlds.build import world_from_free_mask

pytest.importorskip("elkai")

RES = 0.05
RADIUS = 0.105
RANGE_M = 1.0


def _facts(pw, rects: list[tuple[float, float, float, float]], size_m: tuple[float, float], start):
    h, w = int(round(size_m[1] / RES)), int(round(size_m[0] / RES))
    free = np.zeros((h, w), dtype=bool)
    for x0, y0, x1, y1 in rects:
        free[
            int(round(y0 / RES)) : int(round(y1 / RES)), int(round(x0 / RES)) : int(round(x1 / RES))
        ] = True
    world = world_from_free_mask("test", free, GridGeometry(RES, 0.0, 0.0, h, w), start_pose=start)
    return pw(world, start, RADIUS, RANGE_M, RES)


def test_a_straight_corridor_is_driven_once_to_within_range_of_its_end(privileged_world):
    # 8 m x 0.6 m, start 0.3 m from the left end: the optimum is 8 - 0.3 - R (= 6.7 m).
    facts = _facts(privileged_world, [(0.0, 0.0, 8.0, 0.6)], (8.0, 0.6), (0.3, 0.3, 0.0))
    tour = plan_coverage_tour(facts)
    optimum = 8.0 - 0.3 - RANGE_M
    assert optimum - 0.6 <= tour.length_m <= optimum + 0.6
    assert tour.covered_share >= TourParams().coverage_target


def test_a_tree_maze_open_tour_saves_its_longest_branch(privileged_world):
    # A hub at (4, 4) with corridors 0.6 m wide: east 4 m, north 4 m, west 2.5 m (from the
    # hub's centre). Each branch needs its length less R driven; a closed tour drives each
    # twice, an open one drives the longest once.
    rects = [(3.7, 3.7, 8.0, 4.3), (3.7, 3.7, 4.3, 8.0), (1.5, 3.7, 4.3, 4.3)]
    facts = _facts(privileged_world, rects, (8.0, 8.0), (4.0, 4.0, 0.0))
    tour = plan_coverage_tour(facts)
    depth = np.array([4.0, 4.0, 2.5]) - RANGE_M
    closed = 2.0 * depth.sum()
    optimum = closed - depth.max()
    assert optimum - 0.6 * 3 <= tour.length_m <= optimum + 0.6 * 3
    assert tour.length_m < closed - 0.5 * depth.max()
    assert tour.covered_share >= TourParams().coverage_target


def test_the_tour_is_deterministic(privileged_world):
    rects = [(3.7, 3.7, 8.0, 4.3), (3.7, 3.7, 4.3, 8.0), (1.5, 3.7, 4.3, 4.3)]
    facts = _facts(privileged_world, rects, (8.0, 8.0), (4.0, 4.0, 0.0))
    a = plan_coverage_tour(facts, TourParams(lkh_runs=2))
    b = plan_coverage_tour(facts, TourParams(lkh_runs=2))
    assert np.array_equal(a.viewpoints_rc, b.viewpoints_rc)
    assert a.length_m == b.length_m


def test_greedy_cover_takes_the_biggest_sets_first_and_stops_at_the_target():
    rows = [[0, 1, 2, 3], [3, 4], [4, 5, 6], [0, 6]]
    m = sparse.lil_matrix((4, 7), dtype=bool)
    for i, cols in enumerate(rows):
        m[i, cols] = True
    m = m.tocsr()
    assert greedy_cover(m, 7) == [0, 2]
    assert greedy_cover(m, 4) == [0]
    covered = np.zeros(7, dtype=bool)
    covered[:4] = True
    assert greedy_cover(m, 7, covered) == [2]


def test_open_tour_starts_at_zero_and_visits_everything_once():
    xs = np.array([0.0, 5.0, 1.0, 4.0, 2.0, 3.0])
    d = np.abs(xs[:, None] - xs[None, :])
    order = open_tour_order(d)
    assert order[0] == 0 and sorted(order) == list(range(6))
    assert d[order[:-1], order[1:]].sum() == pytest.approx(5.0)


def test_scans_along_the_legs_count_and_refining_never_lengthens_the_tour(privileged_world):
    # A comb: a 6 m corridor with four 1.2 m teeth. With a 1 m LiDAR the plain cover stops in
    # every tooth; the scans taken while driving the spine see into the teeth, so the refined
    # tour drops viewpoints the legs make unnecessary, and it is never longer (both counted
    # with one scan per pose: the robust count sees less and may need more).
    rects = [(0.0, 0.0, 6.0, 0.6)] + [(x, 0.6, x + 0.6, 1.8) for x in (0.9, 2.1, 3.3, 4.5)]
    facts = _facts(privileged_world, rects, (6.0, 1.8), (0.3, 0.3, 0.0))
    plain = plan_coverage_tour(facts, TourParams(refine_rounds=0, robust_cells=0))
    refined = plan_coverage_tour(facts, TourParams(robust_cells=0))
    assert refined.length_m <= plain.length_m + 1e-9
    assert refined.n_viewpoints < plain.n_viewpoints
    assert refined.covered_share >= TourParams().coverage_target
    robust = plan_coverage_tour(facts)
    assert robust.covered_share >= TourParams().coverage_target
    # What the refined tour counts as seen includes cells none of its viewpoints see.
    by_viewpoints = np.zeros(refined.mask_flat.size, dtype=bool)
    by_viewpoints[refined.visible.indices] = True
    assert (refined.seen & ~by_viewpoints).any()
    assert refined.seen.mean() == pytest.approx(refined.covered_share)


@pytest.mark.parametrize(
    "kwargs, words",
    [
        ({"refine_rounds": -1}, "refine_rounds"),
        ({"leg_sample_m": 0.0}, "leg_sample_m"),
        ({"robust_cells": -2}, "robust_cells"),
        ({"leg_wall_cost": float("nan")}, "leg_wall_cost"),
    ],
)
def test_bad_tour_params_name_the_bad_value(kwargs, words):
    with pytest.raises(ValueError, match=words):
        TourParams(**kwargs)


def test_row_counts_counts_set_columns_of_all_rows_or_the_rows_asked():
    from semexplore_gym.core.coverage_tour.viewpoints import row_counts

    rng = np.random.default_rng(3)
    dense = rng.random((40, 70)) < 0.2
    dense[5] = False  # an empty row
    m = sparse.csr_matrix(dense)
    flags = rng.random(70) < 0.5
    want = (dense & flags).sum(axis=1)
    assert np.array_equal(row_counts(flags, m.indptr, m.indices), want)
    rows = np.array([7, 5, 0, 7])
    assert np.array_equal(row_counts(flags, m.indptr, m.indices, rows), want[rows])


def test_shared_distance_fields_give_the_same_matrix():
    from semexplore_gym.core.coverage_tour.refine import GeodesicFields
    from semexplore_gym.core.coverage_tour.tour import geodesic_matrix
    from semexplore_gym.core.planning.grid_search import distance_field

    standing = np.ones((30, 40), dtype=bool)
    standing[10, 5:38] = False  # a wall with a gap at each end
    geo = GridGeometry(0.05, 0.0, 0.0, 30, 40)
    cost = np.where(standing, 0.05, np.inf)
    cells = np.array([[2, 3], [25, 30], [2, 35], [28, 1]])
    fields = GeodesicFields(cost)
    assert fields.kept((2, 3)) is None
    assert np.array_equal(fields.field((2, 3)), distance_field(cost, (2, 3))[0])
    assert fields.kept((2, 3)) is not None and fields.field((25, 30)) is not None
    assert np.array_equal(
        geodesic_matrix(standing, geo, cells, fields), geodesic_matrix(standing, geo, cells)
    )


def test_the_predicted_drive_counts_leg_scans_and_stops_at_the_leg_that_completes_the_need(
    privileged_world,
):
    # The comb again: driving the spine to its far end sees into every tooth on the way.
    from semexplore_gym.core.coverage_tour.refine import predicted_drive_m

    rects = [(0.0, 0.0, 6.0, 0.6)] + [(x, 0.6, x + 0.6, 1.8) for x in (0.9, 2.1, 3.3, 4.5)]
    facts = _facts(privileged_world, rects, (6.0, 1.8), (0.3, 0.3, 0.0))
    tour = plan_coverage_tour(facts, TourParams(robust_cells=0))
    assert tour.legs is not None
    geo = facts.geometry
    start = np.array([geo.world_to_grid(0.3, 0.3)], dtype=np.int64).reshape(1, 2)
    route = np.vstack([start, tour.viewpoints_rc])
    legs_m = tour.leg_lengths_m
    unseen = np.ones(tour.mask_flat.size, dtype=bool)
    total = int(tour.seen.sum())
    # Nothing needed: no drive. The whole route's count is what the tour counts as seen
    # (less the start scan, which is not in the route's scans here).
    assert predicted_drive_m(tour.legs, route, legs_m, unseen, 0) == (True, 0.0, 0)
    reached, drive_m, seen = predicted_drive_m(tour.legs, route, legs_m, unseen, total + 1)
    assert not reached and drive_m == pytest.approx(legs_m.sum()) and seen <= total
    # More needed never means a shorter drive; what is counted is whole legs.
    drives = []
    for share in (0.2, 0.5, 0.8, 0.95):
        reached, drive_m, seen = predicted_drive_m(
            tour.legs, route, legs_m, unseen, int(share * seen)
        )
        assert reached
        drives.append(drive_m)
        assert any(drive_m == pytest.approx(c) for c in np.cumsum(legs_m))
    assert drives == sorted(drives)
    # Cells already seen do not count: with what the first leg and its viewpoint see marked
    # seen, one more cell takes a longer drive than the first leg.
    a, b = (int(route[0, 0]), int(route[0, 1])), (int(route[1, 0]), int(route[1, 1]))
    first = np.union1d(tour.legs.leg(a, b), tour.legs.cells(route[1:2])[0])
    later = unseen.copy()
    later[first] = False
    assert len(route) > 2 and later.sum() > 0
    r1, d1, s1 = predicted_drive_m(tour.legs, route, legs_m, later, 1)
    assert r1 and s1 >= 1 and d1 > legs_m[0]


def _ring(privileged_world):
    """A 5.05 m square room round a 2.55 m block, symmetric about the row through its middle:
    from the middle of the west corridor to the middle of the east one, the ways north and
    south of the block cost the same."""
    s, w = 5.05, 1.25
    rects = [(0.0, 0.0, s, w), (0.0, s - w, s, s), (0.0, 0.0, w, s), (s - w, 0.0, s, s)]
    facts = _facts(privileged_world, rects, (s, s), (0.625, 2.525, 0.0))
    geo = facts.geometry
    west = tuple(int(v) for v in geo.world_to_grid(0.625, 2.525))
    east = tuple(int(v) for v in geo.world_to_grid(s - 0.625, 2.525))
    return facts, west, east


def test_a_leg_is_one_path_whichever_way_it_is_driven(privileged_world):
    from semexplore_gym.core.planning.grid_search import shortest_path_cells

    facts, west, east = _ring(privileged_world)
    tour = plan_coverage_tour(facts, TourParams(robust_cells=0))
    legs = tour.legs
    assert legs is not None
    there, back = legs.path(west, east), legs.path(east, west)
    assert there is not None and back is not None
    assert tuple(there[0]) == west and tuple(there[-1]) == east
    np.testing.assert_array_equal(there, back[::-1])
    np.testing.assert_array_equal(legs.leg(west, east), legs.leg(east, west))
    # The two ways tie: the leg takes one; a search from two cells towards the other side of
    # the block takes the other, which is why the oracle drives the leg itself.
    side = np.sign(there[:, 0].mean() - west[0])
    assert side != 0
    beside = (west[0] - int(side) * 2, west[1])
    other = shortest_path_cells(legs._cost, beside, east)
    assert other is not None
    assert np.sign(other[0][:, 0].mean() - west[0]) == -side
