"""Data types of the semantic topometric map (the output of :func:`segment_map`).

These types are the contract between the segmentation and every planner that reads it.
Coordinates are world metres unless a name says ``cells``; grids follow the (row, col)
convention of :mod:`semexplore_gym.core`.

The per-element records (:class:`Opening`, :class:`Area`, :class:`Frontier`,
:class:`GraphEdge`) are immutable named tuples: a large map has tens of thousands of them, and
a tuple is built about five times faster than a frozen dataclass instance. Read them by field
name; ``rec._replace(field=value)`` makes a modified copy.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import IntEnum
from typing import TYPE_CHECKING, Any, NamedTuple

import numpy as np

from semexplore_gym.core.grid import GridGeometry
from semexplore_gym.core.lazy_field import LazyField


class AreaType(IntEnum):
    """Semantic type of an area. The values follow GRID-FAST's type codes."""

    INTERSECTION = 0
    PATHWAY = 10
    DEAD_END = 20
    FRONTIER_PATHWAY = 30


class Opening(NamedTuple):
    """A cut across free space between two areas, or between an area and unknown space.

    Attributes:
        id: Index into :attr:`TopometricMap.openings`.
        endpoints_m: ``(2, 2)`` array, the two wall-side ends ``[[x0, y0], [x1, y1]]``.
        midpoint_m: ``(x, y)`` centre of the opening.
        width_m: Free width of the opening.
        area_ids: The ids of the areas on its two sides; ``-1`` stands for unknown space.
        is_frontier: True when one side is unknown space (the opening *is* a frontier).
        anchor_m: ``(x, y)`` where the robot crosses the opening: a point at least the
            clearance away from walls and unknown space, where the areas' paths start and end
            (the skeleton point of a doorway; for a frontier, the frontier's target). ``None``
            when not computed.
    """

    id: int
    endpoints_m: np.ndarray
    midpoint_m: tuple[float, float]
    width_m: float
    area_ids: tuple[int, int]
    is_frontier: bool
    anchor_m: tuple[float, float] | None = None


class Area(NamedTuple):
    """One semantic region of free space.

    Attributes:
        id: Identifier, stable across successive segmentations of a growing map (areas are
            matched by position), so planners can remember visited areas.
        type: :class:`AreaType`.
        centre_m: ``(x, y)`` a point inside the area, far from its walls.
        opening_ids: Ids of the openings on its border.
        paths_m: Polylines ``(K, 2)`` through the area, keyed by opening id: for an intersection
            the path from that opening to the centre; for a pathway the path from that opening to
            the other opening; for a dead end the path from its opening to its far end. A robot
            of the segmentation's clearance can follow every path.
        n_cells: Number of grid cells in the area.
    """

    id: int
    type: AreaType
    centre_m: tuple[float, float]
    opening_ids: tuple[int, ...]
    paths_m: dict[int, np.ndarray]
    n_cells: int


class Frontier(NamedTuple):
    """The frontier at the far end of a frontier pathway.

    A frontier pathway usually has one frontier; a lone corridor open at both ends (no
    intersection yet) is one frontier pathway with two.

    Attributes:
        area_id: The frontier pathway it belongs to.
        opening_id: The opening to unknown space (its geometric middle is
            ``openings[opening_id].midpoint_m``).
        midpoint_m: ``(x, y)`` the exploration target: where the robot can stand next to the
            opening (free, at least the clearance from walls and unknown space); the frontier
            pathway's path ends there.
        width_m: Width of the opening.
        intersection_id: The nearest intersection leading to it (``I`` in the paper), or
            ``None`` when the map has no intersection connected to it yet.
        path_length_m: ``p_l``: path length from the frontier to that intersection (to the
            pathway's other end when ``intersection_id`` is None).
    """

    area_id: int
    opening_id: int
    midpoint_m: tuple[float, float]
    width_m: float
    intersection_id: int | None
    path_length_m: float


class GraphEdge(NamedTuple):
    """An edge of the topometric graph, whose nodes are openings (see :class:`TopometricMap`)."""

    opening_a: int
    opening_b: int
    area_id: int
    length_m: float
    path_m: np.ndarray


class AreaRasterCrop:
    """The area raster of a :class:`TopometricMap` held as its labelled window.

    A large map is mostly unknown while it is explored (Willow Garage: 1.3 M cells, of which
    the free cells' bounding box covers 1-13 % in a 300 s mission). The segmentation hands its
    map this window; the full ``(H, W)`` raster (-1 outside the window) is only built when
    ``TopometricMap.area_ids`` is read, and point look-ups read the window directly.

    Attributes:
        shape: ``(H, W)`` of the full raster.
        r0: Row of the window's first row in the full raster (>= 0).
        c0: Column of the window's first column (>= 0).
        ids: ``(h, w)`` int32 area ids of the window, -1 where no area.
    """

    __slots__ = ("shape", "r0", "c0", "ids")

    def __init__(self, shape: tuple[int, int], r0: int, c0: int, ids: np.ndarray) -> None:
        self.shape = (int(shape[0]), int(shape[1]))
        self.r0 = int(r0)
        self.c0 = int(c0)
        self.ids = ids

    def __getstate__(self) -> dict[str, Any]:
        return {k: getattr(self, k) for k in self.__slots__}

    def __setstate__(self, state: dict[str, Any]) -> None:
        for k, v in state.items():
            setattr(self, k, v)

    def full(self) -> np.ndarray:
        """The ``(H, W)`` int32 raster."""
        out = np.full(self.shape, -1, dtype=np.int32)
        h, w = self.ids.shape
        out[self.r0 : self.r0 + h, self.c0 : self.c0 + w] = self.ids
        return out

    def at(self, rows: np.ndarray, cols: np.ndarray) -> np.ndarray:
        """Ids at cells inside the full raster (int64 row / column arrays), -1 off the window."""
        h, w = self.ids.shape
        r = np.asarray(rows) - self.r0
        c = np.asarray(cols) - self.c0
        inside = (r >= 0) & (r < h) & (c >= 0) & (c < w)
        out = np.full(r.shape, -1, dtype=np.int32)
        out[inside] = self.ids[r[inside], c[inside]]
        return out

    def labelled_cells(self) -> np.ndarray:
        """``np.argwhere(full() >= 0)`` (the same cells, in the same row-major order)."""
        cells = np.argwhere(self.ids >= 0)
        cells[:, 0] += self.r0
        cells[:, 1] += self.c0
        return cells


