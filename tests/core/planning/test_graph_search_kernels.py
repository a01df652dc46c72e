"""The compiled first-leg kernels give the numpy forms' floats, to the bit."""

from __future__ import annotations

import numpy as np

from semexplore_gym.core.grid import FREE, OCCUPIED, UNKNOWN, GridGeometry
from semexplore_gym.core.planning.graph_paths import edge_polyline as _edge_polyline
from semexplore_gym.core.planning.graph_paths import first_legs as _first_legs
from semexplore_gym.core.planning.graph_search_kernels import first_leg_offers, pairwise_sum
from semexplore_gym.core.planning.polyline import dedupe_polyline as _dedupe
from semexplore_gym.core.planning.polyline import oriented_polyline as _oriented
from semexplore_gym.core.planning.polyline import polyline_length as _polyline_length
from semexplore_gym.core.planning.polyline import project_onto_polyline
from semexplore_gym.core.topometric.segmentation import segment_map


def test_pairwise_sum_is_numpys_sum() -> None:
    rng = np.random.default_rng(1)
    for n in [*range(0, 300), 1000, 1023, 4099, 20000]:
        x = rng.random(n) * float(rng.choice([1e-3, 1.0, 1e3]))
        assert pairwise_sum(x, 0, n) == x.sum()
        if n:
            lo = int(rng.integers(0, n))
            assert pairwise_sum(x, lo, n - lo) == x[lo:].sum()


def _random_polyline(rng: np.random.Generator) -> np.ndarray:
    n = int(rng.integers(1, 30))
    pts = np.cumsum(rng.normal(size=(n, 2)) * float(rng.choice([0.05, 1.0])), axis=0)
    if n > 2 and rng.random() < 0.3:
        pts[1] = pts[0]  # a zero-length segment
    if rng.random() < 0.3:
        pts = np.round(pts * 20) / 20  # on a 5 cm lattice: ties between segments
    return pts


