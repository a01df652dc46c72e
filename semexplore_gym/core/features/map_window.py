"""A fixed-size window of the occupancy map: cells ``[r0, r0 + size) x [c0, c0 + size)``.

The one implementation of the pad/crop behind the :class:`~semexplore_gym.wrappers.FixedSizeMap`
wrapper, shared with :class:`~semexplore_gym.policies.sb3_policy.SB3Policy` so a model trained on the wrapped
observation runs as a policy on raw observations. Cells outside the map read as UNKNOWN.
Grid indices are ``(row, col)``.
"""

from __future__ import annotations

import numpy as np

from semexplore_gym.core.grid import UNKNOWN

#: Where the window is centred: on the map's centre cell, or on the robot's cell.
MAP_ANCHORS: tuple[str, ...] = ("world", "robot")


def window_origin(
    grid_shape: tuple[int, int],
    size: int,
    anchor: str,
    robot_rc: tuple[int, int] | None = None,
) -> tuple[int, int]:
    """The ``(row, col)`` of the window's first cell in the map (may be negative).

    Args:
        grid_shape: ``(height, width)`` of the map in cells.
        size: Side of the square window in cells.
        anchor: ``"world"`` (the map's centre at the window's centre) or ``"robot"``.
        robot_rc: The robot's cell; required for ``anchor="robot"``.

    Raises:
        ValueError: an unknown anchor, or ``"robot"`` without ``robot_rc``.
    """
    half = int(size) // 2
    if anchor == "world":
        return (int(grid_shape[0]) // 2 - half, int(grid_shape[1]) // 2 - half)
    if anchor == "robot":
        if robot_rc is None:
            raise ValueError("anchor 'robot' needs the robot's cell (robot_rc)")
        return (int(robot_rc[0]) - half, int(robot_rc[1]) - half)
    raise ValueError(f"anchor must be one of {MAP_ANCHORS}, got {anchor!r}")


def map_window(
    grid: np.ndarray, origin_rc: tuple[int, int], size: int, fill: int = UNKNOWN
) -> np.ndarray:
    """The ``(size, size)`` uint8 window of ``grid`` starting at ``origin_rc``, padded with ``fill``.

    ``window[r, c] == grid[r + r0, c + c0]`` wherever that cell exists.
    """
    h, w = grid.shape
    r0, c0 = int(origin_rc[0]), int(origin_rc[1])
    s = int(size)
    window = np.full((s, s), fill, dtype=np.uint8)
    gr0, gr1 = max(r0, 0), min(r0 + s, h)
    gc0, gc1 = max(c0, 0), min(c0 + s, w)
    if gr0 < gr1 and gc0 < gc1:
        window[gr0 - r0 : gr1 - r0, gc0 - c0 : gc1 - c0] = grid[gr0:gr1, gc0:gc1]
    return window
