"""Algorithm 1 (frontier path search and goal selection) on hand-built topometric maps."""

from __future__ import annotations

import math

import networkx as nx
import numpy as np
import pytest

from semexplore_gym.core.grid import GridGeometry
from semexplore_gym.core.planning.graph_search import (
    FrontierCostWeights,
    find_frontier_paths,
    metric_cost,
    search_frontier_paths,
)
from semexplore_gym.core.planning.polyline import project_onto_polyline
from semexplore_gym.core.topometric.types import (
    Area,
    AreaType,
    Frontier,
    GraphEdge,
    Opening,
    TopometricMap,
)

INT, P, D, F = AreaType.INTERSECTION, AreaType.PATHWAY, AreaType.DEAD_END, AreaType.FRONTIER_PATHWAY


def build_map(
    openings_xy: list[tuple[float, float]],
    areas: list[tuple[int, AreaType, tuple[float, float], tuple[int, ...]]],
    l_path_m: float = float("nan"),
    frontier_widths_m: dict[int, float] | None = None,
) -> TopometricMap:
    """A TopometricMap of straight paths: intersections join openings through their centre.

    ``areas`` rows are ``(id, type, centre, opening_ids)``. An opening listed by a single area
    leads to unknown space (a frontier when that area is a frontier pathway). Every grid cell
    within 0.45 m of an area's paths is labelled with that area (the nearest one wins).
    """
    owners: dict[int, list[int]] = {i: [] for i in range(len(openings_xy))}
    for aid, _, _, oids in areas:
        for o in oids:
            owners[o].append(aid)
    types = {aid: t for aid, t, _, _ in areas}
    openings = []
    for o, xy in enumerate(openings_xy):
        sides = owners[o] + [-1] * (2 - len(owners[o]))
        frontier = len(owners[o]) == 1 and types[owners[o][0]] == F
        openings.append(
            Opening(o, np.array([xy, xy], float), xy, 0.8, (sides[0], sides[1]), frontier)
        )

    edges: list[GraphEdge] = []
    area_objs: dict[int, Area] = {}
    segments: dict[int, list[np.ndarray]] = {}
    for aid, t, centre, oids in areas:
        c = np.asarray(centre, float)
        paths = {}
        segs = []
        if t == INT:
            for o in oids:
                paths[o] = np.array([openings_xy[o], centre], float)
                segs.append(paths[o])
            for i, a in enumerate(oids):
                for b in oids[i + 1 :]:
                    poly = np.array([openings_xy[a], centre, openings_xy[b]], float)
                    length = float(np.hypot(*np.diff(poly, axis=0).T).sum())
                    edges.append(GraphEdge(a, b, aid, length, poly))
        elif len(oids) == 2:
            poly = np.array([openings_xy[oids[0]], openings_xy[oids[1]]], float)
            paths[oids[0]] = poly
            paths[oids[1]] = poly[::-1].copy()
            segs.append(poly)
            edges.append(
                GraphEdge(oids[0], oids[1], aid, float(np.hypot(*(poly[1] - poly[0]))), poly)
            )
        else:
            poly = np.array([openings_xy[oids[0]], centre], float)
            paths[oids[0]] = poly
            segs.append(poly)
        area_objs[aid] = Area(aid, t, tuple(c), tuple(oids), paths, 10)
        segments[aid] = segs

    geom = GridGeometry(0.1, -8.0, -8.0, 160, 160)
    rows, cols = np.mgrid[0:160, 0:160]
    xs, ys = geom.grid_to_world(rows, cols)
    best = np.full((160, 160), np.inf)
    ids = np.full((160, 160), -1, np.int32)
    for aid, segs in segments.items():
        for poly in segs:
            for a, b in zip(poly[:-1], poly[1:], strict=True):
                ab = b - a
                den = max(float(ab @ ab), 1e-12)
                t = np.clip(((xs - a[0]) * ab[0] + (ys - a[1]) * ab[1]) / den, 0, 1)
                d = np.hypot(xs - a[0] - t * ab[0], ys - a[1] - t * ab[1])
                closer = (d < best) & (d <= 0.45)
                best[closer] = d[closer]
                ids[closer] = aid

    frontiers = []
    widths = frontier_widths_m or {}
    for aid, t, _, oids in areas:
        if t != F:
            continue
        fo = next(o for o in oids if openings[o].is_frontier)
        inner = [o for o in oids if o != fo]
        iid = None
        if inner:
            iid = next((a for a in owners[inner[0]] if types[a] == INT), None)
        length = (
            float(np.hypot(*(np.subtract(openings_xy[fo], openings_xy[inner[0]]))))
            if inner
            else 0.0
        )
        frontiers.append(Frontier(aid, fo, openings_xy[fo], widths.get(fo, 0.8), iid, length))
    return TopometricMap(geom, ids, area_objs, openings, frontiers, edges, l_path_m, 0.15)


