"""The expert's graded clearance (``narrow_passages``): passages narrower than the planners'
clearance but wider than the robot are explored, slowly and without touching their walls."""

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


def test_narrow_passages_is_off_by_default_and_its_parameters_are_checked():
    from semexplore_gym.policies.semantic_expert_params import SemanticExpertParams

    assert SemanticExpertParams().narrow_passages is False
    with pytest.raises(ValueError, match="narrow_clearance_margin_m"):
        SemanticExpertParams(narrow_clearance_margin_m=-0.2)
    with pytest.raises(ValueError, match="tight_speed_mps"):
        SemanticExpertParams(tight_speed_mps=0.0)
