"""Algorithm 1's goal driven over the grid's route (the semantic source's ``grid_route``
variant, today's recipe's): the goal and its
cost stay Algorithm 1's, the path is the grid's clearance-aware route instead of the map's."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from semexplore_gym.core.grid import FREE, OCCUPIED, GridGeometry

RES_M = 0.05
ROBOT_XY_M = (1.0, 1.5)
GOAL_XY_M = (4.0, 1.5)
#: The map's path (a stand-in for the skeleton's): up by a wall and back down, 3.84 m long.
MAP_PATH_M = np.array([ROBOT_XY_M, (2.5, 2.7), GOAL_XY_M])


def _room() -> tuple[np.ndarray, GridGeometry]:
    """A 3 m x 5 m free room walled all round."""
    grid = np.full((60, 100), FREE, dtype=np.uint8)
    grid[:2, :] = grid[-2:, :] = OCCUPIED
    grid[:, :2] = grid[:, -2:] = OCCUPIED
    return grid, GridGeometry(RES_M, 0.0, 0.0, 60, 100)


def _context(plan_context, grid: np.ndarray, geometry: GridGeometry, goal_xy_m=GOAL_XY_M):
    from semexplore_gym.policies.expert.params import SemanticExpertParams

    prm = SemanticExpertParams()
    path = MAP_PATH_M.copy()
    path[-1] = goal_xy_m
    chosen = SimpleNamespace(goal_xy_m=goal_xy_m, path_m=path, l_path_m=4.0, cost=0.5)
    return plan_context(grid, geometry, prm, (*ROBOT_XY_M, 0.0), [chosen])


def _length_m(path: np.ndarray) -> float:
    return float(np.hypot(*np.diff(path, axis=0).T).sum())


def _propose(ctx, grid_route: bool = True):
    from semexplore_gym.policies.expert.plan_sources import SemanticFrontier

    return SemanticFrontier(grid_candidate=False, grid_route=grid_route).propose(ctx)


def test_the_goal_is_driven_to_over_the_grids_route(plan_context) -> None:
    from semexplore_gym.policies.expert.plan import PlanKind

    ctx = _context(plan_context, *_room())
    plan = _propose(ctx)
    assert plan.kind == PlanKind.SEMANTIC and plan.goal_xy_m == GOAL_XY_M
    assert plan.candidate is ctx.candidates[0]  # Algorithm 1's choice, its cost untouched
    assert _length_m(plan.path_m) < 3.3 < _length_m(MAP_PATH_M)  # straight across: about 3 m
    assert np.allclose(plan.path_m[0], ROBOT_XY_M, atol=0.05)
    assert np.hypot(*(plan.path_m[-1] - GOAL_XY_M)) <= 0.15 + 1e-9  # the grid route's reach
    assert np.abs(plan.path_m[:, 1] - 1.5).max() < 0.2  # never up by the wall
    assert ctx.counts.semantic_grid_routes == 1


def test_without_it_the_maps_path_is_driven(plan_context) -> None:
    ctx = _context(plan_context, *_room())
    plan = _propose(ctx, grid_route=False)
    assert _length_m(plan.path_m) == pytest.approx(_length_m(MAP_PATH_M), abs=0.05)
    assert plan.path_m[:, 1].max() > 2.6
    assert ctx.counts.semantic_grid_routes == 0


def test_where_the_grid_has_no_route_the_maps_path_stands(plan_context) -> None:
    """A wall across the room, with a gap narrower than the planners' clearance: the grid
    finds no route, the map's path (which the segmentation drew) is driven as before."""
    grid, geometry = _room()
    grid[:, 70:72] = OCCUPIED  # at x = 3.5 m, past the map path's first leg
    grid[28:33, 70:72] = FREE  # a 0.25 m gap: under 2 x 0.155 m
    ctx = _context(plan_context, grid, geometry)
    plan = _propose(ctx)
    assert _length_m(plan.path_m) == pytest.approx(_length_m(MAP_PATH_M), abs=0.05)
    assert ctx.counts.semantic_grid_routes == 0


def test_todays_recipe_has_it_and_the_older_ones_do_not() -> None:
    from semexplore_gym.policies.expert.recipes import PAPER_METHOD, SEMANTIC_V2, SEMANTIC_V3

    routes = [r.semantic_source.grid_route for r in (SEMANTIC_V3, SEMANTIC_V2, PAPER_METHOD)]
    assert routes == [True, False, False]


def test_policies_measured_on_the_maps_paths_keep_them() -> None:
    """Teams, the learning agents' driver, the frontier student and the learned frontier value
    were trained and measured driving the map's paths: they keep them (the outside-choice
    recipe; a recipe or key with the route is refused: tests/policies/test_outside_choice.py)."""
    from semexplore_gym.policies.expert.driver import ExpertDriver
    from semexplore_gym.policies.frontier_student import FrontierStudentPolicy
    from semexplore_gym.policies.learned_frontier_value import FrontierValuePolicy
    from semexplore_gym.policies.team.semantic_team import SemanticTeam, _ExpertMember

    def route(pol) -> bool:
        return any(getattr(s, "grid_route", False) for s in pol.plan_sources)

    team = SemanticTeam()
    for pol in (
        ExpertDriver(),
        FrontierValuePolicy(),
        FrontierStudentPolicy(),
        _ExpertMember(team, 0, team.params.expert),
    ):
        assert not route(pol), type(pol).__name__


def test_in_a_maze_the_expert_drives_less_over_the_grids_routes(short_mission) -> None:
    """An 8 m maze (a tuning world of the path decomposition): the same goals, shorter drives."""
    from semexplore_gym.policies.expert.expert import SemanticExpertPolicy
    from semexplore_gym.policies.expert.recipes import SEMANTIC_V3

    world = "maze:seed=61001,size_m=8,braid=0.3"
    new, p_new = short_mission(world, "semantic", 5000, 1200)
    without = SemanticExpertPolicy(recipe=SEMANTIC_V3.with_semantic(grid_route=False))
    old, p_old = short_mission(world, without, 5000, 1200)
    assert p_new.counters["semantic_grid_routes"] > 0
    assert p_old.counters["semantic_grid_routes"] == 0
    assert new.self_stopped and new.coverage >= 0.99 and new.collisions == 0
    assert new.path_length_m < 0.9 * old.path_length_m
    assert new.mission_time_s < old.mission_time_s