def brute_force_costs(
    tmap: TopometricMap, robot_xy, yaw: float, w: FrontierCostWeights
) -> dict[int, float]:
    """C of every frontier by enumerating every simple path (independent of Algorithm 1).

    Uses the same first legs (robot to each opening of its area), so only the graph part is
    recomputed here.
    """
    from semexplore_gym.core.planning.graph_paths import first_legs as _first_legs
    from semexplore_gym.core.planning.graph_search import resolve_path_length_m
    from semexplore_gym.core.planning.polyline import heading_angle as _heading_angle
    from semexplore_gym.core.planning.polyline import polyline_length as _polyline_length

    l_path = resolve_path_length_m(tmap, w)
    start_area = tmap.area_at(*robot_xy)
    g = nx.MultiGraph()
    for k, e in enumerate(tmap.edges):
        # Paths move inside the robot's own area only along their first leg.
        if e.area_id != start_area:
            g.add_edge(e.opening_a, e.opening_b, key=k, weight=e.length_m)
    legs = _first_legs(tmap, start_area, robot_xy)
    out = {}
    for f in tmap.frontiers:
        best = math.inf
        for start, leg in legs.items():
            seed = (
                w.w_v * _heading_angle(leg, robot_xy, yaw, w.heading_lookahead_m)
                + _polyline_length(leg) / l_path
            )
            if start == f.opening_id:
                best = min(best, seed)
                continue
            if start not in g or f.opening_id not in g:
                continue
            for p in nx.all_simple_edge_paths(g, start, f.opening_id):
                best = min(best, seed + sum(g.edges[u, v, k]["weight"] for u, v, k in p) / l_path)
        if math.isfinite(best):
            iid = f.intersection_id
            gain = w.w_p * f.path_length_m + (
                w.w_i * (tmap.n_openings(iid) + tmap.n_frontier_pathways(iid))
                if iid is not None
                else 0.0
            )
            out[f.opening_id] = best - gain
    return out


# Robot at the origin in intersection 0. East: a short frontier pathway. West: a pathway to
# intersection 1, which has a long frontier pathway north and a dead end south. North: dead end.
OPENINGS = [
    (1.0, 0.0),  # 0: I0 east
    (-1.0, 0.0),  # 1: I0 west
    (0.0, 1.0),  # 2: I0 north
    (2.0, 0.0),  # 3: east frontier
    (-3.0, 0.0),  # 4: I1 east
    (-4.0, 1.0),  # 5: I1 north
    (-4.0, -1.0),  # 6: I1 south
    (-4.0, 5.0),  # 7: north frontier of I1
]
AREAS = [
    (0, INT, (0.0, 0.0), (0, 1, 2)),
    (1, F, (1.5, 0.0), (0, 3)),
    (2, P, (-2.0, 0.0), (1, 4)),
    (3, D, (0.0, 2.0), (2,)),
    (4, INT, (-4.0, 0.0), (4, 5, 6)),
    (5, F, (-4.0, 3.0), (5, 7)),
    (6, D, (-4.0, -2.0), (6,)),
]


