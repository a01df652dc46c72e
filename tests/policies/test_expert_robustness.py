"""The expert never gives up on a reachable frontier (#13): winding passages, sealed-off and
narrow-at-first-sight frontiers, retries, dropped goals that come back, the paper-pure preset."""

from __future__ import annotations

import math
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest
from semexplore_gym.policies.expert.expert import SemanticExpertParams, SemanticExpertPolicy
from semexplore_gym.policies.expert.recipes import PAPER_METHOD, PAPER_PARAMS, SEMANTIC_V3
from semexplore_gym.policies.navigation.frontier_memory import FrontierMemory
from semexplore_gym.policies.navigation.side_approach import side_approach
from semexplore_gym.policies.registry import make_policy

import semexplore_gym  # noqa: F401
from semexplore_gym.config import build_params
from semexplore_gym.core.frontiers.reachable import clearance_field_m, pocket_exit_path
from semexplore_gym.core.grid import FREE, OCCUPIED, UNKNOWN, GridGeometry
from semexplore_gym.core.worlds.build import world_from_free_mask
from semexplore_gym.evaluation.rollout import run_mission

RES = 0.05
REPO = Path(__file__).resolve().parents[2]


def _world(name: str, size_m: tuple[float, float], rects: list, start: tuple) -> object:
    """A raster world: free rectangles ``(x0, y0, x1, y1)`` in metres on a 0.05 m grid."""
    h, w = int(round(size_m[1] / RES)), int(round(size_m[0] / RES))
    free = np.zeros((h, w), dtype=bool)
    for x0, y0, x1, y1 in rects:
        free[
            int(round(y0 / RES)) : int(round(y1 / RES)), int(round(x0 / RES)) : int(round(x1 / RES))
        ] = True
    return world_from_free_mask(name, free, GridGeometry(RES, 0.0, 0.0, h, w), start_pose=start)


def _mission(world: object, policy: SemanticExpertPolicy, max_time_s: float = 900.0):
    env = gym.make("SemanticExplore-v0", world=world)
    try:
        return run_mission(
            env, policy, seed=0, max_time_s=max_time_s, progress=False, ignore_terminated=True
        )
    finally:
        env.close()


def test_a_frontier_behind_a_winding_passage_is_reached() -> None:
    # Two rooms joined by an S-shaped passage 0.5 m wide with four turns.
    rects = [
        (0.3, 0.3, 1.8, 3.7),  # room A (start)
        (1.8, 0.3, 2.6, 0.8),
        (2.1, 0.3, 2.6, 3.4),
        (2.1, 2.9, 3.6, 3.4),
        (3.1, 0.6, 3.6, 3.4),
        (3.1, 0.6, 4.3, 1.1),
        (4.2, 0.3, 5.7, 3.7),  # room B, seen only through the passage
    ]
    world = _world("winding", (6.0, 4.0), rects, (1.0, 2.0, 0.0))
    res = _mission(world, SemanticExpertPolicy())
    assert res.self_stopped, res.stop_reason
    assert res.coverage >= 0.97, (res.coverage, res.stop_reason)
    assert res.collisions == 0
    assert max(x for x, _y, _t in res.trajectory) > 4.3  # it drove into room B


def test_a_sealed_off_frontier_ends_the_mission_by_the_grid_check() -> None:
    # Room B lies behind a 0.1 m slit the LiDAR sees through but no robot passes.
    rects = [(0.3, 0.3, 2.8, 2.7), (2.8, 1.45, 3.0, 1.55), (3.0, 0.3, 5.7, 2.7)]
    world = _world("sealed", (6.0, 3.0), rects, (1.0, 1.5, 0.0))
    pol = SemanticExpertPolicy()
    res = _mission(world, pol)
    assert res.self_stopped, res.stop_reason
    assert "grid check: none reachable" in res.stop_reason
    assert res.coverage >= 0.97  # of the reachable area: room A
    assert max(x for x, _y, _t in res.trajectory) < 2.8
    # A slit even a robot of half the clearance cannot pass is no gap worth a look.
    assert pol.counters["look_drives"] == 0


GEOM = GridGeometry(RES, 0.0, 0.0, 60, 100)  # 5 m x 3 m
INFO = {
    "map_geometry": GEOM.to_dict(),
    "robot": {"radius_m": 0.105, "max_linear_speed_mps": 0.22, "max_angular_speed_radps": 2.84},
    "lidar": {"n_beams": 360, "min_range_m": 0.12, "max_range_m": 3.5},
    "dt_s": 0.2,
}


