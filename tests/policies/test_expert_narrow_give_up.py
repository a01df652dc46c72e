"""The narrow tier's optional give-up: once its last goals mapped almost no room to move (cracks
narrower than the robot, slots too small to matter), the expert stops driving into them."""

from __future__ import annotations

import numpy as np
import pytest


def _room_with_slots(width_px: int = 5, n: int = 8) -> np.ndarray:
    """Map pixels (0.05 m): a 2 m room whose walls have ``n`` bent dead-end slots ``width_px``
    wide (0.25 m: the env counts them reachable, the planners' clearance does not), 0.8 m out
    and 0.5 m along, so their ends are seen only from inside."""
    img = np.zeros((80, 80), dtype=np.uint8)
    img[20:60, 20:60] = 254
    d, w = 16, width_px
    for k in range(n):
        side, off = divmod(k, 2)
        c = 27 + off * 18
        if side == 0:
            img[20 - d : 20, c : c + w] = 254
            img[20 - d : 20 - d + w, c : c + 10] = 254
        elif side == 1:
            img[60 : 60 + d, c : c + w] = 254
            img[60 + d - w : 60 + d, c : c + 10] = 254
        elif side == 2:
            img[c : c + w, 20 - d : 20] = 254
            img[c : c + 10, 20 - d : 20 - d + w] = 254
        else:
            img[c : c + w, 60 : 60 + d] = 254
            img[c : c + 10, 60 + d - w : 60 + d] = 254
    return img


def _slots_missions(ros_map_file, short_mission, give_up: str):
    """The narrow tier in the slotted room without and with the give-up ``give_up``: the
    missions ``(keeps_on, p_on), (gives_up, p_up)``."""
    from semexplore_gym.policies.expert.expert import SemanticExpertPolicy
    from semexplore_gym.policies.expert.params import SemanticExpertParams
    from semexplore_gym.policies.expert.recipes import SEMANTIC_V3

    from semexplore_gym.config import build_params

    world = ros_map_file(_room_with_slots(), "slots", (0.013, 0.021))
    # The expert of the time the give-up was made (the goal rule vanish_on_frontier came later:
    # with it, the unknown rock round a slot's end is no frontier and fewer slots become goals).
    then = SEMANTIC_V3.with_rules(vanish_on_frontier=False)

    def expert(*overrides: str) -> SemanticExpertPolicy:
        prm = build_params(SemanticExpertParams, overrides=["narrow_passages=true", *overrides])
        return SemanticExpertPolicy(prm, recipe=then)

    return (
        short_mission(world, expert(), 2, 600),
        short_mission(world, expert(give_up), 2, 600),
    )


def test_the_narrow_tier_gives_up_on_slots_that_map_almost_nothing(ros_map_file, short_mission):
    (keeps_on, p_on), (gives_up, p_up) = _slots_missions(
        ros_map_file, short_mission, "narrow_give_up_goals=4"
    )
    k = p_up.params.narrow_give_up_goals
    assert len(p_on.goal_memory.narrow_goals) > k  # on into more slots
    assert len(p_up.goal_memory.narrow_goals) == k  # then no new narrow goal
    assert gives_up.self_stopped and keeps_on.self_stopped
    assert gives_up.mission_time_s < 0.8 * keeps_on.mission_time_s
    assert gives_up.collisions == keeps_on.collisions == 0


