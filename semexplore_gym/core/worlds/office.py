"""Procedural office floors (``"office:seed=3,size_m=20"``).

A square floor of ``size_m`` is cut into horizontal bands. Each band has a corridor along its
middle with a row of rooms on either side; neighbouring bands meet back to back. When there
are two or more bands, one or two vertical corridors cut through the room rows and join all
horizontal corridors (two make a loop). Room rows are split into rooms 2.5-5 m wide. Every room
has a door to its corridor; rooms next to a vertical corridor may get a second door onto it;
neighbouring rooms are joined by an inner door with probability ``room_link_prob``, and some
partitions are left out, giving open-plan rooms.

The floor is drawn on a 0.05 m raster with 0.1 m thick walls and turned into wall segments
with :func:`~semexplore_gym.core.worlds.build.world_from_free_mask`, so the world is a raster
world: both faces of every wall are segments and the free mask is exact.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from semexplore_gym.core.grid import GridGeometry
from semexplore_gym.core.worlds.build import world_from_free_mask
from semexplore_gym.core.worlds.grid_maze import check_range
from semexplore_gym.core.worlds.world import World

_CLUTTER_GAP_M = 0.6
_RES_M = 0.05
_WALL_CELLS = 2  # 0.1 m walls
_MIN_ROOM_DEPTH_M = 3.0
_MIN_ROOM_WIDTH_M = 2.5
_MAX_ROOM_WIDTH_M = 5.0
_DOOR_MARGIN_M = 0.3  # door jamb to the nearest corner
_OPEN_PLAN_PROB = 0.15
_SIDE_DOOR_PROB = 0.5


@dataclass(frozen=True)
class OfficeParams:
    """Parameters of a procedural office floor.

    Attributes:
        seed: Random seed; the same seed gives the same floor.
        size_m: Side of the square floor in metres.
        corridor_width_m: Width of every corridor (wall face to wall face).
        door_width_m: Width of every door opening.
        room_link_prob: Probability that two neighbouring rooms get a door between them.
        clutter: Furniture boxes per 10 m^2 of room floor (0: empty rooms). Boxes are 0.3-0.8 m
            a side and stay at least ``_CLUTTER_GAP_M`` from walls and each other, so every
            room stays reachable; they come from their own random stream, so the floor plan
            is the same as without clutter.
    """

    seed: int = 0
    size_m: float = 20.0
    corridor_width_m: float = 1.5
    door_width_m: float = 0.9
    room_link_prob: float = 0.3
    clutter: float = 0.0

    def __post_init__(self) -> None:
        if (
            isinstance(self.seed, bool)
            or not isinstance(self.seed, (int, np.integer))
            or self.seed < 0
        ):
            raise ValueError(f"office parameter seed={self.seed!r} must be a non-negative integer")
        check_range("office", "size_m", self.size_m, 8.0, 100.0)
        check_range("office", "corridor_width_m", self.corridor_width_m, 0.8, 4.0)
        check_range("office", "door_width_m", self.door_width_m, 0.7, 2.0)
        check_range("office", "room_link_prob", self.room_link_prob, 0.0, 1.0)
        check_range("office", "clutter", self.clutter, 0.0, 5.0)


def _add_clutter(
    free: np.ndarray, room_rows: list[tuple[int, int, str]], params: OfficeParams
) -> None:
    """Put furniture boxes into the rooms of ``free`` (in place), from their own random stream.

    A box is kept only where every cell of it is at least ``_CLUTTER_GAP_M`` from any non-free
    cell (walls and boxes placed before), so no passage closes.
    """
    rng = np.random.default_rng([params.seed, 1])
    gap = _cells(_CLUTTER_GAP_M)
    lo, hi = _cells(0.3), _cells(0.8)
    rows = [(y0, y1) for y0, y1, _side in room_rows if y1 - y0 > hi + 2 * gap]
    floor_m2 = sum(int(free[y0:y1].sum()) for y0, y1 in rows) * _RES_M**2
    target = int(round(params.clutter * floor_m2 / 10.0))
    placed = 0
    for _ in range(target * 30):
        if placed >= target or not rows:
            break
        y0, y1 = rows[int(rng.integers(len(rows)))]
        h, w = (int(v) for v in rng.integers(lo, hi + 1, 2))
        r = int(rng.integers(y0, y1 - h))
        c = int(rng.integers(0, free.shape[1] - w))
        window = free[max(r - gap, 0) : r + h + gap, max(c - gap, 0) : c + w + gap]
        if r - gap < 0 or c - gap < 0 or window.shape != (h + 2 * gap, w + 2 * gap):
            continue
        if window.all():
            free[r : r + h, c : c + w] = False
            placed += 1


def _cells(length_m: float) -> int:
    return int(round(length_m / _RES_M))


def _split_row(xa: int, xb: int, rng: np.random.Generator) -> list[int]:
    """Partition positions (cell index of the partition's centre) splitting [xa, xb) into rooms."""
    lo, hi = _cells(_MIN_ROOM_WIDTH_M), _cells(_MAX_ROOM_WIDTH_M)
    cuts = []
    x = xa
    while xb - x > hi:
        x += int(rng.integers(lo, hi + 1))
        if xb - x < lo:
            break
        cuts.append(x)
    return cuts


def _carve_rooms(
    free: np.ndarray,
    room_rows: list[tuple[int, int, str]],
    corridors: list[tuple[int, int]],
    verticals: list[tuple[int, int]],
    params: OfficeParams,
    rng: np.random.Generator,
) -> None:
    """Split each row of rooms beside a corridor into rooms with doors, in place."""
    n = free.shape[1]
    t = _WALL_CELLS
    dw = _cells(params.door_width_m)
    margin = _cells(_DOOR_MARGIN_M)
    for ry0, ry1, side in room_rows:
        crossed = [v for v in verticals if corridors[0][0] <= ry0 and ry1 <= corridors[-1][1]]
        # Spans of the row between vertical corridors: (x0, x1, left wall col, right wall col),
        # a wall col being the first column of a vertical corridor's side wall, or None.
        spans: list[tuple[int, int, int | None, int | None]] = []
        x, left_wall = 0, None
        for vx0, vx1 in crossed:
            spans.append((x, vx0 - t, left_wall, vx0 - t))
            x, left_wall = vx1 + t, vx1
        spans.append((x, n, left_wall, None))
        door_rows = (ry1, ry1 + t) if side == "above" else (ry0 - t, ry0)
        for sx0, sx1, left_wall, right_wall in spans:
            if sx1 - sx0 < dw + 2 * margin:
                free[ry0:ry1, sx0:sx1] = False  # too narrow for a door: solid
                continue
            cuts = _split_row(sx0, sx1, rng)
            bounds = [sx0, *cuts, sx1]
            drawn = []
            for cut in cuts:
                if rng.random() < _OPEN_PLAN_PROB:
                    drawn.append(False)
                    continue
                free[ry0:ry1, cut - t // 2 : cut + t - t // 2] = False
                drawn.append(True)
            for k in range(len(bounds) - 1):
                rx0 = bounds[k] + (t - t // 2 if k > 0 else 0)
                rx1 = bounds[k + 1] - (t // 2 if k < len(bounds) - 2 else 0)
                dx = int(rng.integers(rx0 + margin, max(rx0 + margin + 1, rx1 - margin - dw + 1)))
                free[door_rows[0] : door_rows[1], dx : dx + dw] = True
                if (
                    k < len(cuts)
                    and drawn[k]
                    and rng.random() < params.room_link_prob
                    and ry1 - ry0 >= dw + 2 * margin
                ):
                    dy = int(rng.integers(ry0 + margin, ry1 - margin - dw + 1))
                    free[dy : dy + dw, cuts[k] - t // 2 : cuts[k] + t - t // 2] = True
            # The end rooms of a span may also open onto the vertical corridor beside them.
            for wall_col in (left_wall, right_wall):
                if (
                    wall_col is not None
                    and ry1 - ry0 >= dw + 2 * margin
                    and rng.random() < _SIDE_DOOR_PROB
                ):
                    dy = int(rng.integers(ry0 + margin, ry1 - margin - dw + 1))
                    free[dy : dy + dw, wall_col : wall_col + t] = True


def _horizontal_corridors(
    free: np.ndarray, cw: int, d_min: int, rng: np.random.Generator
) -> tuple[list[tuple[int, int]], list[tuple[int, int, str]]]:
    """Cut the map into bands, each a corridor of ``cw`` cells with a row of rooms on either
    side (walls drawn in ``free``). Returns the corridors' ``(y0, y1)`` and the room rows'
    ``(y0, y1, side of the corridor: "above"/"below")``."""
    n = free.shape[0]
    t = _WALL_CELLS
    n_bands = max(1, n // (2 * d_min + cw + 3 * t))
    edges = np.round(np.linspace(0, n, n_bands + 1)).astype(int)
    corridors: list[tuple[int, int]] = []
    room_rows: list[tuple[int, int, str]] = []
    for i in range(n_bands):
        lo = edges[i] + (t - t // 2 if i > 0 else 0)
        hi = edges[i + 1] - (t // 2 if i < n_bands - 1 else 0)
        room_space = hi - lo - cw - 2 * t
        jitter = room_space // 10
        lower = room_space // 2 + int(rng.integers(-jitter, jitter + 1))
        y0 = lo + lower + t
        y1 = y0 + cw
        free[y0 - t : y0, :] = False
        free[y1 : y1 + t, :] = False
        if i < n_bands - 1:
            free[edges[i + 1] - t // 2 : edges[i + 1] + t - t // 2, :] = False
        corridors.append((y0, y1))
        room_rows.append((lo, y0 - t, "above"))
        room_rows.append((y1 + t, hi, "below"))
    return corridors, room_rows


def _vertical_corridors(
    free: np.ndarray, cw: int, corridors: list[tuple[int, int]], rng: np.random.Generator
) -> list[tuple[int, int]]:
    """With two bands or more, one or two vertical corridors joining them (carved in
    ``free``); their ``(x0, x1)``, left to right."""
    n = free.shape[0]
    t = _WALL_CELLS
    verticals: list[tuple[int, int]] = []
    if len(corridors) < 2:
        return verticals
    room_w = _cells(_MIN_ROOM_WIDTH_M)
    x0 = int(rng.integers(n // 4, max(n // 4 + 1, 3 * n // 4 - cw)))
    verticals.append((x0, x0 + cw))
    if rng.random() < 0.5:
        # A second vertical corridor near the end farther from the first closes a loop.
        if x0 > n // 2:
            x2 = int(rng.integers(room_w + t, 2 * room_w + t))
        else:
            x2 = n - cw - int(rng.integers(room_w + t, 2 * room_w + t))
        if abs(x2 - x0) > cw + 2 * t + room_w:
            verticals.append((x2, x2 + cw))
    verticals.sort()
    ya, yb = corridors[0][0], corridors[-1][1]
    for vx0, vx1 in verticals:
        free[ya:yb, vx0 - t : vx0] = False
        free[ya:yb, vx1 : vx1 + t] = False
        free[ya:yb, vx0:vx1] = True
    for cy0, cy1 in corridors:
        free[cy0:cy1, :] = True
    return verticals


def generate_office(params: OfficeParams, name: str | None = None) -> World:
    """A procedural office world (deterministic for ``params.seed``).

    The start pose is in the first corridor, facing +x.
    """
    rng = np.random.default_rng(params.seed)
    n = _cells(params.size_m)
    cw = _cells(params.corridor_width_m)
    d_min = _cells(_MIN_ROOM_DEPTH_M)
    free = np.ones((n, n), dtype=bool)

    corridors, room_rows = _horizontal_corridors(free, cw, d_min, rng)
    verticals = _vertical_corridors(free, cw, corridors, rng)

    _carve_rooms(free, room_rows, corridors, verticals, params, rng)

    if params.clutter > 0:
        _add_clutter(free, room_rows, params)
    cy0, cy1 = corridors[0]
    start_col = (verticals[0][0] + verticals[0][1]) / 2 if verticals else n / 2
    start = (start_col * _RES_M, 0.5 * (cy0 + cy1) * _RES_M, 0.0)
    spec = (
        f"office:seed={params.seed},size_m={params.size_m:g},corridor_width_m={params.corridor_width_m:g},"
        f"door_width_m={params.door_width_m:g},room_link_prob={params.room_link_prob:g}"
        + (f",clutter={params.clutter:g}" if params.clutter > 0 else "")
    )
    return world_from_free_mask(
        name if name is not None else spec,
        free,
        GridGeometry(_RES_M, 0.0, 0.0, n, n),
        start_pose=start,
        bounds_m=(0.0, 0.0, n * _RES_M, n * _RES_M),
        metadata={
            "source": "procedural",
            "family": "office",
            "params": asdict(params),
            "spec": spec,
            "n_corridors": len(corridors),
            "n_vertical_corridors": len(verticals),
        },
    )
