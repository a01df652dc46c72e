"""The grid's nearest frontier competes with Algorithm 1's choice (the semantic source's
``grid_candidate`` variant, today's recipe's): scored by the same ``C`` without semantic terms."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from semexplore_gym.core.grid import FREE, OCCUPIED, UNKNOWN, GridGeometry

RES_M = 0.05
ROBOT_XY_M = (1.0, 1.5)


def _corridor() -> tuple[np.ndarray, GridGeometry]:
    """A 3 m x 5 m free room walled on three sides; its last 0.5 m (x > 4.5 m) is unseen."""
    grid = np.full((60, 100), FREE, dtype=np.uint8)
    grid[:2, :] = grid[-2:, :] = OCCUPIED
    grid[:, :2] = OCCUPIED
    grid[2:-2, 90:] = UNKNOWN
    return grid, GridGeometry(RES_M, 0.0, 0.0, 60, 100)


def _context(plan_context, chosen_cost: float, goal_xy_m=(0.2, 1.5), **params):
    from semexplore_gym.policies.expert.params import SemanticExpertParams

    grid, geometry = _corridor()
    prm = SemanticExpertParams(**params)
    # Algorithm 1's choice (stand-in): by default a goal 0.8 m behind the robot, L_path 2 m.
    chosen = SimpleNamespace(
        goal_xy_m=goal_xy_m,
        path_m=np.array([ROBOT_XY_M, goal_xy_m]),
        l_path_m=2.0,
        cost=chosen_cost,
    )
    # heading +x, toward the unseen end
    return plan_context(grid, geometry, prm, (*ROBOT_XY_M, 0.0), [chosen])


def _propose(ctx, **variant):
    from semexplore_gym.policies.expert.plan_sources import SemanticFrontier

    return SemanticFrontier(**variant).propose(ctx)


def test_a_cheaper_grid_frontier_replaces_algorithm_1s_choice(plan_context) -> None:
    from semexplore_gym.policies.expert.plan import PlanKind

    # The unseen end is about 3.4 m ahead: C = 3.4 / 2 + w_v * 0 = 1.7 < 5.
    ctx = _context(plan_context, chosen_cost=5.0)
    plan = _propose(ctx)
    assert plan.kind == PlanKind.FALLBACK
    assert plan.goal_xy_m[0] > 4.3  # next to the unseen end
    assert ctx.counts.grid_frontier_plans == 1


@pytest.mark.parametrize("chosen_cost", [1.0, 1.6])
def test_algorithm_1s_choice_stands_when_the_grid_frontier_is_not_cheaper(
    plan_context,
    chosen_cost: float,
) -> None:
    from semexplore_gym.policies.expert.plan import PlanKind

    ctx = _context(plan_context, chosen_cost=chosen_cost)  # the grid frontier costs about 1.7
    plan = _propose(ctx)
    assert plan.kind == PlanKind.SEMANTIC and plan.goal_xy_m == (0.2, 1.5)
    assert ctx.counts.grid_frontier_plans == 0


def test_a_grid_frontier_next_to_algorithm_1s_goal_is_the_same_goal(plan_context) -> None:
    from semexplore_gym.policies.expert.plan import PlanKind

    ctx = _context(
        plan_context, chosen_cost=5.0, goal_xy_m=(4.0, 1.8)
    )  # within 1 m of the grid's goal
    assert _propose(ctx).kind == PlanKind.SEMANTIC
    assert ctx.counts.grid_frontier_plans == 0


def test_the_paper_method_and_semantic_v2_leave_algorithm_1_alone(plan_context) -> None:
    from semexplore_gym.policies.expert.plan import PlanKind
    from semexplore_gym.policies.expert.recipes import PAPER_METHOD, SEMANTIC_V2

    for recipe in (PAPER_METHOD, SEMANTIC_V2):
        assert recipe.semantic_source is not None and not recipe.semantic_source.grid_candidate
    ctx = _context(plan_context, chosen_cost=5.0)
    assert _propose(ctx, grid_candidate=False).kind == PlanKind.SEMANTIC
    assert ctx.counts.grid_frontier_plans == 0


def test_in_a_maze_the_expert_explores_what_it_passes_and_drives_less(short_mission) -> None:
    """An 8 m maze (a tuning world): the frontiers Algorithm 1 leaves behind are taken on the way."""
    from semexplore_gym.policies.expert.expert import SemanticExpertPolicy
    from semexplore_gym.policies.expert.recipes import SEMANTIC_V3

    world = "maze:seed=61001,size_m=8,braid=0.3"
    # the expert of that time (a later goal rule off), so that this tests one change
    then = SEMANTIC_V3.with_rules(vanish_on_frontier=False)
    without = then.with_semantic(grid_candidate=False)
    new, p_new = short_mission(world, SemanticExpertPolicy(recipe=then), 5000, 1200)
    old, p_old = short_mission(world, SemanticExpertPolicy(recipe=without), 5000, 1200)
    assert p_new.counters["grid_frontier_plans"] > 0
    assert p_old.counters["grid_frontier_plans"] == 0
    assert new.self_stopped and new.coverage >= 0.99 and new.collisions == 0
    assert new.path_length_m < 0.9 * old.path_length_m


def test_policies_that_choose_the_frontier_themselves_run_without_it() -> None:
    """Teams, the learning agents' driver and the learned frontier value make the choice: the
    grid's nearest frontier never overrules it. They run the outside-choice recipe, and refuse
    a recipe or key with it (tests/policies/test_outside_choice.py)."""
    from semexplore_gym.policies.expert.driver import ExpertDriver
    from semexplore_gym.policies.expert.expert import SemanticExpertPolicy
    from semexplore_gym.policies.learned_frontier_value import FrontierValuePolicy
    from semexplore_gym.policies.team.semantic_team import SemanticTeam, _ExpertMember

    def candidate(pol) -> bool:
        return any(getattr(s, "grid_candidate", False) for s in pol.plan_sources)

    assert candidate(SemanticExpertPolicy())  # the robust expert's default
    assert not candidate(ExpertDriver())
    assert not candidate(FrontierValuePolicy())
    team = SemanticTeam()
    assert not candidate(_ExpertMember(team, 0, team.params.expert))


def test_the_goal_the_shuttle_guard_holds_is_kept_against_the_grid_frontier(
    plan_context,
) -> None:
    """A goal adopted again without progress is seen through: the grid's frontier does not
    take turns with it (else the two sources shuttle, as on a real SLAM map for 2,000 s)."""
    from semexplore_gym.policies.expert.plan import PlanKind

    ctx = _context(plan_context, chosen_cost=5.0)  # the grid's is cheaper
    ctx.memory.shuttle_xy_m = (0.2, 1.5)  # the shuttle guard holds Algorithm 1's goal
    plan = _propose(ctx)
    assert plan.kind == PlanKind.SEMANTIC
    assert ctx.counts.grid_frontier_plans == 0
    ctx = _context(
        plan_context, chosen_cost=5.0
    )  # the guard holds another goal: the grid's frontier wins
    ctx.memory.shuttle_xy_m = (3.0, 0.5)
    assert _propose(ctx).kind == PlanKind.FALLBACK
