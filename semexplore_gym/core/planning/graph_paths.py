"""Paths over the topometric graph for Algorithm 1 (:mod:`.graph_search`).

A search path (:class:`SearchPath`) is a chain of openings joined by the map's edges; the
robot reaches the first opening along a *first leg* through its own area (:func:`first_legs`).
A candidate's metric polyline joins the first leg, every edge's path and the goal
(:func:`path_parts`, joined lazily by :class:`PathParts`).
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np

from semexplore_gym.core.planning.graph_search_kernels import first_leg_offers
from semexplore_gym.core.planning.polyline import (
    dedupe_polyline,
    oriented_polyline,
    polyline_length,
    project_onto_polyline,
)
from semexplore_gym.core.topometric.types import TopometricMap


class SearchPath(NamedTuple):
    """A path of the search (a named tuple: the search builds thousands)."""

    nodes: tuple[int, ...]
    edges: tuple[int, ...]
    cost: float
    length_m: float


class PathParts:
    """A candidate's polyline as the pieces :func:`assemble_path` joins (built when first read: a
    replan scores tens of frontiers and drives to one)."""

    __slots__ = ("parts",)

    def __init__(self, parts: list[np.ndarray]) -> None:
        self.parts = parts

    def __getstate__(self) -> dict[str, Any]:
        return {"parts": self.parts}

    def __setstate__(self, state: dict[str, Any]) -> None:
        self.parts = state["parts"]

    def build(self) -> np.ndarray:
        return dedupe_polyline(np.concatenate(self.parts, axis=0))


def edge_polyline(tmap: TopometricMap, k: int, from_node: int) -> np.ndarray:
    e = tmap.edges[k]
    to_node = e.opening_b if from_node == e.opening_a else e.opening_a
    return oriented_polyline(
        e.path_m, tmap.openings[from_node].midpoint_m, tmap.openings[to_node].midpoint_m
    )


def first_legs(
    tmap: TopometricMap, area_id: int, robot_xy: tuple[float, float]
) -> dict[int, np.ndarray]:
    """Polylines from the robot to every opening of its area, along the area's own paths.

    The robot joins the nearest point of each path of its area in a straight line, then follows
    that path to the opening. Openings no path reaches are joined in a straight line. The
    projections and lengths of the area's edge paths come from one compiled call
    (:func:`~semexplore_gym.core.planning.graph_search_kernels.first_leg_offers`, the same values as
    :func:`project_onto_polyline` and ``polyline_length``); each opening's polyline is built
    once, for the shortest offer (the first of equals).
    """
    area = tmap.areas[area_id]
    r = np.asarray(robot_xy, dtype=np.float64)
    # node -> (length, nearest point q, the rest of the way after q)
    best: dict[int, tuple[float, np.ndarray, np.ndarray]] = {}

    def offer(node: int, length: float, q: np.ndarray, rest: np.ndarray) -> None:
        if node not in best or length < best[node][0]:
            best[node] = (length, q, rest)

    edges = [(k, e) for k, e in enumerate(tmap.edges) if e.area_id == area_id]
    if edges:
        polys = [edge_polyline(tmap, k, e.opening_a) for k, e in edges]
        sizes = [len(p) for p in polys]
        if min(sizes) == 0:
            raise ValueError(f"an edge of area {area_id} has an empty path")
        starts = np.zeros(len(polys) + 1, dtype=np.int64)
        np.cumsum(sizes, out=starts[1:])
        seg_idx = np.empty(len(polys), dtype=np.int64)
        q_xy = np.empty((len(polys), 2))
        lengths = np.empty((len(polys), 2))
        first_leg_offers(
            np.concatenate(polys), starts, float(r[0]), float(r[1]), seg_idx, q_xy, lengths
        )
        for (_k, e), poly, i, q, (back_m, on_m) in zip(
            edges, polys, seg_idx.tolist(), q_xy, lengths.tolist(), strict=True
        ):
            offer(e.opening_a, back_m, q, poly[: i + 1][::-1])
            offer(e.opening_b, on_m, q, poly[i + 1 :])
    for oid, path in area.paths_m.items():
        if oid in best or oid not in area.opening_ids:
            continue
        # Single-opening areas (dead ends) have no edges; their path starts at the opening.
        poly = oriented_polyline(path, tmap.openings[oid].midpoint_m, tuple(np.asarray(path)[-1]))
        dist, q, i, _ = project_onto_polyline(poly, robot_xy)
        rest = poly[: i + 1][::-1]
        offer(oid, dist + polyline_length(np.vstack([q, rest])), q, rest)
    for oid in area.opening_ids:
        if oid not in best and 0 <= oid < len(tmap.openings):
            m = np.asarray(tmap.openings[oid].midpoint_m, dtype=np.float64)
            offer(oid, float(np.hypot(*(m - r))), m, np.empty((0, 2)))
    return {node: dedupe_polyline(np.vstack([r, q, rest])) for node, (_, q, rest) in best.items()}


def assemble_path(
    tmap: TopometricMap,
    path: SearchPath,
    first_leg: np.ndarray,
    goal_xy: tuple[float, float],
    polylines: dict[tuple[int, int], np.ndarray] | None = None,
) -> np.ndarray:
    """The candidate's polyline: first leg, the edges' paths, the goal. ``polylines`` caches
    :func:`edge_polyline` by ``(edge, from_node)`` across calls."""
    return path_parts(tmap, path, first_leg, goal_xy, polylines).build()


def path_parts(
    tmap: TopometricMap,
    path: SearchPath,
    first_leg: np.ndarray,
    goal_xy: tuple[float, float],
    polylines: dict[tuple[int, int], np.ndarray] | None = None,
) -> PathParts:
    """The pieces of :func:`assemble_path`'s polyline, not yet joined."""
    parts = [first_leg]
    for j, k in enumerate(path.edges):
        key = (k, path.nodes[j])
        poly = polylines.get(key) if polylines is not None else None
        if poly is None:
            poly = edge_polyline(tmap, k, path.nodes[j])
            if polylines is not None:
                polylines[key] = poly
        parts.append(poly)
    parts.append(np.asarray([goal_xy], dtype=np.float64))
    return PathParts(parts)
