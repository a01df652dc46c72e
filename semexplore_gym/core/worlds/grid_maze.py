"""Procedural grid mazes (``"maze:seed=3,size_m=10,corridor_width_m=0.8,braid=0.3"``).

A square grid of cells, each ``corridor_width_m`` wide, carved by a randomised depth-first
search into a *perfect* maze (exactly one path between any two cells, so every loop-free
dead end is a real dead end). ``braid`` then removes that fraction of the dead ends by opening
one more wall of each, preferring a wall to another dead end; ``braid=1`` leaves none, which
makes a maze full of loops. Walls are thin segments on the cell borders, merged into maximal
straight runs.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from semexplore_gym.core.worlds.build import world_from_segments
from semexplore_gym.core.worlds.world import World


def check_range(family: str, key: str, value: float, lo: float, hi: float) -> None:
    """Raise a ValueError naming ``family``'s parameter ``key`` unless ``lo <= value <= hi``."""
    if not (np.isfinite(value) and lo <= value <= hi):
        raise ValueError(f"{family} parameter {key}={value!r} is outside [{lo}, {hi}]")


@dataclass(frozen=True)
class MazeParams:
    """Parameters of a procedural grid maze.

    Attributes:
        seed: Random seed; the same seed gives the same maze.
        size_m: Target side of the square maze, in metres (rounded to whole cells).
        corridor_width_m: Cell pitch = corridor width between wall centre lines.
        braid: Fraction of dead ends removed (0 = perfect maze, 1 = no dead ends).
    """

    seed: int = 0
    size_m: float = 8.0
    corridor_width_m: float = 0.8
    braid: float = 0.0

    def __post_init__(self) -> None:
        if (
            isinstance(self.seed, bool)
            or not isinstance(self.seed, (int, np.integer))
            or self.seed < 0
        ):
            raise ValueError(f"maze parameter seed={self.seed!r} must be a non-negative integer")
        check_range("maze", "corridor_width_m", self.corridor_width_m, 0.6, 5.0)
        check_range("maze", "size_m", self.size_m, 2.0 * self.corridor_width_m, 50.0)
        check_range("maze", "braid", self.braid, 0.0, 1.0)

    @property
    def n_cells(self) -> int:
        """Cells per side."""
        return max(2, int(round(self.size_m / self.corridor_width_m)))


def carve_maze(
    n_rows: int, n_cols: int, rng: np.random.Generator, braid: float = 0.0
) -> tuple[np.ndarray, np.ndarray]:
    """Carve a maze on an ``n_rows x n_cols`` cell grid.

    Returns:
        ``(h_walls, v_walls)``: ``h_walls[k, c]`` (shape ``(n_rows + 1, n_cols)``) is True when
        the wall on horizontal grid line ``k`` (line 0 at the bottom) above column ``c`` stands;
        ``v_walls[r, k]`` (shape ``(n_rows, n_cols + 1)``) likewise for vertical line ``k``.
        The outer border is always closed.
    """
    h_walls = np.ones((n_rows + 1, n_cols), dtype=bool)
    v_walls = np.ones((n_rows, n_cols + 1), dtype=bool)
    visited = np.zeros((n_rows, n_cols), dtype=bool)
    start = (int(rng.integers(n_rows)), int(rng.integers(n_cols)))
    stack = [start]
    visited[start] = True
    steps = ((1, 0), (-1, 0), (0, 1), (0, -1))
    while stack:
        r, c = stack[-1]
        options = [
            (r + dr, c + dc)
            for dr, dc in steps
            if 0 <= r + dr < n_rows and 0 <= c + dc < n_cols and not visited[r + dr, c + dc]
        ]
        if not options:
            stack.pop()
            continue
        r2, c2 = options[int(rng.integers(len(options)))]
        _open_wall(h_walls, v_walls, (r, c), (r2, c2))
        visited[r2, c2] = True
        stack.append((r2, c2))

    if braid > 0.0:
        dead = [tuple(rc) for rc in np.argwhere(_open_sides(h_walls, v_walls) == 1)]
        order = rng.permutation(len(dead))
        n_remove = int(round(braid * len(dead)))
        for idx in order[:n_remove]:
            r, c = dead[idx]
            opens = _open_sides(h_walls, v_walls)
            if opens[r, c] != 1:
                continue  # already opened from a neighbouring dead end
            closed = [
                (r + dr, c + dc)
                for dr, dc in steps
                if 0 <= r + dr < n_rows
                and 0 <= c + dc < n_cols
                and _wall_between(h_walls, v_walls, (r, c), (r + dr, c + dc))
            ]
            if not closed:
                continue
            preferred = [rc for rc in closed if opens[rc] == 1]
            pool = preferred or closed
            _open_wall(h_walls, v_walls, (r, c), pool[int(rng.integers(len(pool)))])
    return h_walls, v_walls


