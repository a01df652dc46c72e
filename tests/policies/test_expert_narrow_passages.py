"""The expert's graded clearance (the ``room_beyond_gap`` source, in today's recipe; the
user's switch ``narrow_passages``):
passages narrower than the planners' clearance but wider than the robot are explored, slowly
and without touching their walls."""

from __future__ import annotations

import numpy as np
import pytest


def _rooms_joined_by_a_passage(width_px: int) -> np.ndarray:
    """Map pixels (0.05 m): two 1.5 m rooms joined by a 1.5 m straight passage ``width_px``
    pixels wide."""
    img = np.zeros((90, 40), dtype=np.uint8)
    img[5:35, 5:35] = 254
    img[65:85, 5:35] = 254
    lo = 20 - width_px // 2
    img[35:65, lo : lo + width_px] = 254
    return img


@pytest.mark.parametrize("width_px", [5, 6])
def test_a_passage_just_wider_than_the_robot_is_explored_without_touching_it(
    ros_map_file, short_mission, width_px
):
    # 0.25 m and 0.30 m: the env counts the far room as reachable (gaps from 0.23 m), the
    # planners' clearance (0.155 m, gaps from 0.31 m) does not.
    # The origin is off the cell grid: no wall lies on a cell border of the robot's map.
    world = ros_map_file(_rooms_joined_by_a_passage(width_px), "passage", (0.013, 0.021))
    default, _ = short_mission(world, "semantic", 1, 600)
    assert default.self_stopped and default.coverage < 0.8  # stops in the first room
    narrow, policy = short_mission(world, "semantic[narrow_passages=true]", 1, 600)
    assert narrow.self_stopped and narrow.coverage >= 0.97
    assert narrow.collisions == 0
    assert policy.counters["narrow_plans"] > 0 and policy.counters["tight_steps"] > 0


def _rooms_with_a_gap(width_px: int) -> np.ndarray:
    """Map pixels (0.05 m): two 1.5 m rooms side by side, the wall between them (0.1 m thick)
    open by a gap ``width_px`` pixels wide: from either room the LiDAR sees into the other."""
    img = np.zeros((40, 75), dtype=np.uint8)
    img[5:35, 5:35] = 254
    img[5:35, 37:70] = 254
    lo = 20 - width_px // 2
    img[lo : lo + width_px, 35:37] = 254
    return img


@pytest.mark.parametrize("width_px", [5, 6])
def test_room_seen_beyond_a_gap_just_wider_than_the_robot_is_explored_by_default(
    ros_map_file, short_mission, width_px
):
    # 0.25 m and 0.30 m: narrower than the planners' clearance allows (gaps from 0.31 m), wider
    # than the robot. The default expert goes through (room_beyond_gap), slowly and exactly.
    from semexplore_gym.policies.expert.expert import SemanticExpertPolicy
    from semexplore_gym.policies.expert.recipes import SEMANTIC_V3

    world = ros_map_file(_rooms_with_a_gap(width_px), "gap", (0.013, 0.021))
    for seed in (1, 2):
        result, policy = short_mission(world, "semantic", seed, 300)
        assert result.self_stopped and result.coverage >= 0.97 and result.collisions == 0
        assert policy.counters["narrow_plans"] > 0 and policy.counters["tight_steps"] > 0
        assert any(e == "room" for _t, e, _d in policy.events)
        without = SemanticExpertPolicy(recipe=SEMANTIC_V3.without("room_beyond_gap"))
        off, _ = short_mission(world, without, seed, 300)
        assert off.self_stopped and off.coverage < 0.8  # stops in its own room


def test_a_gap_narrower_than_the_robot_ends_the_mission_without_a_collision(
    ros_map_file, short_mission
):
    # 0.20 m: the env counts only the start room as reachable; the expert may try the gap (the
    # map places walls only to within a cell), the scan holds it back, and it stops by itself.
    world = ros_map_file(_rooms_with_a_gap(4), "crack", (0.013, 0.021))
    for seed in (1, 2):
        result, _ = short_mission(world, "semantic", seed, 300)
        assert result.self_stopped and result.coverage >= 0.97 and result.collisions == 0
        assert result.mission_time_s < 60.0


def test_narrow_passages_is_off_by_default_and_its_parameters_are_checked():
    from semexplore_gym.policies.expert.params import SemanticExpertParams

    assert SemanticExpertParams().narrow_passages is False
    from semexplore_gym.policies.expert.recipes import SEMANTIC_V3

    assert "room_beyond_gap" in SEMANTIC_V3.source_names
    with pytest.raises(ValueError, match="narrow_min_room_m2"):
        SemanticExpertParams(narrow_min_room_m2=float("nan"))
    with pytest.raises(ValueError, match="narrow_clearance_margin_m"):
        SemanticExpertParams(narrow_clearance_margin_m=-0.2)
    with pytest.raises(ValueError, match="tight_speed_mps"):
        SemanticExpertParams(tight_speed_mps=0.0)