def _two_rooms(gap_m: float) -> np.ndarray:
    """Room A known (x < 2.4 m), a wall at x 2.4-2.5 m with a gap of ``gap_m`` at y = 1.5 m,
    unknown beyond: a frontier in the gap."""
    g = np.full(GEOM.shape, UNKNOWN, dtype=np.uint8)
    g[:, :50] = OCCUPIED
    g[4:56, 4:48] = FREE
    half = int(round(gap_m / RES / 2))
    g[30 - half : 30 + half, 48:51] = FREE
    return g


def _empty_tmap(grid: np.ndarray, *_: object, **__: object) -> object:
    from semexplore_gym.core.topometric.types import TopometricMap

    return TopometricMap(GEOM, np.full(grid.shape, -1, np.int32), {}, [], [], [], math.nan, 0.155)


def _obs(grid: np.ndarray, x: float, y: float) -> dict[str, np.ndarray]:
    return {
        "map": grid,
        "pose": np.array([x, y, 0.0], dtype=np.float32),
        "scan": np.full(360, 3.5, dtype=np.float32),
    }


def test_a_narrow_at_first_sight_opening_gets_a_closer_look_then_is_explored() -> None:
    pol = SemanticExpertPolicy(segmenter=_empty_tmap)
    # 0.2 m: too narrow for the robot's 0.31 m, first seen from 2.2 m away (farther than
    # look_seen_radius_m, so it has not had its closer look yet).
    narrow = _obs(_two_rooms(0.2), 0.3, 1.5)
    pol.reset(narrow, INFO, seed=0)
    pol.act(narrow, INFO)
    assert pol.plan_source == "look" and not pol.done
    goal = pol.goal_xy_m
    assert goal is not None and math.dist(goal, (2.45, 1.5)) <= 1.0 + 0.2
    # Seen from close by the opening is wider than it looked: the grid reaches through it.
    wide = _obs(_two_rooms(0.6), goal[0], goal[1])
    pol.request_replan()
    pol.act(wide, INFO)
    assert pol.plan_source == "fallback" and pol.goal_xy_m[0] > 2.3
    # Had it stayed narrow, reaching the look point drops it as looked-at and the mission ends
    # (with the view of unseen frontiers off; on, a place that sees through the gap comes first).
    no_view = SEMANTIC_V3.with_rules(view_unseen_frontiers=False).without("view")
    for view in (False, True):
        recipe = SEMANTIC_V3 if view else no_view
        pol2 = SemanticExpertPolicy(segmenter=_empty_tmap, recipe=recipe)
        pol2.reset(narrow, INFO, seed=0)
        pol2.act(narrow, INFO)
        at_goal = _obs(_two_rooms(0.2), *pol2.goal_xy_m)
        for _ in range(5):
            pol2.act(at_goal, INFO)
            if pol2.done or pol2.plan_source == "view":
                break
        if view:
            assert pol2.plan_source == "view" and pol2.counters["view_drives"] == 1
        else:
            assert pol2.done and "looked at" in pol2.stop_reason


def test_a_failed_goal_is_retried_by_other_approaches_before_it_is_dropped() -> None:
    prm = SemanticExpertParams(stuck_timeout_s=1.0, backoff_duration_s=0.4, local_min_timeout_s=99)
    pol = SemanticExpertPolicy(prm, segmenter=_empty_tmap)
    obs = _obs(_two_rooms(0.6), 0.6, 1.5)
    pol.reset(obs, INFO, seed=0)
    sources = []
    for _ in range(300):  # the pose never changes: every approach gets stuck
        pol.act(obs, INFO)
        sources.append(pol.plan_source)
        if pol.done:
            break
    assert pol.counters["retries"] == prm.max_goal_attempts - 1
    assert "retry" in sources
    assert pol.done and f"failed {prm.max_goal_attempts} approaches" in pol.stop_reason


def _pocket_and_room() -> np.ndarray:
    """A pocket (x 0.2-0.8 m) joined to a room (x 1.5-3.55 m, unknown beyond) by a passage
    whose middle row is 0.15 m from its walls: passable for the robot (radius 0.105 m), but
    narrower than the planner's clearance (0.155 m)."""
    g = np.full(GEOM.shape, OCCUPIED, dtype=np.uint8)
    g[24:36, 4:16] = FREE  # the pocket
    g[28:33, 16:30] = FREE  # the passage: walls at rows 27 and 33
    g[4:56, 30:71] = FREE  # the room
    g[4:56, 71:96] = UNKNOWN  # unexplored: the room's frontier at x = 3.5 m
    return g


