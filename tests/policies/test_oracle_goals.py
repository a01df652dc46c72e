"""The oracle's goals off its tour: a second look where a viewpoint's scan fell short, a
shortcut to the goal, and what to see once the tour is done."""

from __future__ import annotations

import numpy as np
import pytest
from semexplore_gym.policies.oracle_goals import fallback_cell, repair_cell, shortcut_cell

from semexplore_gym.core.coverage_tour import plan_coverage_tour
from semexplore_gym.core.coverage_tour.tour import row_counts
from semexplore_gym.core.grid import GridGeometry
from semexplore_gym.core.planning.grid_search import distance_field
from semexplore_gym.core.worlds.build import world_from_free_mask

pytest.importorskip("elkai")


@pytest.fixture
def tour(privileged_world):
    # An L of 0.6 m corridors, 5 m each way, a 1 m LiDAR.
    res = 0.05
    free = np.zeros((120, 120), dtype=bool)
    free[10:22, 10:110] = True
    free[10:110, 10:22] = True
    geo = GridGeometry(res, 0.0, 0.0, 120, 120)
    start = (0.8, 0.8, 0.0)
    world = world_from_free_mask("l", free, geo, start_pose=start)
    return plan_coverage_tour(privileged_world(world, start, 0.105, 1.0, res))


def _field_from(tour, rc):
    cost = np.where(tour.standing, 0.05, np.inf)
    return distance_field(cost, rc)[0]


def test_a_viewpoint_whose_scan_fell_short_gets_a_second_look_nearby(tour):
    vp = 0
    rc = tuple(int(v) for v in tour.viewpoints_rc[vp])
    unseen = np.ones(tour.mask_flat.size, dtype=bool)  # the scan there saw nothing
    got = repair_cell(tour, unseen, vp, [], lambda: _field_from(tour, rc), (10, 1.0))
    assert got is not None and _field_from(tour, rc)[got] <= 1.0
    row = tour.candidate_visible[int(np.flatnonzero((tour.candidates_rc == got).all(1))[0])]
    assert row_counts(unseen, row.indptr, row.indices)[0] >= 10
    # Nothing missed, or what was missed a viewpoint left will see: no second look.
    seen = np.zeros_like(unseen)
    assert repair_cell(tour, seen, vp, [], lambda: _field_from(tour, rc), (10, 1.0)) is None
    assert repair_cell(tour, unseen, vp, [vp], lambda: _field_from(tour, rc), (10, 1.0)) is None


def test_a_shortcut_is_taken_only_when_nearer_than_the_rest_of_the_tour(tour):
    start = tuple(int(v) for v in tour.viewpoints_rc[0])
    field = _field_from(tour, start)
    unseen = np.zeros(tour.mask_flat.size, dtype=bool)
    unseen[tour.visible[tour.n_viewpoints - 1].indices] = True  # only the last view is left
    left = list(range(tour.n_viewpoints))
    assert shortcut_cell(tour, unseen, 0, left, lambda: field, 1.5) is None  # goal reached
    need = 5
    got = shortcut_cell(tour, unseen, need, [], lambda: field, 1.5)  # no tour left: any
    assert got is not None
    row = tour.candidate_visible[int(np.flatnonzero((tour.candidates_rc == got).all(1))[0])]
    assert row_counts(unseen, row.indptr, row.indices)[0] >= 1.5 * need
    # At the last viewpoint itself the rest of the tour costs nothing: no shortcut beats it.
    last = tuple(int(v) for v in tour.viewpoints_rc[-1])
    at_last = _field_from(tour, last)
    assert shortcut_cell(tour, unseen, need, [tour.n_viewpoints - 1], lambda: at_last, 1.5) is None
    huge = int(unseen.sum()) + 1
    assert shortcut_cell(tour, unseen, huge, [], lambda: field, 1.5) is None


def test_after_the_tour_the_nearest_candidate_that_alone_reaches_the_goal(tour):
    field = _field_from(tour, tuple(int(v) for v in tour.viewpoints_rc[0]))
    unseen = np.ones(tour.mask_flat.size, dtype=bool)
    got = fallback_cell(tour, unseen, 10, set(), field, 1)
    assert got is not None
    assert fallback_cell(tour, unseen, 10, {got}, field, 1) != got  # never one tried
    assert fallback_cell(tour, np.zeros_like(unseen), 10, set(), field, 1) is None