def test_finds_the_cost_minimising_frontier_and_all_paths():
    tmap = build_map(OPENINGS, AREAS, l_path_m=4.0)
    w = FrontierCostWeights()
    for yaw in (0.0, math.pi / 2, math.pi, -math.pi / 2):
        cands = find_frontier_paths(tmap, (0.0, 0.0), yaw, w)
        assert {c.frontier.opening_id for c in cands} == {3, 7}
        expected = brute_force_costs(tmap, (0.0, 0.0), yaw, w)
        got = {c.frontier.opening_id: c.cost for c in cands}
        assert got == pytest.approx(expected)
        assert cands[0].frontier.opening_id == min(expected, key=expected.get)
        assert [c.cost for c in cands] == sorted(c.cost for c in cands)


def test_candidate_terms_and_polyline():
    tmap = build_map(OPENINGS, AREAS, l_path_m=4.0)
    w = FrontierCostWeights()
    cands = {c.frontier.opening_id: c for c in find_frontier_paths(tmap, (0.0, 0.0), math.pi, w)}
    west = cands[7]
    # robot -> west opening (1) -> I1 east (4) -> via centre (-4,0) -> north (5) -> frontier (7)
    assert west.opening_ids == (1, 4, 5, 7)
    assert west.d_m == pytest.approx(1.0 + 2.0 + 1.0 + 1.0 + 4.0)
    assert west.v_rad == pytest.approx(0.0)
    assert (west.p_l_m, west.n_openings, west.n_frontier_pathways) == (4.0, 3, 1)
    assert west.metric_cost == pytest.approx(9.0 / 4.0)
    assert west.semantic_gain == pytest.approx(0.2 * 4.0 + 0.1 * 4)
    assert west.cost == pytest.approx(west.metric_cost - west.semantic_gain)
    np.testing.assert_allclose(
        west.path_m, [[0, 0], [-1, 0], [-3, 0], [-4, 0], [-4, 1], [-4, 5]], atol=1e-9
    )
    assert west.goal_xy_m == (-4.0, 5.0)
    east = cands[3]
    assert east.v_rad == pytest.approx(math.pi)
    np.testing.assert_allclose(east.path_m, [[0, 0], [1, 0], [2, 0]], atol=1e-9)


def test_metric_cost_is_the_metric_part_of_every_candidates_cost():
    w = FrontierCostWeights(w_v=2.0)
    assert metric_cost(6.0, 0.5, 4.0, w) == 6.0 / 4.0 + 2.0 * 0.5
    assert metric_cost(6.0, 0.5, 4.0, FrontierCostWeights(w_v=0.0)) == 1.5
    tmap = build_map(OPENINGS, AREAS, l_path_m=4.0)
    cands = find_frontier_paths(tmap, (0.0, 0.0), math.pi, w)
    assert cands
    for c in cands:
        # the search adds leg by leg, so the sum matches up to rounding
        assert c.metric_cost == pytest.approx(metric_cost(c.d_m, c.v_rad, c.l_path_m, w))


def test_angle_term_changes_the_choice():
    # Facing west the far western frontier wins; facing east the short eastern one does.
    tmap = build_map(OPENINGS, AREAS, l_path_m=4.0)
    w = FrontierCostWeights(w_v=4.0, w_p=0.0, w_i=0.0)
    assert find_frontier_paths(tmap, (0.0, 0.0), math.pi, w)[0].frontier.opening_id == 7
    assert find_frontier_paths(tmap, (0.0, 0.0), 0.0, w)[0].frontier.opening_id == 3
    # Without the angle term the nearer (eastern) frontier wins whatever the heading.
    w0 = FrontierCostWeights(w_v=0.0, w_p=0.0, w_i=0.0)
    assert find_frontier_paths(tmap, (0.0, 0.0), math.pi, w0)[0].frontier.opening_id == 3


def test_semantic_gain_can_outweigh_distance():
    # Facing north (both frontiers need a turn of pi/2): with a large w_p the long western
    # frontier pathway (p_l = 4 m vs 1 m) is preferred despite being farther away.
    tmap = build_map(OPENINGS, AREAS, l_path_m=4.0)
    assert (
        find_frontier_paths(tmap, (0.0, 0.0), math.pi / 2, FrontierCostWeights(w_p=0.0, w_i=0.0))[
            0
        ].frontier.opening_id
        == 3
    )
    assert (
        find_frontier_paths(tmap, (0.0, 0.0), math.pi / 2, FrontierCostWeights(w_p=1.0, w_i=0.0))[
            0
        ].frontier.opening_id
        == 7
    )