def _open_sides(h_walls: np.ndarray, v_walls: np.ndarray) -> np.ndarray:
    return (~h_walls[1:]).astype(np.int64) + ~h_walls[:-1] + ~v_walls[:, 1:] + ~v_walls[:, :-1]


def _wall_between(
    h_walls: np.ndarray, v_walls: np.ndarray, a: tuple[int, int], b: tuple[int, int]
) -> bool:
    (r, c), (r2, c2) = a, b
    if r2 != r:
        return bool(h_walls[max(r, r2), c])
    return bool(v_walls[r, max(c, c2)])


def _open_wall(
    h_walls: np.ndarray, v_walls: np.ndarray, a: tuple[int, int], b: tuple[int, int]
) -> None:
    (r, c), (r2, c2) = a, b
    if r2 != r:
        h_walls[max(r, r2), c] = False
    else:
        v_walls[r, max(c, c2)] = False


def maze_walls_to_segments(
    h_walls: np.ndarray, v_walls: np.ndarray, xs_m: np.ndarray, ys_m: np.ndarray
) -> np.ndarray:
    """Merge standing cell walls into maximal straight segments.

    Args:
        h_walls: ``(n_rows + 1, n_cols)`` from :func:`carve_maze`.
        v_walls: ``(n_rows, n_cols + 1)`` from :func:`carve_maze`.
        xs_m: ``(n_cols + 1,)`` x of the vertical grid lines.
        ys_m: ``(n_rows + 1,)`` y of the horizontal grid lines.

    Returns:
        ``(N, 4)`` segments, horizontal ones first.
    """
    out = []
    for walls, along, across, horizontal in (
        (h_walls, xs_m, ys_m, True),
        (v_walls.T, ys_m, xs_m, False),
    ):
        padded = np.zeros((walls.shape[0], walls.shape[1] + 2), dtype=np.int8)
        padded[:, 1:-1] = walls
        d = np.diff(padded, axis=1)
        line, first = np.nonzero(d == 1)
        _, last = np.nonzero(d == -1)
        a0 = along[first]
        a1 = along[last]
        k = across[line]
        out.append(
            np.column_stack([a0, k, a1, k]) if horizontal else np.column_stack([k, a0, k, a1])
        )
    return np.vstack(out)


def generate_maze(params: MazeParams, name: str | None = None) -> World:
    """A procedural grid maze world (deterministic for ``params.seed``).

    The start pose is the centre of a random cell, facing one of its open sides.
    """
    rng = np.random.default_rng(params.seed)
    n = params.n_cells
    w = params.corridor_width_m
    h_walls, v_walls = carve_maze(n, n, rng, params.braid)
    lines_m = np.arange(n + 1) * w
    segments = maze_walls_to_segments(h_walls, v_walls, lines_m, lines_m)
    centres = (np.arange(n) + 0.5) * w
    gx, gy = np.meshgrid(centres, centres)
    interior = np.column_stack([gx.ravel(), gy.ravel()])

    r, c = int(rng.integers(n)), int(rng.integers(n))
    headings = []
    if not h_walls[r + 1, c]:
        headings.append(np.pi / 2)
    if not h_walls[r, c]:
        headings.append(-np.pi / 2)
    if not v_walls[r, c + 1]:
        headings.append(0.0)
    if not v_walls[r, c]:
        headings.append(np.pi)
    yaw = float(headings[int(rng.integers(len(headings)))])
    start = (float(centres[c]), float(centres[r]), yaw)
    spec = f"maze:seed={params.seed},size_m={params.size_m:g},corridor_width_m={w:g},braid={params.braid:g}"
    return world_from_segments(
        name if name is not None else spec,
        segments,
        interior,
        start_pose=start,
        metadata={
            "source": "procedural",
            "family": "maze",
            "params": asdict(params),
            "spec": spec,
            "n_cells": n,
        },
    )
