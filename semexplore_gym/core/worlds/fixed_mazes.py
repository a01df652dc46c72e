"""The two fixed test mazes, ``maze1`` and ``maze2``.

They are modelled on the two board-built indoor mazes the paper uses for validation (section IV:
"two maze configurations ... custom-built for the validation tests", mapped at 0.05 m into a
224 x 224 grid). The paper shows them only as pictures, so these are our own layouts with the
same character: about 7.2 m x 7.2 m inside, corridors 0.7-0.9 m wide between thin board walls,
long pathways, several 3- and 4-way intersections, loops and dead ends.

Each maze was laid out on a cell grid (candidate layouts from a randomised depth-first maze
with a few walls knocked out were screened for at least two 4-way junctions, six 3-way
junctions, five dead ends, a handful of loops and no open 2 x 2 block, then frozen here by
hand). The wall lists below are explicit; the sketches are the same walls, drawn with the top
line at the largest y: ``---`` / ``|`` is a board, ``+`` a grid post. The walls are
zero-thickness segments (the boards of such mazes are about 1.5 cm thick); their
coordinates are the board centre lines, in metres, with the origin at the outer lower-left
corner.
"""

from __future__ import annotations

import math

import numpy as np

from semexplore_gym.core.worlds.build import world_from_segments
from semexplore_gym.core.worlds.world import World

#: Maze 1: 8 x 8 cells of 0.9 m, 7.2 m x 7.2 m. 2 four-way and 8 three-way junctions, 6 dead
#: ends, 4 independent loops. Start: bottom-left cell, facing +x.
MAZE1_COLUMN_WIDTHS_M: tuple[float, ...] = (0.9,) * 8
MAZE1_ROW_HEIGHTS_M: tuple[float, ...] = (0.9,) * 8
MAZE1_SEGMENTS_M: tuple[tuple[float, float, float, float], ...] = (
    (0.0, 0.0, 7.2, 0.0),
    (0.9, 0.9, 1.8, 0.9),
    (2.7, 0.9, 3.6, 0.9),
    (4.5, 0.9, 5.4, 0.9),
    (0.0, 1.8, 2.7, 1.8),
    (3.6, 1.8, 4.5, 1.8),
    (5.4, 1.8, 6.3, 1.8),
    (0.9, 2.7, 1.8, 2.7),
    (2.7, 2.7, 3.6, 2.7),
    (4.5, 2.7, 7.2, 2.7),
    (0.9, 3.6, 1.8, 3.6),
    (5.4, 3.6, 6.3, 3.6),
    (0.0, 4.5, 1.8, 4.5),
    (2.7, 4.5, 4.5, 4.5),
    (5.4, 4.5, 6.3, 4.5),
    (1.8, 5.4, 2.7, 5.4),
    (4.5, 5.4, 5.4, 5.4),
    (6.3, 5.4, 7.2, 5.4),
    (0.9, 6.3, 1.8, 6.3),
    (2.7, 6.3, 4.5, 6.3),
    (5.4, 6.3, 6.3, 6.3),
    (0.0, 7.2, 7.2, 7.2),
    (0.0, 0.0, 0.0, 7.2),
    (0.9, 4.5, 0.9, 6.3),
    (1.8, 1.8, 1.8, 2.7),
    (2.7, 0.9, 2.7, 1.8),
    (2.7, 2.7, 2.7, 3.6),
    (2.7, 4.5, 2.7, 5.4),
    (3.6, 1.8, 3.6, 2.7),
    (3.6, 3.6, 3.6, 4.5),
    (3.6, 5.4, 3.6, 6.3),
    (4.5, 0.0, 4.5, 1.8),
    (4.5, 2.7, 4.5, 3.6),
    (4.5, 4.5, 4.5, 5.4),
    (5.4, 1.8, 5.4, 2.7),
    (5.4, 4.5, 5.4, 6.3),
    (6.3, 0.9, 6.3, 1.8),
    (6.3, 3.6, 6.3, 4.5),
    (7.2, 0.0, 7.2, 7.2),
)
MAZE1_START_POSE: tuple[float, float, float] = (0.45, 0.45, 0.0)