def test_zero_weights_pick_the_nearest_frontier_by_path_length():
    # Frontier 4 is 1.5 m away in a straight line but 5.8 m along the paths; frontier 3 is
    # 3.2 m away in a straight line and 4 m along the paths.
    openings = [(1.0, 0.0), (-1.0, 0.0), (1.0, 3.0), (-1.0, 3.0), (0.0, 1.5)]
    areas = [
        (0, INT, (0.0, 0.0), (0, 1)),  # two-opening "intersection" keeps the example small
        (1, P, (1.0, 1.5), (0, 2)),
        (2, F, (-1.0, 1.5), (1, 3)),
        (3, F, (0.5, 2.0), (2, 4)),
    ]
    tmap = build_map(openings, areas)
    w = FrontierCostWeights(w_v=0.0, w_p=0.0, w_i=0.0)
    cands = find_frontier_paths(tmap, (0.0, 0.0), 0.0, w)
    assert [c.frontier.opening_id for c in cands] == [3, 4]
    assert [c.d_m for c in cands] == pytest.approx([1.0 + 3.0, 1.0 + 3.0 + math.hypot(1.0, 1.5)])


def loop_map() -> TopometricMap:
    # Two intersections joined by two pathways: a short one and a long detour; a frontier
    # beyond the second intersection. The detour reaches I1's opening 7 more expensively.
    openings = [
        (1.0, 0.0),  # 0 I0 east (short pathway)
        (0.0, 1.0),  # 1 I0 north (detour)
        (-1.0, 0.0),  # 2 I0 west dead end
        (3.0, 0.0),  # 3 I1 west (short pathway)
        (4.0, 1.0),  # 4 I1 north (detour)
        (5.0, 0.0),  # 5 I1 east -> frontier pathway
        (7.0, 0.0),  # 6 frontier
    ]
    areas = [
        (0, INT, (0.0, 0.0), (0, 1, 2)),
        (1, P, (2.0, 0.0), (0, 3)),
        (2, P, (2.0, 4.0), (1, 4)),
        (3, D, (-2.0, 0.0), (2,)),
        (4, INT, (4.0, 0.0), (3, 4, 5)),
        (5, F, (6.0, 0.0), (5, 6)),
    ]
    return build_map(openings, areas, l_path_m=3.0)


def count_unpruned_pushes(tmap: TopometricMap, seeds: int) -> int:
    """Paths an exhaustive search would push: every simple path from every seed."""
    adj: dict[int, list[int]] = {}
    for e in tmap.edges:
        if e.area_id == tmap.area_at(0.0, 0.0):
            continue
        adj.setdefault(e.opening_a, []).append(e.opening_b)
        adj.setdefault(e.opening_b, []).append(e.opening_a)

    def walk(path: tuple[int, ...]) -> int:
        return 1 + sum(walk(path + (n,)) for n in adj.get(path[-1], []) if n not in path)

    return sum(walk((s,)) for s in range(seeds))


def test_a_cost_pruning_discontinues_dearer_paths_and_keeps_the_best():
    tmap = loop_map()
    w = FrontierCostWeights()
    for yaw in (0.0, math.pi / 2, math.pi, -math.pi / 2):
        cands, stats = search_frontier_paths(tmap, (0.0, 0.0), yaw, w)
        assert len(cands) == 1
        assert cands[0].cost == pytest.approx(brute_force_costs(tmap, (0.0, 0.0), yaw, w)[6])
        assert stats.n_seeds == 3 and stats.n_pruned > 0
        assert stats.n_pushed < count_unpruned_pushes(tmap, 3)
    # Facing east the short pathway is cheaper; facing north the detour starts straight ahead
    # (cost 9/3 = 3 against 7/3 + 4 * pi/2 for the short one).
    assert find_frontier_paths(tmap, (0.0, 0.0), 0.0, w)[0].opening_ids == (0, 3, 5, 6)
    assert find_frontier_paths(tmap, (0.0, 0.0), math.pi / 2, w)[0].opening_ids == (1, 4, 5, 6)