@dataclass(frozen=True)
class TopometricMap:
    """A semantic topometric map of an explored occupancy grid.

    Attributes:
        geometry: The grid frame the map was computed on.
        area_ids: ``(H, W)`` int32 raster, the area id of every reachable free cell, -1 elsewhere
            (cells of occupied specks and unknown holes that the noise filter turned free count
            as free). The segmentation passes an :class:`AreaRasterCrop`; the full raster is
            built when this attribute is first read (:meth:`area_ids_at` reads the window).
        areas: Areas by id.
        openings: Openings, ``openings[i].id == i``.
        frontiers: One per frontier opening (one per frontier pathway, two for a lone corridor
            open at both ends).
        edges: Graph edges. Nodes are openings; inside each area every pair of its openings is
            joined (through the centre for intersections) with the metric length of the path.
        mean_intersection_path_m: ``L_path``: mean length of the paths between adjacent
            intersections; ``nan`` when fewer than two intersections are connected.
        clearance_m: The robot clearance (radius + margin) used.
        time_ms: Wall time the segmentation took.
    """

    geometry: GridGeometry
    if TYPE_CHECKING:
        area_ids: np.ndarray
    else:
        # the descriptor stores an array or an AreaRasterCrop and always returns the array
        area_ids: np.ndarray = LazyField(AreaRasterCrop, AreaRasterCrop.full)
    areas: dict[int, Area]
    openings: list[Opening]
    frontiers: list[Frontier]
    edges: list[GraphEdge]
    mean_intersection_path_m: float
    clearance_m: float
    time_ms: float = 0.0
    extras: dict = field(default_factory=dict)

    def areas_of_type(self, area_type: AreaType) -> list[Area]:
        return [a for a in self.areas.values() if a.type == area_type]

    def n_openings(self, intersection_id: int) -> int:
        """``O(I)``: the number of openings of an intersection."""
        return len(self.areas[intersection_id].opening_ids)

    def n_frontier_pathways(self, intersection_id: int) -> int:
        """``P_u(I)``: the number of the intersection's pathways that lead directly to a frontier."""
        n = 0
        for oid in self.areas[intersection_id].opening_ids:
            for aid in self.openings[oid].area_ids:
                if (
                    aid >= 0
                    and aid != intersection_id
                    and self.areas[aid].type == AreaType.FRONTIER_PATHWAY
                ):
                    n += 1
        return n

    def area_ids_at(self, rows: np.ndarray, cols: np.ndarray) -> np.ndarray:
        """``area_ids[rows, cols]`` for cells inside the raster, without building the full
        raster when the map holds only its labelled window."""
        v = self.__dict__["_area_ids"]
        if isinstance(v, AreaRasterCrop):
            return v.at(rows, cols)
        return np.asarray(v[rows, cols])

    def area_at(self, x_m: float, y_m: float) -> int:
        """Id of the area containing a point, or of the nearest area cell; -1 if the map has none."""
        g = self.geometry
        row, col = g.world_to_grid(x_m, y_m)
        r, c = int(row), int(col)
        if 0 <= r < g.height and 0 <= c < g.width:
            here = int(self.area_ids_at(np.array([r]), np.array([c]))[0])
            if here >= 0:
                return here
        v = self.__dict__["_area_ids"]
        cells = v.labelled_cells() if isinstance(v, AreaRasterCrop) else np.argwhere(v >= 0)
        if len(cells) == 0:
            return -1
        d2 = (cells[:, 0] - r) ** 2 + (cells[:, 1] - c) ** 2
        rr, cc = cells[int(np.argmin(d2))]
        return int(self.area_ids_at(np.array([rr]), np.array([cc]))[0])

    def area_type_raster(self) -> np.ndarray:
        """``(H, W)`` int16 raster of :class:`AreaType` values (-1 where no area): the env overlay."""
        if not self.areas:
            return np.full(self.area_ids.shape, -1, dtype=np.int16)
        top = max(self.areas) + 2
        lut = np.full(top, -1, dtype=np.int16)
        for a in self.areas.values():
            lut[a.id + 1] = int(a.type)
        return lut[np.clip(self.area_ids, -1, top - 2) + 1]

    def frontier_of_area(self, area_id: int) -> list[Frontier]:
        """The frontiers of one frontier pathway (usually one)."""
        return [f for f in self.frontiers if f.area_id == area_id]

    def counts(self) -> dict[str, int]:
        return {
            "intersections": len(self.areas_of_type(AreaType.INTERSECTION)),
            "pathways": len(self.areas_of_type(AreaType.PATHWAY)),
            "dead_ends": len(self.areas_of_type(AreaType.DEAD_END)),
            "frontier_pathways": len(self.areas_of_type(AreaType.FRONTIER_PATHWAY)),
        }
