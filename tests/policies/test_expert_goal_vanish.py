"""When a goal's frontier counts as mapped: any UNKNOWN cell near the goal (``unknown_near``),
or, with the goal rule ``vanish_on_frontier`` (today's recipe's), only a frontier cell (UNKNOWN next to FREE: ``frontier_near``).
Unknown space behind a mapped wall is no frontier: no drive can map it from this side."""

from __future__ import annotations

import numpy as np

from semexplore_gym.core.grid import FREE, OCCUPIED, UNKNOWN, GridGeometry

RES_M = 0.05
GOAL_XY_M = (2.0, 1.2)  # 0.3 m below the wall at y = 1.5 m


def _walled_room(opening: bool) -> tuple[np.ndarray, GridGeometry]:
    """A 5 m x 1.5 m free room (y < 1.5 m) under a mapped wall; above it all is unknown. With
    ``opening``, a 0.4 m gap in the wall lets the unknown touch the room near the goal."""
    grid = np.full((60, 100), UNKNOWN, dtype=np.uint8)
    grid[2:30, 2:98] = FREE
    grid[30, :] = OCCUPIED
    grid[:2, :] = grid[:, :2] = grid[:, 98:] = OCCUPIED
    if opening:
        grid[30, 38:46] = FREE
    return grid, GridGeometry(RES_M, 0.0, 0.0, 60, 100)


def test_unknown_behind_a_wall_is_no_frontier() -> None:
    from semexplore_gym.policies.expert.plan_context import frontier_near, unknown_near

    grid, geometry = _walled_room(opening=False)
    assert unknown_near(grid, geometry, GOAL_XY_M, 0.5)  # the box reaches across the wall
    assert not frontier_near(grid, geometry, GOAL_XY_M, 0.5)  # but no unknown cell touches FREE
    grid, geometry = _walled_room(opening=True)
    assert frontier_near(grid, geometry, GOAL_XY_M, 0.5)  # the gap's unknown side is a frontier
    assert not frontier_near(grid, geometry, (2.0, 0.7), 0.5)  # the box ends short of the gap
    assert frontier_near(grid, geometry, (0.1, 0.5), 0.5)  # a box past the map's edge: unknown


def _committed_fallback_keeps(grid: np.ndarray, geometry: GridGeometry, **rules) -> bool:
    from semexplore_gym.policies.expert.counters import ExpertCounters
    from semexplore_gym.policies.expert.goal_memory import GoalMemory, GoalRules
    from semexplore_gym.policies.expert.params import SemanticExpertParams
    from semexplore_gym.policies.expert.plan import Plan, PlanKind
    from semexplore_gym.policies.expert.plan_context import PlanContext
    from semexplore_gym.policies.expert.plan_sources import CommittedFallback

    prm = SemanticExpertParams()
    counts = ExpertCounters()
    memory = GoalMemory(prm.goal_memory, counts, lambda *_: None, GoalRules(**rules))
    memory.reset(geometry, prm.goal_memory)
    old = Plan(PlanKind.FALLBACK, GOAL_XY_M, np.array([(0.5, 0.5), GOAL_XY_M]))
    ctx = PlanContext(
        grid=grid,
        pose=(0.5, 0.5, 0.0),
        geometry=geometry,
        params=prm,
        clearance_m=0.155,
        robot_radius_m=0.105,
        candidates=[],
        current=old,
        memory=memory,
        counts=counts,
        choose_goal=lambda cands: cands[0],
        log=lambda *_: None,
    )
    plan = CommittedFallback().propose(ctx)
    return plan is not None and plan.goal_xy_m == GOAL_XY_M


def test_the_committed_fallback_lets_a_goal_go_once_its_frontier_is_mapped() -> None:
    walled = _walled_room(opening=False)
    assert _committed_fallback_keeps(*walled, vanish_on_frontier=False)  # unknown across a wall
    assert not _committed_fallback_keeps(*walled, vanish_on_frontier=True)
    gap = _walled_room(opening=True)  # a real frontier near the goal: kept by both rules
    assert _committed_fallback_keeps(*gap, vanish_on_frontier=False)
    assert _committed_fallback_keeps(*gap, vanish_on_frontier=True)


def _thick_walled_rooms() -> np.ndarray:
    """Map pixels (0.05 m; 0 wall, 254 free): two rooms behind 0.4 m thick walls, a 1 m door
    between them, thick half-walls making alcoves. A wall's inside is never seen."""
    img = np.zeros((100, 160), dtype=np.uint8)
    img[8:92, 8:152] = 254
    img[8:92, 76:84] = 0
    img[40:60, 76:84] = 254
    img[8:40, 40:48] = 0
    img[60:92, 112:120] = 0
    return img


def test_by_thick_walls_goals_are_let_go_once_their_frontier_is_mapped(
    ros_map_file, short_mission
) -> None:
    from semexplore_gym.policies.expert.expert import SemanticExpertPolicy
    from semexplore_gym.policies.expert.recipes import SEMANTIC_V3

    world = ros_map_file(_thick_walled_rooms(), "thick_rooms")
    # the expert of that time (a later change off), so that this tests one change
    then = SEMANTIC_V3.with_semantic(grid_route=False)
    new, p_new = short_mission(world, SemanticExpertPolicy(recipe=then), 0, 300)
    before = then.with_rules(vanish_on_frontier=False)
    old, p_old = short_mission(world, SemanticExpertPolicy(recipe=before), 0, 300)
    assert p_new.goal_memory.rules.vanish_on_frontier
    assert not p_old.goal_memory.rules.vanish_on_frontier
    # the unknown inside the walls kept a goal alive until the robot reached it
    assert p_new.counters["replan_goal_vanished"] > p_old.counters["replan_goal_vanished"]
    assert p_new.counters["replan_goal_reached"] < p_old.counters["replan_goal_reached"]
    assert new.path_length_m < old.path_length_m
    assert new.self_stopped and new.coverage >= old.coverage >= 0.99
    assert new.collisions == old.collisions == 0