def test_the_grid_check_leads_out_of_a_pocket_instead_of_stopping() -> None:
    grid = _pocket_and_room()
    in_pocket = _obs(grid, 0.525, 1.525)
    way_out = pocket_exit_path(grid, GEOM, (0.525, 1.525), 0.155, 0.13, 0.1)
    assert way_out is not None and 1.5 <= way_out[-1][0] <= 1.6  # the room's first usable cell
    assert pocket_exit_path(grid, GEOM, (0.525, 1.525), 0.155, 0.155, 0.1) is None  # too thin
    assert pocket_exit_path(grid, GEOM, (2.5, 1.5), 0.155, 0.13, 0.1) is None  # not a pocket
    pol = SemanticExpertPolicy(segmenter=_empty_tmap)
    pol.reset(in_pocket, INFO, seed=0)
    pol.act(in_pocket, INFO)
    assert pol.plan_source == "fallback" and not pol.done
    assert pol.counters["pocket_escapes"] == 1
    assert pol.goal_xy_m[0] > 3.3  # at the room's frontier
    assert any(e == "pocket" for _t, e, _d in pol.events)
    # Without the escape the room beyond the pocket's gap, which the map shows with its
    # frontier, still leads out (at the narrow tier's clearance) ...
    no_escape = SEMANTIC_V3.without("pocket_escape")
    room = SemanticExpertPolicy(segmenter=_empty_tmap, recipe=no_escape)
    room.reset(in_pocket, INFO, seed=0)
    room.act(in_pocket, INFO)
    assert room.plan_source == "fallback" and room.goal_xy_m[0] > 3.3
    assert room.counters["pocket_escapes"] == 0 and room.counters["narrow_plans"] == 1
    assert any(e == "room" for _t, e, _d in room.events)
    # ... and without both the check sees only the pocket: no fallback goal (a look, a stop).
    no_way = no_escape.without("room_beyond_gap")
    off = SemanticExpertPolicy(segmenter=_empty_tmap, recipe=no_way)
    off.reset(in_pocket, INFO, seed=0)
    for _ in range(20):
        off.act(in_pocket, INFO)
        assert off.plan_source != "fallback"
        if off.done:
            break
    assert off.done and "grid check: none reachable" in off.stop_reason
    # From the room itself nothing changes: the usual check finds the frontier.
    in_room = _obs(grid, 2.0, 1.5)
    pol2 = SemanticExpertPolicy(segmenter=_empty_tmap)
    pol2.reset(in_room, INFO, seed=0)
    pol2.act(in_room, INFO)
    assert pol2.plan_source == "fallback" and pol2.counters["pocket_escapes"] == 0
    # A pocket with no frontier beyond its passage: the escape finds nothing, the mission ends.
    sealed = grid.copy()
    sealed[sealed == UNKNOWN] = OCCUPIED
    done = _obs(sealed, 0.525, 1.525)
    pol3 = SemanticExpertPolicy(segmenter=_empty_tmap)
    pol3.reset(done, INFO, seed=0)
    for _ in range(5):
        pol3.act(done, INFO)
    assert pol3.done and pol3.counters["pocket_escapes"] == 0


def test_pocket_parameters_are_checked() -> None:
    with pytest.raises(ValueError, match="pocket_max_share"):
        SemanticExpertParams(pocket_max_share=1.5)
    with pytest.raises(ValueError, match="pocket_clearance_margin_m"):
        SemanticExpertParams(pocket_clearance_margin_m=-0.01)


def test_frontier_memory_drops_revives_and_caps_revivals() -> None:
    grid = _two_rooms(0.6)
    mem = FrontierMemory(0.5, 0.75, 40, max_revivals=1, max_attempts=3)
    assert mem.record_failure((2.5, 1.5), (1.0, 1.5)) == (1, (1.0, 1.5))
    assert mem.record_failure((2.6, 1.6), (2.0, 1.5)) == (2, (1.0, 1.5))  # same place
    mem.drop((2.5, 1.5), "attempts", grid, GEOM)
    assert mem.is_dropped((2.7, 1.5)) and not mem.is_dropped((3.2, 1.5))
    assert mem.revive(grid, GEOM) == []  # nothing changed round it
    changed = grid.copy()
    changed[20:40, 51:60] = FREE  # the space behind the gap got mapped
    assert mem.revive(changed, GEOM) == [(2.5, 1.5)]
    assert not mem.is_dropped((2.5, 1.5))
    assert mem.record_failure((2.5, 1.5), (1.0, 1.5))[0] == 1  # counting starts afresh
    mem.drop((2.5, 1.5), "attempts", changed, GEOM)
    assert mem.revive(grid, GEOM) == []  # at most max_revivals per place
    assert mem.count("attempts") == 1 and mem.count("looked") == 0