def test_area_pruning_is_available_and_agrees_on_simple_maps():
    tmap = build_map(OPENINGS, AREAS, l_path_m=4.0)
    a = find_frontier_paths(tmap, (0.0, 0.0), 0.0, prune_by="area")
    b = find_frontier_paths(tmap, (0.0, 0.0), 0.0, prune_by="opening")
    assert [c.frontier.opening_id for c in a] == [c.frontier.opening_id for c in b]
    assert [c.cost for c in a] == pytest.approx([c.cost for c in b])
    with pytest.raises(ValueError, match="prune_by"):
        find_frontier_paths(tmap, (0.0, 0.0), 0.0, prune_by="node")  # type: ignore[arg-type]


def test_robot_inside_a_pathway_joins_its_path():
    tmap = build_map(OPENINGS, AREAS, l_path_m=4.0)
    # In the west pathway (area 2), 0.2 m off its centre line.
    cands = {
        c.frontier.opening_id: c
        for c in find_frontier_paths(tmap, (-2.0, 0.2), math.pi, FrontierCostWeights())
    }
    np.testing.assert_allclose(
        cands[7].path_m[:3], [[-2.0, 0.2], [-2.0, 0.0], [-3.0, 0.0]], atol=1e-9
    )
    assert cands[7].d_m == pytest.approx(0.2 + 1.0 + 1.0 + 1.0 + 4.0)
    assert cands[3].opening_ids[:2] == (1, 0)


def test_narrow_frontiers_are_skipped_and_no_area_gives_nothing():
    tmap = build_map(OPENINGS, AREAS, l_path_m=4.0, frontier_widths_m={3: 0.15})
    cands = find_frontier_paths(tmap, (0.0, 0.0), 0.0, min_frontier_width_m=0.3)
    assert [c.frontier.opening_id for c in cands] == [7]
    assert find_frontier_paths(tmap, (7.5, 7.5), 0.0)[0].frontier.opening_id in (
        3,
        7,
    )  # nearest area
    empty = TopometricMap(
        tmap.geometry, np.full((160, 160), -1, np.int32), {}, [], [], [], float("nan"), 0.15
    )
    cands, stats = search_frontier_paths(empty, (0.0, 0.0), 0.0)
    assert cands == [] and stats.robot_area_id == -1
    with pytest.raises(ValueError, match="finite"):
        find_frontier_paths(tmap, (math.nan, 0.0), 0.0)


def test_weights_validate():
    with pytest.raises(ValueError, match="w_v"):
        FrontierCostWeights(w_v=-1.0)
    with pytest.raises(ValueError, match="fallback_path_length_m"):
        FrontierCostWeights(fallback_path_length_m=0.0)


def test_projection_onto_polyline():
    poly = np.array([[0.0, 0.0], [2.0, 0.0], [2.0, 2.0]])
    dist, q, i, s = project_onto_polyline(poly, (2.5, 1.0))
    assert (dist, i, s) == pytest.approx((0.5, 1, 3.0))
    np.testing.assert_allclose(q, [2.0, 1.0])


def test_candidate_paths_are_joined_when_read_and_survive_pickling():
    import pickle

    from semexplore_gym.core.planning.graph_paths import PathParts as _PathParts

    tmap = build_map(OPENINGS, AREAS, l_path_m=4.0)
    cands, _ = search_frontier_paths(tmap, (0.0, 0.0), math.pi, FrontierCostWeights())
    assert cands and all(isinstance(c.__dict__["_path_m"], _PathParts) for c in cands)
    copies = pickle.loads(pickle.dumps(cands))  # still unjoined
    for c, d in zip(cands, copies, strict=True):
        assert c.path_m is c.path_m  # joined once
        assert np.array_equal(d.path_m, c.path_m)
        assert np.allclose(c.path_m[0], (0.0, 0.0)) and np.allclose(c.path_m[-1], c.goal_xy_m)
    west = next(c for c in copies if c.frontier.opening_id == 7)
    np.testing.assert_allclose(
        west.path_m, [[0, 0], [-1, 0], [-3, 0], [-4, 0], [-4, 1], [-4, 5]], atol=1e-9
    )
