"""JSON export of a :class:`TopometricMap` for other tools.

:func:`to_json_dict` returns plain JSON types (``json.dumps`` works as is; ``nan`` becomes
``null``). Coordinates are world metres, ids are the map's ids. Layout (format
``"semexplore-topometric/1"``)::

    {
      "format": "semexplore-topometric/1",
      "geometry": {resolution_m, origin_x_m, origin_y_m, height, width},
      "clearance_m": float, "time_ms": float, "mean_intersection_path_m": float | null,
      "counts": {"intersections", "pathways", "dead_ends", "frontier_pathways"},
      "areas": [{"id", "type", "type_code", "centre_m", "n_cells", "opening_ids",
                 "n_openings", "n_frontier_pathways", "paths_m": {"<opening id>": [[x, y], ...]}}],
      "openings": [{"id", "endpoints_m", "midpoint_m", "anchor_m", "width_m", "area_ids", "is_frontier"}],
      "frontiers": [{"area_id", "opening_id", "midpoint_m", "width_m", "intersection_id", "path_length_m"}],
      "opening_graph": <node-link graph>,
      "area_graph": <node-link graph>
    }

Both graphs use networkx's node-link format (``networkx.node_link_graph(d, edges="edges")``
rebuilds them; keys ``directed``, ``multigraph``, ``graph``, ``nodes``, ``edges``):

* ``opening_graph`` (undirected multigraph) - the planning graph: nodes are openings
  (``id`` = opening id, with ``midpoint_m``, ``anchor_m``, ``width_m``, ``is_frontier``,
  ``area_ids``); edges are :class:`GraphEdge` s (``key`` = edge index, ``area_id``,
  ``length_m``, and ``path_m`` when paths are included). Shortest paths by ``length_m`` are
  metric routes between openings.
* ``area_graph`` (undirected multigraph) - the topology: nodes are areas (``id`` = area id, with
  ``type``, ``centre_m``, ``n_cells``, ``n_frontiers``); one edge per opening between two areas
  (``key`` = opening id, ``width_m``, ``midpoint_m``). Frontier openings (to unknown space) are
  not edges; they are counted in ``n_frontiers``.

Raster data (the per-cell area ids) is not exported; it is ``TopometricMap.area_ids``.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from semexplore_gym.core.topometric.types import AreaType, TopometricMap

FORMAT = "semexplore-topometric/1"

_TYPE_NAMES = {
    AreaType.INTERSECTION: "intersection",
    AreaType.PATHWAY: "pathway",
    AreaType.DEAD_END: "dead_end",
    AreaType.FRONTIER_PATHWAY: "frontier_pathway",
}


def _xy(p: Any) -> list[float] | None:
    if p is None:
        return None
    return [round(float(p[0]), 6), round(float(p[1]), 6)]


def _poly(a: Any) -> list[list[float]]:
    return np.round(np.asarray(a, dtype=np.float64).reshape(-1, 2), 6).tolist()


def _num(v: float) -> float | None:
    v = float(v)
    return None if not math.isfinite(v) else round(v, 6)


def type_name(t: AreaType) -> str:
    """``"intersection"``, ``"pathway"``, ``"dead_end"`` or ``"frontier_pathway"``."""
    return _TYPE_NAMES[AreaType(t)]


def opening_graph_node_link(tmap: TopometricMap, include_paths: bool = True) -> dict:
    """The planning graph (nodes: openings, edges: graph edges) in node-link form."""
    nodes = [
        {
            "id": o.id,
            "midpoint_m": _xy(o.midpoint_m),
            "anchor_m": _xy(o.anchor_m),
            "width_m": round(float(o.width_m), 6),
            "is_frontier": bool(o.is_frontier),
            "area_ids": [int(a) for a in o.area_ids],
        }
        for o in tmap.openings
    ]
    edges = []
    for k, e in enumerate(tmap.edges):
        d: dict[str, Any] = {
            "source": int(e.opening_a),
            "target": int(e.opening_b),
            "key": k,
            "area_id": int(e.area_id),
            "length_m": round(float(e.length_m), 6),
        }
        if include_paths:
            d["path_m"] = _poly(e.path_m)
        edges.append(d)
    return {
        "directed": False,
        "multigraph": True,
        "graph": {"kind": "opening_graph"},
        "nodes": nodes,
        "edges": edges,
    }


def area_graph_node_link(tmap: TopometricMap) -> dict:
    """The topology (nodes: areas, edges: openings between two areas) in node-link form."""
    n_front: dict[int, int] = {}
    for o in tmap.openings:
        if o.is_frontier:
            for a in o.area_ids:
                if a >= 0:
                    n_front[a] = n_front.get(a, 0) + 1
    nodes = [
        {
            "id": a.id,
            "type": type_name(a.type),
            "centre_m": _xy(a.centre_m),
            "n_cells": int(a.n_cells),
            "n_frontiers": n_front.get(a.id, 0),
        }
        for a in tmap.areas.values()
    ]
    edges = [
        {
            "source": int(o.area_ids[0]),
            "target": int(o.area_ids[1]),
            "key": o.id,
            "width_m": round(float(o.width_m), 6),
            "midpoint_m": _xy(o.midpoint_m),
        }
        for o in tmap.openings
        if o.area_ids[0] >= 0 and o.area_ids[1] >= 0
    ]
    return {
        "directed": False,
        "multigraph": True,
        "graph": {"kind": "area_graph"},
        "nodes": nodes,
        "edges": edges,
    }


def to_json_dict(tmap: TopometricMap, include_paths: bool = True) -> dict:
    """The whole map as JSON-ready data (see the module docstring for the layout).

    Args:
        tmap: The map.
        include_paths: Include the polylines (areas' ``paths_m`` and edges' ``path_m``).
    """
    if not isinstance(tmap, TopometricMap):
        raise TypeError(f"expected a TopometricMap, got {type(tmap).__name__}")
    areas = []
    for a in tmap.areas.values():
        d: dict[str, Any] = {
            "id": a.id,
            "type": type_name(a.type),
            "type_code": int(a.type),
            "centre_m": _xy(a.centre_m),
            "n_cells": int(a.n_cells),
            "opening_ids": [int(k) for k in a.opening_ids],
        }
        if a.type == AreaType.INTERSECTION:
            d["n_openings"] = tmap.n_openings(a.id)
            d["n_frontier_pathways"] = tmap.n_frontier_pathways(a.id)
        if include_paths:
            d["paths_m"] = {str(k): _poly(p) for k, p in a.paths_m.items()}
        areas.append(d)
    openings = [
        {
            "id": o.id,
            "endpoints_m": _poly(o.endpoints_m),
            "midpoint_m": _xy(o.midpoint_m),
            "anchor_m": _xy(o.anchor_m),
            "width_m": round(float(o.width_m), 6),
            "area_ids": [int(a) for a in o.area_ids],
            "is_frontier": bool(o.is_frontier),
        }
        for o in tmap.openings
    ]
    frontiers = [
        {
            "area_id": f.area_id,
            "opening_id": f.opening_id,
            "midpoint_m": _xy(f.midpoint_m),
            "width_m": round(float(f.width_m), 6),
            "intersection_id": f.intersection_id,
            "path_length_m": round(float(f.path_length_m), 6),
        }
        for f in tmap.frontiers
    ]
    return {
        "format": FORMAT,
        "geometry": tmap.geometry.to_dict(),
        "clearance_m": float(tmap.clearance_m),
        "time_ms": round(float(tmap.time_ms), 3),
        "mean_intersection_path_m": _num(tmap.mean_intersection_path_m),
        "counts": tmap.counts(),
        "areas": areas,
        "openings": openings,
        "frontiers": frontiers,
        "opening_graph": opening_graph_node_link(tmap, include_paths),
        "area_graph": area_graph_node_link(tmap),
    }


def to_networkx(tmap: TopometricMap, kind: str = "opening") -> Any:
    """A ``networkx.MultiGraph`` of the opening graph (``kind="opening"``) or area graph (``"area"``).

    networkx is an optional dependency (``pip install networkx``).
    """
    if kind not in ("opening", "area"):
        raise ValueError(f"kind must be 'opening' or 'area', got {kind!r}")
    try:
        import networkx as nx
    except ImportError as e:  # pragma: no cover - depends on the environment
        raise ImportError("to_networkx needs networkx: pip install networkx") from e
    data = opening_graph_node_link(tmap) if kind == "opening" else area_graph_node_link(tmap)
    return nx.node_link_graph(data, edges="edges")