def test_a_goal_dropped_near_an_older_drop_is_excluded_round_itself_too() -> None:
    # The livelock this prevents: the grid fallback excludes frontier cells near the dropped
    # points; a goal 0.45 m from an older drop is "the same place", and if only the old point
    # were kept, the frontier 0.9 m from it (beside the new goal) stayed searchable, and the
    # same goal came back after every drop.
    grid = _two_rooms(0.6)
    mem = FrontierMemory(0.5, 0.75, 40, max_revivals=1, max_attempts=3)
    mem.drop((2.5, 1.5), "looked", grid, GEOM)
    mem.drop((2.95, 1.5), "attempts", grid, GEOM)
    assert mem.active_points() == [(2.5, 1.5), (2.95, 1.5)]
    assert mem.is_dropped((3.4, 1.5))  # within the radius of the new point only
    mem.drop((2.95, 1.5), "attempts", grid, GEOM)  # the very same point: no third entry
    assert len(mem.dropped) == 2
    changed = grid.copy()
    changed[20:40, 51:60] = FREE
    assert sorted(mem.revive(changed, GEOM)) == [(2.5, 1.5), (2.95, 1.5)]
    mem.drop((2.6, 1.5), "attempts", changed, GEOM)  # a third point near both
    assert mem.dropped[-1].revivals == 1  # the place's revivals go with it
    assert mem.revive(grid, GEOM) == []  # so it does not come back again
    old = FrontierMemory(0.5, 0.75, 40, max_revivals=1, max_attempts=3, drop_each_point=False)
    old.drop((2.5, 1.5), "looked", grid, GEOM)
    old.drop((2.95, 1.5), "attempts", grid, GEOM)
    assert old.active_points() == [(2.5, 1.5)]  # before the fix: the earlier point only
    assert not old.is_dropped((3.4, 1.5))


def test_abandoned_goals_are_remembered_for_the_oscillation_window() -> None:
    mem = FrontierMemory(0.5, 0.75, 40, max_revivals=1, max_attempts=3)
    mem.abandon((1.0, 1.0), 10.0)
    assert mem.recently_abandoned((1.2, 1.0), 100.0, 120.0)
    assert not mem.recently_abandoned((3.0, 1.0), 100.0, 120.0)
    assert not mem.recently_abandoned((1.2, 1.0), 200.0, 120.0)


def test_side_approach_comes_from_away_from_the_failure() -> None:
    grid = np.full(GEOM.shape, OCCUPIED, dtype=np.uint8)
    grid[4:56, 4:96] = FREE
    clearance = clearance_field_m(grid, RES)
    found = side_approach(grid, GEOM, (0.5, 1.5), (2.5, 1.5), (1.9, 1.5), 0.155, clearance)
    assert found is not None
    target, path = found
    assert math.dist(target, (2.5, 1.5)) <= 0.85 and target[0] > 2.5
    assert math.dist(tuple(path[-1]), target) <= 0.15 + RES  # grid_path_to's goal radius


def test_paper_method_yaml_names_the_paper_method_recipe() -> None:
    from semexplore_gym.policies.specs import load_policy_config

    cfg = load_policy_config(REPO / "configs" / "expert" / "paper_method.yaml")
    assert cfg.policy == "semantic-paper" and not cfg.params
    pol = make_policy("semantic-paper")
    assert pol.recipe is PAPER_METHOD
    assert pol.params == build_params(SemanticExpertParams, dict(PAPER_PARAMS))
    assert pol.params.cost == SemanticExpertParams().cost  # the paper's weights
    assert pol.recipe.source_names == ("commanded", "retry", "semantic")
    semantic = pol.recipe.semantic_source
    assert semantic is not None
    assert not (semantic.grid_candidate or semantic.grid_route or semantic.entry_detour)
    assert not any(vars(pol.goal_memory.rules).values())  # no goal rule of ours
    flags = "goal_commitment local_min_escape stuck_recovery".split()
    assert not any(getattr(pol.params, f) for f in flags)
    assert all(getattr(SemanticExpertParams(), f) for f in flags)  # the robust default
    assert not pol.params.potential_field.braking_guard and pol.params.prune_by == "area"
    with pytest.raises(ValueError, match="semantic-paper"):
        make_policy("semantic-paper:x")


def test_without_the_braking_guard_only_the_field_sets_the_speed() -> None:
    from semexplore_gym.core.planning.potential_field import (
        PotentialFieldParams,
        RobotLimits,
        force_to_velocity,
    )

    lim = RobotLimits(0.105, 0.22, 2.84, 3.5)
    scan = np.full(360, 3.5)
    scan[:6] = scan[-6:] = 0.2  # a wall 0.2 m ahead
    angles = np.arange(360) * 2 * math.pi / 360
    no_steer = PotentialFieldParams(guard_steer_max_rad=0.0)
    guarded = force_to_velocity(1.0, 0.0, scan, angles, lim, no_steer)[0]
    free = force_to_velocity(
        1.0,
        0.0,
        scan,
        angles,
        lim,
        PotentialFieldParams(guard_steer_max_rad=0.0, braking_guard=False),
    )[0]
    assert guarded < 0.22 and free == pytest.approx(0.22)