#: Maze 2: 9 x 9 cells with uneven column widths (0.7-0.9 m, listed from x = 0) and row heights
#: (listed from y = 0), 7.2 m x 7.2 m. 2 four-way and 12 three-way junctions, 8 dead ends,
#: 5 independent loops. Start: bottom-left cell, facing +y.
MAZE2_COLUMN_WIDTHS_M: tuple[float, ...] = (0.8, 0.7, 0.9, 0.8, 0.7, 0.8, 0.9, 0.8, 0.8)
MAZE2_ROW_HEIGHTS_M: tuple[float, ...] = (0.8, 0.8, 0.7, 0.9, 0.8, 0.8, 0.7, 0.9, 0.8)
MAZE2_SEGMENTS_M: tuple[tuple[float, float, float, float], ...] = (
    (0.0, 0.0, 7.2, 0.0),
    (1.5, 0.8, 3.2, 0.8),
    (5.6, 0.8, 6.4, 0.8),
    (3.2, 1.6, 5.6, 1.6),
    (0.8, 2.3, 1.5, 2.3),
    (3.2, 2.3, 4.7, 2.3),
    (5.6, 2.3, 6.4, 2.3),
    (0.0, 3.2, 0.8, 3.2),
    (5.6, 3.2, 6.4, 3.2),
    (0.8, 4.0, 1.5, 4.0),
    (4.7, 4.0, 5.6, 4.0),
    (0.8, 4.8, 1.5, 4.8),
    (3.9, 4.8, 6.4, 4.8),
    (0.0, 5.5, 0.8, 5.5),
    (3.9, 5.5, 4.7, 5.5),
    (5.6, 5.5, 6.4, 5.5),
    (0.8, 6.4, 2.4, 6.4),
    (3.2, 6.4, 5.6, 6.4),
    (0.0, 7.2, 7.2, 7.2),
    (0.0, 0.0, 0.0, 7.2),
    (0.8, 0.0, 0.8, 1.6),
    (0.8, 4.0, 0.8, 4.8),
    (1.5, 1.6, 1.5, 4.0),
    (1.5, 4.8, 1.5, 6.4),
    (2.4, 0.8, 2.4, 1.6),
    (2.4, 2.3, 2.4, 5.5),
    (3.2, 0.8, 3.2, 1.6),
    (3.2, 2.3, 3.2, 4.8),
    (3.2, 5.5, 3.2, 7.2),
    (3.9, 0.0, 3.9, 0.8),
    (3.9, 3.2, 3.9, 4.8),
    (4.7, 0.8, 4.7, 4.0),
    (5.6, 0.0, 5.6, 0.8),
    (5.6, 2.3, 5.6, 3.2),
    (5.6, 5.5, 5.6, 6.4),
    (6.4, 0.8, 6.4, 2.3),
    (6.4, 4.0, 6.4, 4.8),
    (6.4, 5.5, 6.4, 6.4),
    (7.2, 0.0, 7.2, 7.2),
)
MAZE2_START_POSE: tuple[float, float, float] = (0.4, 0.4, math.pi / 2)


def _cell_centres_m(widths_m: tuple[float, ...], heights_m: tuple[float, ...]) -> np.ndarray:
    xs = np.cumsum((0.0,) + widths_m)
    ys = np.cumsum((0.0,) + heights_m)
    cx = 0.5 * (xs[:-1] + xs[1:])
    cy = 0.5 * (ys[:-1] + ys[1:])
    gx, gy = np.meshgrid(cx, cy)
    return np.column_stack([gx.ravel(), gy.ravel()])


def make_maze1(name: str = "maze1") -> World:
    """The first fixed maze: 8 x 8 cells of 0.9 m (walls :data:`MAZE1_SEGMENTS_M`).

    Sketch (top line = largest y; each cell is 0.9 m square)::

        +---+---+---+---+---+---+---+---+
        |                               |
        +   +---+   +---+---+   +---+   +
        |   |           |       |       |
        +   +   +---+   +   +---+   +---+
        |   |       |       |   |       |
        +---+---+   +---+---+   +---+   +
        |               |           |   |
        +   +---+   +   +   +   +---+   +
        |           |       |           |
        +   +---+   +---+   +---+---+---+
        |       |       |       |       |
        +---+---+---+   +---+   +---+   +
        |           |       |       |   |
        +   +---+   +---+   +---+   +   +
        |                   |           |
        +---+---+---+---+---+---+---+---+
    """
    return world_from_segments(
        name,
        np.array(MAZE1_SEGMENTS_M),
        _cell_centres_m(MAZE1_COLUMN_WIDTHS_M, MAZE1_ROW_HEIGHTS_M),
        start_pose=MAZE1_START_POSE,
        metadata={
            "source": "fixed_maze",
            "maze": "maze1",
            "spec": "maze1",
            "column_widths_m": MAZE1_COLUMN_WIDTHS_M,
            "row_heights_m": MAZE1_ROW_HEIGHTS_M,
        },
    )


def make_maze2(name: str = "maze2") -> World:
    """The second fixed maze: 9 x 9 cells of uneven size (walls :data:`MAZE2_SEGMENTS_M`).

    Sketch (top line = largest y; column widths :data:`MAZE2_COLUMN_WIDTHS_M` from the left,
    row heights :data:`MAZE2_ROW_HEIGHTS_M` from the bottom)::

        +---+---+---+---+---+---+---+---+---+
        |               |                   |
        +   +---+---+   +---+---+---+   +   +
        |       |       |           |   |   |
        +---+   +   +   +   +---+   +---+   +
        |       |   |                       |
        +   +---+   +   +   +---+---+---+   +
        |   |       |   |   |           |   |
        +   +---+   +   +   +   +---+   +   +
        |       |   |   |   |   |           |
        +---+   +   +   +   +   +   +---+   +
        |       |   |   |       |   |       |
        +   +---+   +   +---+---+   +---+   +
        |       |               |       |   |
        +   +   +   +   +---+---+---+   +   +
        |   |       |   |       |       |   |
        +   +   +---+---+   +   +   +---+   +
        |   |               |       |       |
        +---+---+---+---+---+---+---+---+---+
    """
    return world_from_segments(
        name,
        np.array(MAZE2_SEGMENTS_M),
        _cell_centres_m(MAZE2_COLUMN_WIDTHS_M, MAZE2_ROW_HEIGHTS_M),
        start_pose=MAZE2_START_POSE,
        metadata={
            "source": "fixed_maze",
            "maze": "maze2",
            "spec": "maze2",
            "column_widths_m": MAZE2_COLUMN_WIDTHS_M,
            "row_heights_m": MAZE2_ROW_HEIGHTS_M,
        },
    )