def test_narrow_goal_gives_up_on_new_goals_after_goals_that_added_no_room():
    from semexplore_gym.policies.expert.counters import ExpertCounters
    from semexplore_gym.policies.expert.goal_memory import GoalMemory
    from semexplore_gym.policies.expert.params import SemanticExpertParams

    memory = GoalMemory(SemanticExpertParams().goal_memory, ExpertCounters(), lambda *_: None)

    def propose(xy, room, goals=2):
        return memory.narrow_goal(xy, room, 1.0, goals, 50)

    assert not propose((0.0, 0.0), 100)  # first goal
    assert not propose((0.5, 0.0), 100)  # within 1 m: the same goal, drifting
    assert not propose((3.0, 0.0), 120)  # a second goal
    assert len(memory.narrow_goals) == 2
    assert propose((6.0, 0.0), 149)  # two goals added 49 cells < 50: give up
    assert not propose((3.4, 0.0), 149)  # the current goal goes on (crawling through)
    assert not propose((6.0, 0.0), 149, goals=3)  # a longer window: not yet
    assert not propose((9.0, 0.0), 160, goals=0)  # 0: never gives up
    assert propose((12.0, 0.0), 165)  # the last two goals (120 -> 160 -> 165): 45 cells
    assert not propose((12.0, 5.0), 200)  # the map grew by 80 since 120: try again


@pytest.mark.parametrize("bad", [-1, 1.5, True])
def test_narrow_give_up_goals_is_checked(bad):
    from semexplore_gym.policies.expert.params import SemanticExpertParams

    with pytest.raises(ValueError, match="narrow_give_up_goals"):
        SemanticExpertParams(narrow_give_up_goals=bad)


def test_narrow_goal_gives_up_once_the_map_gained_no_room_for_a_while():
    from semexplore_gym.policies.expert.counters import ExpertCounters
    from semexplore_gym.policies.expert.goal_memory import GoalMemory
    from semexplore_gym.policies.expert.params import SemanticExpertParams

    memory = GoalMemory(SemanticExpertParams().goal_memory, ExpertCounters(), lambda *_: None)

    def propose(xy, room, now_s, give_up_s=100.0):
        return memory.narrow_goal(xy, room, 1.0, 0, 50, now_s=now_s, give_up_s=give_up_s)

    assert not propose((0.0, 0.0), 100, 10.0)  # the clock starts at the first narrow goal
    assert not propose((3.0, 0.0), 140, 60.0)  # 40 new cells < 50: the clock runs on
    assert not propose((6.0, 0.0), 149, 110.0)  # 100 s since 10 s: not more than 100 s yet
    assert propose((9.0, 0.0), 149, 111.0)  # 101 s without 50 new cells: give up
    assert not propose((6.4, 0.0), 149, 150.0)  # the current goal goes on (crawling through)
    assert propose((12.0, 0.0), 149, 150.0, give_up_s=100.0)  # still given up
    assert not propose((12.0, 0.0), 149, 150.0, give_up_s=0.0)  # 0: never gives up
    assert not propose((15.0, 0.0), 151, 300.0)  # 51 cells since 10 s: the clock restarts
    assert memory.narrow_room_since == (300.0, 151)
    assert not propose((18.0, 0.0), 151, 400.0)  # 100 s since 300 s
    assert propose((21.0, 0.0), 160, 400.5)
    memory.reset(memory.geometry)
    assert memory.narrow_room_since is None  # a new mission


def test_the_narrow_tier_gives_up_after_a_while_without_new_room(ros_map_file, short_mission):
    (keeps_on, p_on), (gives_up, p_up) = _slots_missions(
        ros_map_file, short_mission, "narrow_give_up_s=30"
    )
    # Slots a few cells deep add (almost) no room: after 30 s the narrow tier takes no new one.
    assert 1 <= len(p_up.goal_memory.narrow_goals) < len(p_on.goal_memory.narrow_goals)
    assert p_up.counts.narrow_plans < p_on.counts.narrow_plans
    assert gives_up.self_stopped and keeps_on.self_stopped
    assert gives_up.mission_time_s < 0.85 * keeps_on.mission_time_s
    assert gives_up.coverage >= keeps_on.coverage - 0.01
    assert gives_up.collisions == keeps_on.collisions == 0


@pytest.mark.parametrize("bad", [-1.0, float("nan"), float("inf"), "30"])
def test_narrow_give_up_s_is_checked(bad):
    from semexplore_gym.policies.expert.params import SemanticExpertParams

    with pytest.raises(ValueError, match="narrow_give_up_s"):
        SemanticExpertParams(narrow_give_up_s=bad)
