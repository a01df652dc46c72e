"""A stop short of the goal explained by the SLAM map: a lost frontier, a ghost frontier."""

from __future__ import annotations

import numpy as np
import pytest

from semexplore_gym.core.grid import OCCUPIED, parse_ascii_grid
from semexplore_gym.core.slam.false_stop import (
    GHOST_FRONTIER,
    LOST_FRONTIER,
    frontier_differences,
    stop_artefact,
)

# The truth: a room whose corridor runs on into space not yet seen.
CORRIDOR_OPEN = """
##########################
#......###################
#.......................??
#.......................??
#.......................??
#......###################
##########################
"""
# SLAM's map of the same scans: a drifted double of a wall closes the corridor.
CORRIDOR_CLOSED = """
##########################
#......###################
#..........#??????????????
#..........#??????????????
#..........#??????????????
#......###################
##########################
"""
# The same corridor, SLAM's map one cell off: the frontier is where the truth has it.
CORRIDOR_SHIFTED = """
##########################
#......###################
#......................???
#......................???
#......................???
#......###################
##########################
"""
ROOM = """
##########
#........#
#........#
#........#
##########
"""
# SLAM's map of the room: a wall seen twice leaves an unknown sliver inside the room.
ROOM_WITH_GHOST_GAP = """
##########
#...??...#
#...??...#
#...??...#
##########
"""


def _reachable(truth: np.ndarray) -> np.ndarray:
    return truth != OCCUPIED


def test_a_corridor_closed_by_a_doubled_wall_is_a_lost_frontier() -> None:
    truth, slam = parse_ascii_grid(CORRIDOR_OPEN), parse_ascii_grid(CORRIDOR_CLOSED)
    assert frontier_differences(slam, truth, _reachable(truth)) == (3, 0)
    assert stop_artefact(slam, truth, _reachable(truth)) == LOST_FRONTIER


def test_an_unknown_sliver_the_truth_has_seen_is_a_ghost_frontier() -> None:
    truth, slam = parse_ascii_grid(ROOM), parse_ascii_grid(ROOM_WITH_GHOST_GAP)
    assert frontier_differences(slam, truth, _reachable(truth)) == (0, 6)
    assert stop_artefact(slam, truth, _reachable(truth)) == GHOST_FRONTIER


@pytest.mark.parametrize(("truth", "slam"), [(CORRIDOR_OPEN, CORRIDOR_SHIFTED), (ROOM, ROOM)])
def test_frontiers_within_the_tolerance_are_no_artefact(truth: str, slam: str) -> None:
    t, s = parse_ascii_grid(truth), parse_ascii_grid(slam)
    assert stop_artefact(s, t, _reachable(t)) is None
    # With no tolerance the shifted corridor's frontier no longer matches.
    if truth != slam:
        assert stop_artefact(s, t, _reachable(t), tolerance_cells=0) == LOST_FRONTIER


def test_a_frontier_outside_the_reachable_space_is_not_lost() -> None:
    truth, slam = parse_ascii_grid(CORRIDOR_OPEN), parse_ascii_grid(CORRIDOR_CLOSED)
    assert stop_artefact(slam, truth, np.zeros(truth.shape, dtype=bool)) is None


def test_maps_of_different_shapes_are_refused_in_one_line() -> None:
    truth, room = parse_ascii_grid(CORRIDOR_OPEN), parse_ascii_grid(ROOM)
    with pytest.raises(ValueError, match="one shape") as e:
        frontier_differences(room, truth, _reachable(truth))
    assert "\n" not in str(e.value)
