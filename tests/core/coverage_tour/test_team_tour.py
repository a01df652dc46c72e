"""The team tour: the one-robot tour's viewpoints split into k routes of least makespan."""

from __future__ import annotations

import numpy as np
import pytest

from semexplore_gym.core.coverage_tour import plan_coverage_tour
from semexplore_gym.core.coverage_tour.team_tour import (
    TeamTourParams,
    plan_team_tour,
    route_length_m,
    split_order,
    split_routes,
    team_lower_bound_m,
)
from semexplore_gym.core.grid import GridGeometry
from semexplore_gym.core.worlds.build import world_from_free_mask

pytest.importorskip("elkai")
pytest.importorskip("ortools")

RES = 0.05


def _tree_facts(privileged_world):
    # A hub at (4, 4) with corridors 0.6 m wide: east and north 4 m, west 2.5 m from its centre;
    # a 1 m LiDAR sees each branch's end from 1 m before it.
    rects = [(3.7, 3.7, 8.0, 4.3), (3.7, 3.7, 4.3, 8.0), (1.5, 3.7, 4.3, 4.3)]
    h = w = int(round(8.0 / RES))
    free = np.zeros((h, w), dtype=bool)
    for x0, y0, x1, y1 in rects:
        free[
            int(round(y0 / RES)) : int(round(y1 / RES)), int(round(x0 / RES)) : int(round(x1 / RES))
        ] = True
    start = (4.0, 4.0, 0.0)
    world = world_from_free_mask("tree", free, GridGeometry(RES, 0.0, 0.0, h, w), start_pose=start)
    return privileged_world(world, start, 0.105, 1.0, RES)


def _comb_matrix(n_teeth: int, depth: float) -> np.ndarray:
    """A spine from the start (x = 0) with a tooth of ``depth`` at x = 1, 2, ...: node i is the
    end of tooth i; between two teeth the way runs down, along the spine and up."""
    xs = np.arange(n_teeth + 1, dtype=np.float64)
    ys = np.r_[0.0, np.full(n_teeth, depth)]
    d = np.abs(xs[:, None] - xs[None, :]) + ys[:, None] + ys[None, :]
    np.fill_diagonal(d, 0.0)
    return d


def test_one_robot_gets_the_one_robot_tour(privileged_world):
    facts = _tree_facts(privileged_world)
    tour = plan_coverage_tour(facts)
    team = plan_team_tour(tour, facts.geometry, [facts.start_pose[:2]], 1)
    assert team.routes == (tuple(range(tour.n_viewpoints)),)
    assert team.makespan_m == pytest.approx(tour.length_m, abs=1e-6)


def test_a_tree_of_three_corridors_gives_each_of_three_robots_one_branch(privileged_world):
    facts = _tree_facts(privileged_world)
    tour = plan_coverage_tour(facts)
    spans = [
        plan_team_tour(tour, facts.geometry, [facts.start_pose[:2]], k).makespan_m
        for k in (1, 2, 3)
    ]
    # k = 3: one branch each, the longest 4 - 1 m; k = 2: the short branch out and back and a
    # long one (2 x 1.5 + 3 m); the lattice and the cover's slack allow 0.6 m per branch driven.
    assert spans[2] == pytest.approx(3.0, abs=0.6)
    assert spans[1] == pytest.approx(6.0, abs=1.2)
    assert spans[0] >= spans[1] >= spans[2]


def test_the_comb_split_is_the_known_optimum_and_never_grows_with_k():
    d = _comb_matrix(8, 5.0)
    spans = [split_routes(d, k).makespan_m for k in range(1, 9)]
    assert all(a >= b - 1e-9 for a, b in zip(spans[:-1], spans[1:], strict=False))
    # Eight teeth, eight robots: each drives to its own tooth, the farthest is 8 + 5.
    assert spans[-1] == pytest.approx(13.0)
    # Four robots: two neighbouring teeth each (the last pair: 7 + 5 + 1 + 5 + 5 = 23).
    assert spans[3] == pytest.approx(23.0)


def test_the_solver_improves_a_poor_order_and_is_deterministic():
    rng = np.random.default_rng(3)
    pts = rng.uniform(0.0, 20.0, size=(30, 2))
    d = np.hypot(*(pts[:, None] - pts[None]).transpose(2, 0, 1))
    order = list(range(1, 30))
    cut = split_order(d, order, 3)
    a = split_routes(d, 3, order)
    b = split_routes(d, 3, order)
    assert a.routes == b.routes
    assert a.makespan_m < cut.makespan_m
    assert sorted(v for r in a.routes for v in r) == order
    assert a.makespan_m == pytest.approx(max(route_length_m(d, r) for r in a.routes))


def test_without_the_solver_the_split_of_the_order_is_kept():
    d = _comb_matrix(4, 2.0)
    got = split_routes(d, 2, params=TeamTourParams(use_solver=False))
    assert got.solver == "split"
    assert got.routes == ((1, 2), (3, 4))


@pytest.mark.parametrize(
    ("k", "match"),
    [(0, "integer >= 1"), (-2, "integer >= 1"), (5, "5 robots but only 4 viewpoint")],
)
def test_bad_team_sizes_say_what_is_wrong(k, match):
    with pytest.raises(ValueError, match=match):
        split_routes(_comb_matrix(4, 2.0), k)


def test_an_unreachable_viewpoint_is_refused():
    d = _comb_matrix(3, 2.0)
    d[0, 2] = d[2, 0] = np.inf
    with pytest.raises(ValueError, match="cannot be reached from the start"):
        split_routes(d, 2)


def test_the_team_lower_bound_is_the_larger_of_its_two_parts():
    assert team_lower_bound_m(30.0, 4.0, 1) == 30.0
    assert team_lower_bound_m(30.0, 4.0, 2) == pytest.approx(10.0)
    assert team_lower_bound_m(30.0, 12.0, 3) == 12.0
    assert team_lower_bound_m(30.0, 12.0, 3, starts_gap_m=1.0) == 11.0
    with pytest.raises(ValueError, match="robots must be >= 1"):
        team_lower_bound_m(30.0, 4.0, 0)


def test_robots_that_start_apart_take_the_routes_from_their_own_starts():
    # Robot 0 at the spine's start, robot 1 at the far end of the spine (x = 9): the far teeth
    # are robot 1's, whatever the common-start split would say.
    d = _comb_matrix(8, 5.0)
    own = np.zeros((2, 9))
    own[0, 1:] = d[0, 1:]
    own[1, 1:] = np.abs(9.0 - np.arange(1, 9)) + 5.0
    got = split_routes(d, 2, own_starts_m=own)
    assert set(got.routes[1]) >= {7, 8} and set(got.routes[0]) >= {1, 2}
    assert got.makespan_m == pytest.approx(max(got.lengths_m))
    assert got.makespan_m < split_routes(d, 2).makespan_m
    # The lengths count each robot's own way in.
    r1 = got.routes[1]
    assert got.lengths_m[1] == pytest.approx(own[1, r1[0]] + route_length_m(d, r1) - d[0, r1[0]])