def test_first_leg_offers_match_the_numpy_projection_and_lengths() -> None:
    rng = np.random.default_rng(2)
    for _ in range(300):
        polys = [_random_polyline(rng) for _ in range(int(rng.integers(1, 8)))]
        robot = (float(rng.normal()), float(rng.normal()))
        if rng.random() < 0.2:
            robot = tuple(float(v) for v in polys[0][len(polys[0]) // 2])  # on a vertex
        starts = np.concatenate(([0], np.cumsum([len(p) for p in polys]))).astype(np.int64)
        seg_idx = np.empty(len(polys), np.int64)
        q_xy = np.empty((len(polys), 2))
        lengths = np.empty((len(polys), 2))
        first_leg_offers(np.concatenate(polys), starts, *robot, seg_idx, q_xy, lengths)
        for e, poly in enumerate(polys):
            dist, q, i, _ = project_onto_polyline(poly, robot)
            assert seg_idx[e] == i and q_xy[e, 0] == q[0] and q_xy[e, 1] == q[1]
            assert lengths[e, 0] == dist + _polyline_length(np.vstack([q, poly[: i + 1][::-1]]))
            assert lengths[e, 1] == dist + _polyline_length(np.vstack([q, poly[i + 1 :]]))


def _first_legs_numpy(tmap, area_id, robot_xy):
    """The numpy form of ``_first_legs`` (one projection and two lengths per path)."""
    area = tmap.areas[area_id]
    r = np.asarray(robot_xy, dtype=np.float64)
    best: dict[int, tuple[float, np.ndarray]] = {}

    def offer(node, dist, q, rest):
        length = dist + _polyline_length(np.vstack([q, rest]))
        if node not in best or length < best[node][0]:
            best[node] = (length, _dedupe(np.vstack([r, q, rest])))

    for k, e in enumerate(tmap.edges):
        if e.area_id != area_id:
            continue
        poly = _edge_polyline(tmap, k, e.opening_a)
        dist, q, i, _ = project_onto_polyline(poly, robot_xy)
        offer(e.opening_a, dist, q, poly[: i + 1][::-1])
        offer(e.opening_b, dist, q, poly[i + 1 :])
    for oid, path in area.paths_m.items():
        if oid in best or oid not in area.opening_ids:
            continue
        poly = _oriented(path, tmap.openings[oid].midpoint_m, tuple(np.asarray(path)[-1]))
        dist, q, i, _ = project_onto_polyline(poly, robot_xy)
        offer(oid, dist, q, poly[: i + 1][::-1])
    for oid in area.opening_ids:
        if oid not in best and 0 <= oid < len(tmap.openings):
            m = np.asarray(tmap.openings[oid].midpoint_m, dtype=np.float64)
            offer(oid, float(np.hypot(*(m - r))), m, np.empty((0, 2)))
    return {node: poly for node, (_, poly) in best.items()}


def test_first_legs_on_a_segmented_map_match_the_numpy_form() -> None:
    # A half-explored building: rooms off a corridor, a junction, unknown space beyond.
    grid = np.full((160, 200), UNKNOWN, np.uint8)
    grid[20:140, 10:150] = FREE
    grid[20, 10:150] = grid[139, 10:150] = OCCUPIED
    grid[20:140, 10] = OCCUPIED
    for c in (50, 90):
        grid[20:70, c] = OCCUPIED
        grid[90:140, c] = OCCUPIED
    grid[70, 10:45] = grid[90, 10:45] = OCCUPIED
    grid[70, 55:85] = grid[90, 95:150] = OCCUPIED
    geometry = GridGeometry(0.05, 0.0, 0.0, *grid.shape)
    tmap = segment_map(grid, geometry, 0.155)
    assert len(tmap.areas) >= 3 and len(tmap.edges) >= 3
    rng = np.random.default_rng(3)
    n_legs = 0
    for area_id in tmap.areas:
        for _ in range(20):
            robot = (float(rng.uniform(0.5, 7.5)), float(rng.uniform(1.0, 7.0)))
            got, want = _first_legs(tmap, area_id, robot), _first_legs_numpy(tmap, area_id, robot)
            assert list(got) == list(want)
            for node, poly in want.items():
                np.testing.assert_array_equal(got[node], poly)
            n_legs += len(want)
    assert n_legs > 50


def test_compiled_search_equals_the_python_loop_on_a_large_graph() -> None:
    """Algorithm 1's loop with one A_cost slot per opening, compiled, against the Python loop
    (``_search_by_area`` with the identity slot is that loop): same paths, same order, same
    counts, on lattices big enough to outgrow the kernel's first buffers."""
    from types import SimpleNamespace

    from semexplore_gym.core.planning.graph_paths import SearchPath as _Partial
    from semexplore_gym.core.planning.graph_search import _search_by_area, _search_by_opening
    from semexplore_gym.core.topometric.types import GraphEdge

    rng = np.random.default_rng(4)
    for n in (3, 7, 10):
        edges = []
        for r in range(n):
            for c in range(n):
                for dr, dc in ((0, 1), (1, 0), (1, 1)):
                    if r + dr < n and c + dc < n and rng.random() < 0.8:
                        length = float(rng.choice([1.0, 1.5, rng.uniform(0.5, 3.0)]))
                        poly = np.zeros((2, 2))
                        edges.append(
                            GraphEdge(
                                r * n + c, (r + dr) * n + c + dc, len(edges) + 1, length, poly
                            )
                        )
        tmap = SimpleNamespace(edges=edges)
        frontier_at = {int(v): object() for v in rng.choice(n * n, size=n, replace=False)}
        seeds = [
            _Partial((int(v),), (), float(rng.uniform(0, 2)), float(rng.uniform(0, 1)))
            for v in rng.choice(n * n, size=3, replace=False)
        ]
        a_cost = {p.nodes[0]: p.cost for p in seeds}
        got, got_counts = _search_by_opening(tmap, 0, frontier_at, dict(a_cost), list(seeds), 2.5)
        want, want_counts = _search_by_area(
            tmap, 0, frontier_at, dict(a_cost), list(seeds), 2.5, lambda v, _e: v
        )
        assert list(got) == list(want) and got == want and got_counts == want_counts
        if n == 10:
            assert got_counts[0] > 200  # pushes beyond the first record buffers
