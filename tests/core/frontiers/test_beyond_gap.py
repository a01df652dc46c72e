"""Room beyond a gap: the way through a passage narrower than the planners' clearance, taken
only where the map shows room with a frontier on its far side."""

from __future__ import annotations

import numpy as np
import pytest

from semexplore_gym.core.frontiers.beyond_gap import room_beyond_gap_path
from semexplore_gym.core.frontiers.reachable import FrontierFilter, known_free_clearance_m
from semexplore_gym.core.grid import FREE, OCCUPIED, UNKNOWN, GridGeometry

RES = 0.05
CLEARANCE_M = 0.155  # the planners' (radius 0.105 + 0.05)
THIN_M = 0.10  # the narrow tier's (radius - 0.005)
GAP_ROWS = slice(28, 33)  # a 0.25 m gap: 0.15 m from its middle to the walls


def _two_rooms(beyond_unknown: bool = True, gap: bool = True) -> tuple[np.ndarray, GridGeometry]:
    """A mapped room (x < 2 m), a wall at x = 2.0-2.1 m with a 0.25 m gap, and a room beyond
    it (x > 2.1 m) seen through the gap up to x = 4 m, with unknown space after that unless
    ``beyond_unknown`` is False (then the far room is closed and fully mapped)."""
    g = np.full((60, 100), OCCUPIED, dtype=np.uint8)
    g[1:59, 1:40] = FREE
    g[1:59, 42:99] = FREE
    if beyond_unknown:
        g[1:59, 80:99] = UNKNOWN
    if gap:
        g[GAP_ROWS, 40:42] = FREE
    return g, GridGeometry(RES, 0.0, 0.0, *g.shape)


def _path(g: np.ndarray, geom: GridGeometry, start=(1.0, 1.5), **kw) -> np.ndarray | None:
    known = known_free_clearance_m(g, RES)
    return room_beyond_gap_path(g, geom, start, CLEARANCE_M, THIN_M, known, **kw)


def test_the_way_leads_through_the_gap_into_the_room_beyond() -> None:
    g, geom = _two_rooms()
    path = _path(g, geom)
    assert path is not None
    np.testing.assert_allclose(path[0], (1.0, 1.5))
    assert path[-1][0] > 2.1  # ends in the room beyond the wall
    in_wall = path[(path[:, 0] > 2.0) & (path[:, 0] < 2.1)]
    assert len(in_wall) and np.all((in_wall[:, 1] > 1.4) & (in_wall[:, 1] < 1.65))  # the gap
    rows, cols = geom.world_to_grid(path[:, 0], path[:, 1])
    assert np.all(known_free_clearance_m(g, RES)[rows[1:], cols[1:]] >= THIN_M - 1e-9)


def test_no_way_where_the_far_side_shows_no_frontier_or_too_little_room() -> None:
    closed, geom = _two_rooms(beyond_unknown=False)
    assert _path(closed, geom) is None  # all mapped beyond: nothing to go for
    g, geom = _two_rooms()
    far_room_cells = 58 * 38  # generous upper bound of the far room's usable cells
    assert _path(g, geom, min_room_cells=far_room_cells) is None
    assert _path(g, geom, min_room_cells=100) is not None
    # A frontier the expert dropped does not count.
    dropped = FrontierFilter(excluded_xy_m=[(4.0, y) for y in np.arange(0.0, 3.0, 0.5)])
    assert _path(g, geom, frontiers=dropped) is None


def test_no_way_when_the_gap_is_closed_or_the_robot_is_already_beyond() -> None:
    sealed, geom = _two_rooms(gap=False)
    assert _path(sealed, geom) is None
    g, geom = _two_rooms()
    # From inside the far room there is nothing beyond a gap: its frontier is the usual
    # planners' business, and the room behind holds no frontier.
    assert _path(g, geom, start=(3.0, 1.5)) is None


def test_bad_input_is_refused_with_the_bad_value() -> None:
    g, geom = _two_rooms()
    known = known_free_clearance_m(g, RES)
    with pytest.raises(ValueError, match="thin_m"):
        room_beyond_gap_path(g, geom, (1.0, 1.5), CLEARANCE_M, 0.2, known)
    with pytest.raises(ValueError, match="thin_field shape"):
        room_beyond_gap_path(g, geom, (1.0, 1.5), CLEARANCE_M, THIN_M, known[:, :10])
    with pytest.raises(ValueError, match="clearance_m"):
        room_beyond_gap_path(g, geom, (1.0, 1.5), -1.0, THIN_M, known)


def test_unknown_space_round_the_map_changes_nothing() -> None:
    # The search works within the known cells' window: a map inside a wide unknown border
    # gives the same way, shifted by the border.
    g, geom = _two_rooms()
    pad = 200
    big = np.pad(g, pad, constant_values=UNKNOWN)
    big_geom = GridGeometry(RES, -pad * RES, -pad * RES, *big.shape)
    small = _path(g, geom)
    known = known_free_clearance_m(big, RES)
    large = room_beyond_gap_path(big, big_geom, (1.0, 1.5), CLEARANCE_M, THIN_M, known)
    assert small is not None and large is not None
    np.testing.assert_allclose(large, small, atol=1e-9)
