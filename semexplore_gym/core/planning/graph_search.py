"""Goal selection over the semantic topometric map: the paper's Algorithm 1 and frontier cost.

The cost of a frontier ``F_i`` (paper, Eq. 1-2) is::

    C(F_i) = d / L_path + w_v * v  -  (w_p * p_l(F_i) + w_I * (O(I) + P_u(I)))

with ``d`` the length of the path from the robot to ``F_i`` along the map's paths, ``v`` the
angle between the robot's heading and the start of that path, ``L_path`` the mean length of the
paths between adjacent intersections, ``p_l`` the path length from the frontier to its
intersection ``I``, ``O(I)`` the number of openings of ``I`` and ``P_u(I)`` the number of its
pathways that lead directly to a frontier. The goal is ``F* = argmin C``.

Algorithm 1 finds the paths to all frontiers in one search:

* The graph's nodes are the map's **openings**; inside each area every pair of openings is
  joined by the area's path (:class:`~semexplore_gym.core.topometric.types.GraphEdge`).
* The search starts in the robot's area. Each opening of that area is a first neighbour; it is
  seeded with the cost ``w_v * v`` of the angle between the robot's heading and the start of
  the path to it, plus that first leg's length over ``L_path`` (the paper's line 3 names only
  ``w_v * v``; adding the leg keeps the seeds comparable with each other).
* Paths never re-enter the robot's area (as if ``A_cost`` of the start area were 0): the first
  legs already cover every way through it, and re-entering would let a path start straight
  ahead, turn round behind the robot and so dodge the angle cost.
* The search list is a stack: the **last** element is expanded first.
* A path is discontinued when it reaches a node already reached at a lower or equal cost (the
  ``A_cost`` array; the paper's strict ``<`` would let equal-cost paths cycle over zero-length
  edges), and a popped path is dropped when its last node has since been reached more cheaply
  (the same condition, applied late). By default ``A_cost`` has one slot per *opening*: an area is entered through
  one of its openings, and the cost of leaving it depends on which one, so per-opening pruning
  keeps the search exact (it returns the cheapest path to every frontier). ``prune_by="area"``
  keeps one slot per area as the paper's pseudocode reads; it prunes more and can lose the
  cheapest path when an area is entered through two different openings.
* When the popped path ends at a frontier opening it is scored with ``C`` (the semantic gain is
  a property of the frontier, so it is subtracted once the path is complete).

The accumulated search cost is the metric part of ``C`` in the same normalised units
(``d / L_path + w_v * v``), so the pruning compares exactly what goal selection minimises.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Literal, cast

import numpy as np

from semexplore_gym.core.lazy_field import LazyField
from semexplore_gym.core.planning.graph_paths import PathParts, SearchPath, first_legs, path_parts
from semexplore_gym.core.planning.graph_search_kernels import search_by_opening
from semexplore_gym.core.planning.polyline import heading_angle, polyline_length
from semexplore_gym.core.topometric.types import Frontier, TopometricMap
from semexplore_gym.core.validation import require_finite


@dataclass(frozen=True)
class FrontierCostWeights:
    """Weights of the frontier cost ``C`` (defaults: the paper's table).

    Attributes:
        w_v: Weight of the heading angle ``v`` (per radian).
        w_p: Weight of the frontier's path length ``p_l`` to its intersection (per metre).
        w_i: Weight of the intersection's ``O(I) + P_u(I)`` (per opening / pathway).
        fallback_path_length_m: ``L_path`` to use while the map has fewer than two connected
            intersections (its ``mean_intersection_path_m`` is nan).
        heading_lookahead_m: ``v`` is the angle between the robot's heading and the direction
            from the robot to the point this far along the path (the "start of the path").
    """

    w_v: float = 4.0
    w_p: float = 0.2
    w_i: float = 0.1
    fallback_path_length_m: float = 2.0
    heading_lookahead_m: float = 0.5

    def __post_init__(self) -> None:
        require_finite(self, ("w_v", "w_p", "w_i", "heading_lookahead_m"), positive=False)
        if not (math.isfinite(self.fallback_path_length_m) and self.fallback_path_length_m > 0.0):
            raise ValueError(
                f"fallback_path_length_m must be a positive finite number, got {self.fallback_path_length_m!r}"
            )


@dataclass(frozen=True)
class FrontierCandidate:
    """The cheapest path found to one frontier, with every term of its cost.

    Attributes:
        frontier: The frontier (its pathway, opening and intersection).
        goal_xy_m: The exploration target, the frontier opening's midpoint.
        path_m: ``(K, 2)`` metric polyline from the robot's position to ``goal_xy_m``.
        opening_ids: The graph nodes (openings) along the path, first to last.
        d_m: Path length ``d``.
        v_rad: Angle ``v`` in ``[0, pi]`` between the heading and the start of the path.
        p_l_m: ``p_l(F)``.
        n_openings: ``O(I)`` (0 without an intersection).
        n_frontier_pathways: ``P_u(I)`` (0 without an intersection).
        l_path_m: The ``L_path`` used for normalisation.
        metric_cost: ``d / L_path + w_v * v``.
        semantic_gain: ``w_p * p_l + w_I * (O + P_u)``.
        cost: ``C = metric_cost - semantic_gain``.
    """

    frontier: Frontier
    goal_xy_m: tuple[float, float]
    if TYPE_CHECKING:
        path_m: np.ndarray
    else:
        path_m: np.ndarray = LazyField(PathParts, PathParts.build)
    opening_ids: tuple[int, ...]
    d_m: float
    v_rad: float
    p_l_m: float
    n_openings: int
    n_frontier_pathways: int
    l_path_m: float
    metric_cost: float
    semantic_gain: float
    cost: float


@dataclass(frozen=True)
class SearchStats:
    """Work done by one run of Algorithm 1.

    Attributes:
        robot_area_id: The area the search started in (-1: robot not in any area).
        n_seeds: First neighbours seeded.
        n_popped: Paths taken off the search list.
        n_pushed: Paths added to the search list (seeds included).
        n_pruned: Extensions discontinued by the ``A_cost`` condition (at push or at pop).
    """

    robot_area_id: int
    n_seeds: int
    n_pushed: int
    n_popped: int
    n_pruned: int


def resolve_path_length_m(tmap: TopometricMap, weights: FrontierCostWeights) -> float:
    """``L_path``: the map's mean intersection-to-intersection path length, or the fallback."""
    value = float(tmap.mean_intersection_path_m)
    if math.isfinite(value) and value > 0.0:
        return value
    return weights.fallback_path_length_m


def metric_cost(
    path_length_m: float, heading_angle_rad: float, l_path_m: float, weights: FrontierCostWeights
) -> float:
    """The metric part of the frontier cost ``C``: ``d / L_path + w_v * v``.

    Algorithm 1 seeds its search with it (one first leg, then each further leg adds its length
    over ``L_path``), and the expert scores a grid frontier with it, so both compare goals in
    the same normalised units.

    Args:
        path_length_m: ``d``, the path's length.
        heading_angle_rad: ``v``, the angle between the robot's heading and the path's start.
        l_path_m: ``L_path`` (see :func:`resolve_path_length_m`).
        weights: The cost weights (``w_v`` is read).
    """
    return path_length_m / l_path_m + weights.w_v * heading_angle_rad


def semantic_terms(tmap: TopometricMap, frontier: Frontier) -> tuple[float, int, int]:
    """``(p_l, O(I), P_u(I))`` of a frontier; ``O`` and ``P_u`` are 0 when it has no intersection."""
    iid = frontier.intersection_id
    if iid is None or iid not in tmap.areas:
        return float(frontier.path_length_m), 0, 0
    return float(frontier.path_length_m), tmap.n_openings(iid), tmap.n_frontier_pathways(iid)


def find_frontier_paths(
    tmap: TopometricMap,
    robot_xy_m: tuple[float, float],
    robot_yaw_rad: float,
    weights: FrontierCostWeights | None = None,
    *,
    prune_by: Literal["opening", "area"] = "opening",
    min_frontier_width_m: float = 0.0,
) -> list[FrontierCandidate]:
    """Run Algorithm 1 and return one candidate per reachable frontier, cheapest first.

    The first element (if any) is ``F*``. See :func:`search_frontier_paths` for the arguments.
    """
    candidates, _ = search_frontier_paths(
        tmap,
        robot_xy_m,
        robot_yaw_rad,
        weights,
        prune_by=prune_by,
        min_frontier_width_m=min_frontier_width_m,
    )
    return candidates


def search_frontier_paths(
    tmap: TopometricMap,
    robot_xy_m: tuple[float, float],
    robot_yaw_rad: float,
    weights: FrontierCostWeights | None = None,
    *,
    prune_by: Literal["opening", "area"] = "opening",
    min_frontier_width_m: float = 0.0,
) -> tuple[list[FrontierCandidate], SearchStats]:
    """Algorithm 1: paths from the robot to all frontiers of ``tmap``, scored with ``C``.

    Args:
        tmap: The semantic topometric map.
        robot_xy_m: Robot position in the map frame.
        robot_yaw_rad: Robot heading in the map frame.
        weights: Cost weights (default: the paper's).
        prune_by: ``"opening"`` (exact, default) or ``"area"``: what ``A_cost`` is indexed by.
        min_frontier_width_m: Frontiers narrower than this are ignored (too narrow to enter).

    Returns:
        ``(candidates, stats)``: one :class:`FrontierCandidate` per reachable frontier, sorted by
        cost (ties by path length), and the search's :class:`SearchStats`.

    Raises:
        ValueError: on a non-finite pose or an unknown ``prune_by``.
    """
    w = weights if weights is not None else FrontierCostWeights()
    if prune_by not in ("opening", "area"):
        raise ValueError(f"prune_by must be 'opening' or 'area', got {prune_by!r}")
    rx, ry = float(robot_xy_m[0]), float(robot_xy_m[1])
    yaw = float(robot_yaw_rad)
    if not (math.isfinite(rx) and math.isfinite(ry) and math.isfinite(yaw)):
        raise ValueError(f"robot pose must be finite, got xy={robot_xy_m!r}, yaw={robot_yaw_rad!r}")

    robot_area = tmap.area_at(rx, ry) if tmap.areas else -1
    if robot_area < 0 or robot_area not in tmap.areas:
        return [], SearchStats(-1, 0, 0, 0, 0)
    l_path = resolve_path_length_m(tmap, w)

    frontier_at: dict[int, Frontier] = {}
    for f in tmap.frontiers:
        if f.width_m >= min_frontier_width_m:
            frontier_at[f.opening_id] = f

    by_opening = prune_by == "opening"
    slot = _slot_function(tmap, robot_area, by_opening)
    legs = first_legs(tmap, robot_area, (rx, ry))
    a_cost, search_list, leg_start_angle, n_pruned = _seed(legs, (rx, ry), yaw, w, l_path, slot)
    n_seeds = n_pushed = len(search_list)
    if by_opening:
        best, counts = _search_by_opening(
            tmap, robot_area, frontier_at, a_cost, search_list, l_path
        )
    else:
        best, counts = _search_by_area(
            tmap, robot_area, frontier_at, a_cost, search_list, l_path, slot
        )
    n_pushed += counts[0]
    n_popped = counts[1]
    n_pruned += counts[2]

    candidates = _score_candidates(tmap, best, frontier_at, legs, leg_start_angle, l_path, w)
    return candidates, SearchStats(robot_area, n_seeds, n_pushed, n_popped, n_pruned)


def _slot_function(
    tmap: TopometricMap, robot_area: int, by_opening: bool
) -> Callable[[int, int | None], Any]:
    """Which ``A_cost`` entry a path ending at ``node`` (entered by edge ``via_edge``) competes
    for: by opening, the node; by area, the area beyond the node."""

    def slot(node: int, via_edge: int | None) -> int | tuple[str, int]:
        if by_opening:
            return node
        here = tmap.edges[via_edge].area_id if via_edge is not None else robot_area
        ids = tmap.openings[node].area_ids if 0 <= node < len(tmap.openings) else (here,)
        beyond = [a for a in ids if a >= 0 and a != here]
        # A frontier opening leads into unknown space: it keeps its own slot.
        return ("a", beyond[0]) if beyond else ("o", node)

    return slot


def _seed(
    legs: dict[int, np.ndarray],
    robot_xy: tuple[float, float],
    yaw: float,
    w: FrontierCostWeights,
    l_path: float,
    slot: Callable[[int, int | None], Any],
) -> tuple[dict[Any, float], list[SearchPath], dict[int, float], int]:
    """The first neighbours: one search path per first leg, costing ``w_v * v`` plus the leg's
    length over ``L_path``. Returns ``A_cost``, the search list, each leg's angle ``v`` and the
    seeds pruned."""
    a_cost: dict[Any, float] = {}
    search_list: list[SearchPath] = []
    leg_start_angle: dict[int, float] = {}
    n_pruned = 0
    for node, leg in legs.items():
        v = heading_angle(leg, robot_xy, yaw, w.heading_lookahead_m)
        leg_start_angle[node] = v
        leg_m = polyline_length(leg)
        cost = metric_cost(leg_m, v, l_path, w)
        key = slot(node, None)
        if a_cost.get(key, math.inf) <= cost:
            n_pruned += 1
            continue
        a_cost[key] = cost
        search_list.append(SearchPath((node,), (), cost, leg_m))
    return a_cost, search_list, leg_start_angle, n_pruned


def _edge_lists(
    tmap: TopometricMap, robot_area: int
) -> tuple[list[int], list[int], list[int], list[float]]:
    """The map's edges as directed ``(from, to, edge, length)`` lists, both ways round, in edge
    order. Edges of the robot's area are never followed (paths do not re-enter it): left out."""
    src: list[int] = []
    dst: list[int] = []
    idx: list[int] = []
    len_m: list[float] = []
    for k, e in enumerate(tmap.edges):
        if e.area_id == robot_area:
            continue
        d_m = float(e.length_m)
        src += (e.opening_a, e.opening_b)
        dst += (e.opening_b, e.opening_a)
        idx += (k, k)
        len_m += (d_m, d_m)
    return src, dst, idx, len_m


def _search_by_opening(
    tmap: TopometricMap,
    robot_area: int,
    frontier_at: dict[int, Frontier],
    a_cost: dict[Any, float],
    seeds: list[SearchPath],
    l_path: float,
) -> tuple[dict[int, tuple[float, SearchPath]], tuple[int, int, int]]:
    """The search loop with one ``A_cost`` slot per opening, compiled
    (:func:`~semexplore_gym.core.planning.graph_search_kernels.search_by_opening`).

    Returns the cheapest path to each frontier reached (in the order they were first reached)
    and the pushes, pops and prunings after the seeds.
    """
    src, dst, idx, len_m = _edge_lists(tmap, robot_area)
    seed_ids = [p.nodes[0] for p in seeds]
    ids = sorted({*src, *seed_ids, *frontier_at})
    dense = {node: i for i, node in enumerate(ids)}
    n = len(ids)
    src_d = np.fromiter((dense[v] for v in src), np.int64, len(src))
    # A stable sort by source keeps each node's neighbours in the order they were appended.
    by_src = np.argsort(src_d, kind="stable")
    adj_ptr = np.zeros(n + 1, np.int64)
    np.cumsum(np.bincount(src_d, minlength=n), out=adj_ptr[1:])
    adj_node = np.fromiter((dense[v] for v in dst), np.int64, len(dst))[by_src]
    adj_edge = np.asarray(idx, np.int64)[by_src]
    adj_len = np.asarray(len_m, np.float64)[by_src]
    is_frontier = np.zeros(n, np.bool_)
    is_frontier[[dense[v] for v in frontier_at]] = True
    costs = np.full(n, np.inf)
    for node, c in a_cost.items():
        costs[dense[node]] = c
    order, best_rec, rec_node, rec_edge, rec_parent, rec_cost, rec_len, n_pushed, n_popped, n_pruned = (
        search_by_opening(
            adj_ptr, adj_node, adj_edge, adj_len, is_frontier, costs,
            np.asarray([dense[v] for v in seed_ids], np.int64),
            np.asarray([p.cost for p in seeds], np.float64),
            np.asarray([p.length_m for p in seeds], np.float64),
            float(l_path),
        )
    )  # fmt: skip
    rec_node_l, rec_edge_l, rec_parent_l = rec_node.tolist(), rec_edge.tolist(), rec_parent.tolist()
    best: dict[int, tuple[float, SearchPath]] = {}
    for d in order.tolist():
        r = int(best_rec[d])
        nodes: list[int] = []
        edges: list[int] = []
        q = r
        while q >= 0:
            nodes.append(ids[rec_node_l[q]])
            if rec_edge_l[q] >= 0:
                edges.append(rec_edge_l[q])
            q = rec_parent_l[q]
        cost = float(rec_cost[r])
        best[ids[d]] = (
            cost,
            SearchPath(tuple(nodes[::-1]), tuple(edges[::-1]), cost, float(rec_len[r])),
        )
    return best, (int(n_pushed) - len(seeds), int(n_popped), int(n_pruned))


def _search_by_area(
    tmap: TopometricMap,
    robot_area: int,
    frontier_at: dict[int, Frontier],
    a_cost: dict[Any, float],
    search_list: list[SearchPath],
    l_path: float,
    slot: Callable[[int, int | None], Any],
) -> tuple[dict[int, tuple[float, SearchPath]], tuple[int, int, int]]:
    """The search loop with one ``A_cost`` slot per area (the paper's pseudocode), in Python.

    Returns the cheapest path to each frontier reached and the pushes, pops and prunings after
    the seeds.
    """
    adjacency: dict[int, list[tuple[int, int, float]]] = {}
    for a, b, k, d_m in zip(*_edge_lists(tmap, robot_area), strict=True):
        adjacency.setdefault(a, []).append((b, k, d_m))
    n_pushed = n_popped = n_pruned = 0
    best: dict[int, tuple[float, SearchPath]] = {}
    while search_list:
        path = search_list.pop()
        n_popped += 1
        last = path.nodes[-1]
        at = slot(last, path.edges[-1] if path.edges else None)
        if a_cost.get(at, math.inf) < path.cost:
            # Reached more cheaply since it was pushed: the A_cost condition, applied at pop.
            n_pruned += 1
            continue
        if last in frontier_at:
            prev = best.get(last)
            if prev is None or path.cost < prev[0]:
                best[last] = (path.cost, path)
        for nbr, k, d_m in adjacency.get(last, ()):
            if nbr in path.nodes:
                continue
            new_cost = path.cost + d_m / l_path
            key = slot(nbr, k)
            if a_cost.get(key, math.inf) <= new_cost:
                n_pruned += 1
                continue
            a_cost[key] = new_cost
            search_list.append(
                SearchPath(path.nodes + (nbr,), path.edges + (k,), new_cost, path.length_m + d_m)
            )
            n_pushed += 1
    return best, (n_pushed, n_popped, n_pruned)


def _score_candidates(
    tmap: TopometricMap,
    best: dict[int, tuple[float, SearchPath]],
    frontier_at: dict[int, Frontier],
    first_legs: dict[int, np.ndarray],
    leg_start_angle: dict[int, float],
    l_path: float,
    w: FrontierCostWeights,
) -> list[FrontierCandidate]:
    """The cheapest path found to each frontier, scored with ``C = metric - gain``, cheapest
    first (ties by path length)."""
    candidates: list[FrontierCandidate] = []
    # oriented edge polylines, shared by the candidates' paths (read only)
    polylines: dict[tuple[int, int], np.ndarray] = {}
    for node, (metric, path) in best.items():
        f = frontier_at[node]
        p_l, n_open, n_fp = semantic_terms(tmap, f)
        gain = w.w_p * p_l + w.w_i * (n_open + n_fp)
        poly = path_parts(tmap, path, first_legs[path.nodes[0]], f.midpoint_m, polylines)
        candidates.append(
            FrontierCandidate(
                frontier=f,
                goal_xy_m=(float(f.midpoint_m[0]), float(f.midpoint_m[1])),
                path_m=cast(np.ndarray, poly),  # joined when first read
                opening_ids=path.nodes,
                d_m=path.length_m,
                v_rad=leg_start_angle[path.nodes[0]],
                p_l_m=p_l,
                n_openings=n_open,
                n_frontier_pathways=n_fp,
                l_path_m=l_path,
                metric_cost=metric,
                semantic_gain=gain,
                cost=metric - gain,
            )
        )
    candidates.sort(key=lambda c: (c.cost, c.d_m))
    return candidates
