"""Semantic topometric segmentation on hand-drawn maps: types, openings, frontiers, paths, graph."""

from __future__ import annotations

import math

import numpy as np
import pytest
from _topometric_maps import (
    CLEARANCE_M,
    GAP,
    LONE,
    PLUS,
    RES_M,
    RING,
    ROOM3,
    ROOM_FRONTIERS,
    T_OPEN,
    H,
)
from scipy import ndimage

from semexplore_gym.core.grid import FREE, OCCUPIED, UNKNOWN, GridGeometry, parse_ascii_grid
from semexplore_gym.core.topometric import (
    AreaType,
    SegmentationParams,
    TopometricMap,
    TopometricSegmenter,
    segment_map,
)

INTER, PATH, DEAD, FRONT = (
    AreaType.INTERSECTION,
    AreaType.PATHWAY,
    AreaType.DEAD_END,
    AreaType.FRONTIER_PATHWAY,
)


def seg(text: str, **kw) -> tuple[np.ndarray, TopometricMap]:
    grid = parse_ascii_grid(text)
    return grid, segment_map(grid, RES_M, CLEARANCE_M, **kw)


def counts(m: TopometricMap) -> tuple[int, int, int, int]:
    c = m.counts()
    return c["intersections"], c["pathways"], c["dead_ends"], c["frontier_pathways"]


def clearance_field_m(grid: np.ndarray, res: float) -> np.ndarray:
    """Metres from each cell centre to the nearest occupied/unknown cell's edge (outside = blocked)."""
    free = np.pad(grid == FREE, 1, constant_values=False)
    return (ndimage.distance_transform_edt(free)[1:-1, 1:-1] - 0.5) * res


def cell_of(m: TopometricMap, xy) -> tuple[int, int]:
    r, c = m.geometry.world_to_grid(xy[0], xy[1])
    return int(r), int(c)


# ----------------------------------------------------------------------------------------------
# The layouts of the issue
# ----------------------------------------------------------------------------------------------


def test_plus_crossing_is_one_intersection_with_four_openings():
    _, m = seg(PLUS)
    assert counts(m) == (1, 0, 4, 0)
    (inter,) = m.areas_of_type(INTER)
    assert m.n_openings(inter.id) == 4
    for oid in inter.opening_ids:
        o = m.openings[oid]
        assert not o.is_frontier
        assert o.width_m == pytest.approx(0.7, abs=0.11)
        assert inter.id in o.area_ids
        other = [a for a in o.area_ids if a != inter.id]
        assert len(other) == 1 and m.areas[other[0]].type == DEAD
    # the crossing's centre is in the middle of the map
    assert inter.centre_m[0] == pytest.approx(1.55, abs=0.3)
    assert inter.centre_m[1] == pytest.approx(1.55, abs=0.3)
    assert math.isnan(m.mean_intersection_path_m)
    assert m.frontiers == []


def test_t_with_one_arm_open_to_unknown():
    grid, m = seg(T_OPEN)
    assert counts(m) == (1, 0, 2, 1)
    (inter,) = m.areas_of_type(INTER)
    (fp,) = m.areas_of_type(FRONT)
    assert m.n_openings(inter.id) == 3
    assert m.n_frontier_pathways(inter.id) == 1
    (f,) = m.frontiers
    assert f.area_id == fp.id
    assert f.intersection_id == inter.id
    assert f.width_m == pytest.approx(0.7, abs=0.11)
    assert 0.3 < f.path_length_m < 1.6  # from the junction's mouth to the frontier target
    # the frontier pathway's two openings: one shared with the intersection, one to unknown space
    fo = m.openings[f.opening_id]
    assert fo.is_frontier and fo.area_ids == (fp.id, -1)
    assert set(fp.opening_ids) == {f.opening_id} | {
        k for k in inter.opening_ids if fp.id in m.openings[k].area_ids
    }
    # the target is where the robot can stand: free, at least the clearance from walls and unknown
    r, c = cell_of(m, f.midpoint_m)
    assert grid[r, c] == FREE
    assert clearance_field_m(grid, RES_M)[r, c] >= CLEARANCE_M - 1e-9
    # ... and close to the frontier itself (the right end of the arm, x = 3.3 m)
    assert 2.9 < f.midpoint_m[0] < 3.3


def test_h_layout():
    _, m = seg(H)
    assert counts(m) == (2, 1, 4, 0)
    (pw,) = m.areas_of_type(PATH)
    inters = m.areas_of_type(INTER)
    assert all(m.n_openings(a.id) == 3 for a in inters)
    # the pathway joins the two intersections
    sides = {a for oid in pw.opening_ids for a in m.openings[oid].area_ids if a != pw.id}
    assert sides == {a.id for a in inters}
    # L_path: centre to centre through the pathway, about the distance between the two bars
    dist = abs(inters[0].centre_m[0] - inters[1].centre_m[0])
    assert dist > 2.0
    assert m.mean_intersection_path_m == pytest.approx(dist, rel=0.15)


def test_ring_with_two_tails():
    _, m = seg(RING)
    assert counts(m) == (2, 2, 2, 0)
    inters = {a.id for a in m.areas_of_type(INTER)}
    for pw in m.areas_of_type(PATH):
        sides = {a for oid in pw.opening_ids for a in m.openings[oid].area_ids if a != pw.id}
        assert sides == inters  # both halves of the ring join the two T-junctions


def test_room_with_three_doors_is_one_intersection():
    _, m = seg(ROOM3)
    assert counts(m) == (1, 0, 3, 0)
    (room,) = m.areas_of_type(INTER)
    assert m.n_openings(room.id) == 3
    for oid in room.opening_ids:
        assert m.openings[oid].width_m == pytest.approx(
            0.5, abs=0.11
        )  # at the doors, not inside the room
    assert room.n_cells > 250  # the whole 1.8 m x 1.8 m room


def test_lone_corridor_open_at_one_end_yields_a_frontier_and_a_path():
    grid, m = seg(LONE)
    assert counts(m) == (0, 0, 0, 1)
    (fp,) = m.areas_of_type(FRONT)
    (f,) = m.frontiers
    assert f.intersection_id is None
    assert f.area_id == fp.id
    # p_l falls back to the pathway's own length: frontier to the far (closed) end
    assert 1.2 < f.path_length_m < 2.4
    path = fp.paths_m[f.opening_id]
    assert np.allclose(path[0], f.midpoint_m)
    assert path[-1][0] < 0.8  # the far end is at the closed left end
    assert m.openings[f.opening_id].area_ids == (fp.id, -1)


def test_lone_corridor_open_at_both_ends_has_two_frontiers():
    text = LONE.replace("#.", "?.")  # open the left end too
    _, m = seg(text)
    assert counts(m) == (0, 0, 0, 1)
    (fp,) = m.areas_of_type(FRONT)
    assert len(m.frontiers) == 2
    assert {f.area_id for f in m.frontiers} == {fp.id}
    assert all(f.intersection_id is None for f in m.frontiers)
    (e,) = m.edges  # the two frontiers are joined through the corridor
    assert {e.opening_a, e.opening_b} == {f.opening_id for f in m.frontiers}
    assert e.length_m > 1.5


def test_room_seen_from_inside_has_a_frontier_pathway_per_gap():
    _, m = seg(ROOM_FRONTIERS)
    assert counts(m) == (1, 0, 0, 3)
    (room,) = m.areas_of_type(INTER)
    assert m.n_openings(room.id) == 3
    assert m.n_frontier_pathways(room.id) == 3
    for f in m.frontiers:
        assert f.intersection_id == room.id
        assert f.path_length_m == pytest.approx(0.0, abs=1e-9)  # the frontier is on the room's wall
        assert f.width_m == pytest.approx(0.6, abs=0.11)
        assert m.areas[f.area_id].n_cells == 0


def test_all_unknown_and_fully_occupied_maps_are_empty():
    for fill in (UNKNOWN, OCCUPIED):
        grid = np.full((30, 40), fill, dtype=np.uint8)
        m = segment_map(grid, 0.05, CLEARANCE_M)
        assert m.areas == {} and m.openings == [] and m.frontiers == [] and m.edges == []
        assert m.area_ids.shape == (30, 40) and (m.area_ids == -1).all()
        assert math.isnan(m.mean_intersection_path_m)


def test_free_space_narrower_than_the_robot_has_no_area():
    # a 0.3 m wide corridor: free, but the robot (0.31 m) cannot enter it
    grid = np.full((20, 40), OCCUPIED, dtype=np.uint8)
    grid[8:11, 2:38] = FREE
    m = segment_map(grid, RES_M, CLEARANCE_M)
    assert m.areas == {}


def test_gap_narrower_than_the_robot_is_not_an_opening():
    _, m = seg(GAP)
    assert counts(m) == (0, 0, 2, 0)
    assert m.openings == [] and m.edges == []
    left = m.area_at(0.8, 1.2)
    right = m.area_at(2.6, 1.2)
    assert left >= 0 and right >= 0 and left != right
    # widening the gap to 0.5 m joins the rooms through an opening or into one area
    grid = parse_ascii_grid(GAP)
    grid[9:14, 16:19] = FREE
    m2 = segment_map(grid, RES_M, CLEARANCE_M)
    a, b = m2.area_at(0.8, 1.2), m2.area_at(2.6, 1.2)
    assert a == b or any({a, b} <= set(o.area_ids) for o in m2.openings)


# ----------------------------------------------------------------------------------------------
# Properties that hold on every layout
# ----------------------------------------------------------------------------------------------

ALL_MAPS = {
    "plus": PLUS,
    "t_open": T_OPEN,
    "h": H,
    "ring": RING,
    "room3": ROOM3,
    "lone": LONE,
    "room_frontiers": ROOM_FRONTIERS,
}


@pytest.mark.parametrize("name", sorted(ALL_MAPS))
def test_paths_keep_the_clearance(name):
    grid, m = seg(ALL_MAPS[name])
    clear = clearance_field_m(grid, RES_M)
    n_paths = 0
    for a in m.areas.values():
        for oid, p in a.paths_m.items():
            assert oid in a.opening_ids
            p = np.asarray(p)
            assert p.ndim == 2 and p.shape[1] == 2 and len(p) >= 2
            n_paths += 1
            for (x0, y0), (x1, y1) in zip(p[:-1], p[1:], strict=True):
                n = max(2, int(math.hypot(x1 - x0, y1 - y0) / 0.02))
                for t in np.linspace(0.0, 1.0, n):
                    r, c = cell_of(m, (x0 + t * (x1 - x0), y0 + t * (y1 - y0)))
                    # vertices are configuration-space cells; segments may clip a cell corner
                    assert clear[r, c] >= CLEARANCE_M - RES_M + 1e-9, (name, a.id, oid)
            for x, y in p:
                r, c = cell_of(m, (x, y))
                assert clear[r, c] >= CLEARANCE_M - 1e-9
    assert n_paths > 0


@pytest.mark.parametrize("name", sorted(ALL_MAPS))
def test_graph_and_paths_are_consistent(name):
    _, m = seg(ALL_MAPS[name])
    assert [o.id for o in m.openings] == list(range(len(m.openings)))
    for o in m.openings:
        for aid in o.area_ids:
            assert aid == -1 or (aid in m.areas and o.id in m.areas[aid].opening_ids)
        assert (o.area_ids[1] == -1) == o.is_frontier
        assert (
            o.width_m >= 2 * CLEARANCE_M - RES_M
        )  # never narrower than the robot (one-cell rounding)
    n_edges = 0
    for a in m.areas.values():
        k = len(a.opening_ids)
        mine = [e for e in m.edges if e.area_id == a.id]
        if a.type == INTER:
            assert k >= 3 and len(mine) == k * (k - 1) // 2
            for e in mine:  # through the centre: the sum of the two legs
                leg = sum(
                    float(np.hypot(*np.diff(a.paths_m[o], axis=0).T).sum())
                    for o in (e.opening_a, e.opening_b)
                )
                assert e.length_m == pytest.approx(leg, abs=1e-6)
        elif a.type == PATH:
            assert k == 2 and len(mine) == 1
        elif a.type == DEAD:
            assert k <= 1 and mine == []
        n_edges += len(mine)
        for e in mine:
            p = np.asarray(e.path_m)
            assert e.length_m == pytest.approx(
                float(np.hypot(*np.diff(p, axis=0).T).sum()), abs=1e-6
            )
            oa, ob = m.openings[e.opening_a], m.openings[e.opening_b]
            assert np.allclose(p[0], oa.anchor_m) and np.allclose(p[-1], ob.anchor_m)
            assert e.length_m >= math.dist(oa.anchor_m, ob.anchor_m) - 1e-9
    assert n_edges == len(m.edges)


@pytest.mark.parametrize("name", sorted(ALL_MAPS))
def test_raster_covers_the_reachable_free_space(name):
    grid, m = seg(ALL_MAPS[name])
    ids = m.area_ids
    assert ids.dtype == np.int32 and ids.shape == grid.shape
    assert (grid[ids >= 0] == FREE).all()  # never a wall or unknown cell
    assert set(np.unique(ids[ids >= 0])) == {a.id for a in m.areas.values() if a.n_cells > 0}
    for a in m.areas.values():
        assert a.n_cells == int((ids == a.id).sum())
    # every free cell the robot's body can cover (within the clearance of C-space) has an area
    cspace = clearance_field_m(grid, RES_M) >= CLEARANCE_M
    reach = ndimage.distance_transform_edt(~cspace) * RES_M <= CLEARANCE_M
    assert (ids[reach & (grid == FREE)] >= 0).all()
    # area_at finds the area of a point, and the nearest area from outside
    for a in m.areas.values():
        if a.n_cells:
            assert m.area_at(*a.centre_m) == a.id


# ----------------------------------------------------------------------------------------------
# Noise, input forms, identity
# ----------------------------------------------------------------------------------------------


def add_slam_noise(grid: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """Ragged walls (one cell in five next to a wall), six 1-cell specks and three 2x2 unknown
    holes, the specks and holes at least 0.3 m from walls and from each other."""
    g = grid.copy()
    near_wall = (g == FREE) & ndimage.binary_dilation(g == OCCUPIED)
    cells = np.argwhere(near_wall)
    g[tuple(cells[rng.random(len(cells)) < 0.2].T)] = OCCUPIED
    taken = g != FREE
    for size, value, n in ((1, OCCUPIED, 6), (2, UNKNOWN, 3)):
        for _ in range(n):
            ok = np.argwhere(~ndimage.binary_dilation(taken, iterations=6) & (g == FREE))
            r, c = ok[rng.integers(len(ok))]
            g[r : r + size, c : c + size] = value
            taken[r : r + size, c : c + size] = True
    return g


@pytest.mark.parametrize(
    "name,expected", [("room3", (1, 0, 3, 0)), ("h", (2, 1, 4, 0)), ("t_open", (1, 0, 2, 1))]
)
def test_robust_to_slam_noise(name, expected):
    # at 0.05 m per cell (each drawn cell becomes 2 x 2), like a real SLAM map
    clean = np.kron(parse_ascii_grid(ALL_MAPS[name]), np.ones((2, 2), dtype=np.uint8))
    assert counts(segment_map(clean, 0.05, CLEARANCE_M)) == expected
    for seed in range(3):
        noisy = add_slam_noise(clean, np.random.default_rng(seed))
        assert (noisy != clean).sum() > 20
        assert counts(segment_map(noisy, 0.05, CLEARANCE_M)) == expected, seed


def test_one_cell_speck_in_a_corridor_is_ignored():
    grid = parse_ascii_grid(LONE)
    grid[5, 10] = OCCUPIED  # in the middle of the corridor: the robot could not pass it
    assert counts(segment_map(grid, RES_M, CLEARANCE_M)) == (0, 0, 0, 1)
    off = SegmentationParams(max_speckle_area_m2=0.0)
    assert counts(segment_map(grid, RES_M, CLEARANCE_M, params=off)) != (0, 0, 0, 1)


def test_small_unknown_hole_in_a_room_is_not_a_frontier():
    grid = parse_ascii_grid(ROOM3)
    grid[16:18, 16:18] = UNKNOWN  # 0.2 m x 0.2 m unseen patch in the room
    m = segment_map(grid, RES_M, CLEARANCE_M)
    assert counts(m) == (1, 0, 3, 0) and m.frontiers == []


def test_ros_grid_gives_the_same_map():
    grid = parse_ascii_grid(T_OPEN)
    ros = np.full(grid.shape, -1, dtype=np.int8)
    ros[grid == FREE] = 0
    ros[grid == OCCUPIED] = 100
    a = segment_map(grid, RES_M, CLEARANCE_M)
    b = segment_map(ros, RES_M, CLEARANCE_M)
    assert counts(a) == counts(b)
    assert np.array_equal(a.area_ids, b.area_ids)


def test_geometry_places_the_map_in_the_world():
    grid = parse_ascii_grid(T_OPEN)
    geo = GridGeometry(RES_M, -5.0, 2.0, grid.shape[0], grid.shape[1])
    a = segment_map(grid, RES_M, CLEARANCE_M)
    b = segment_map(grid, geo, CLEARANCE_M)
    assert counts(a) == counts(b)
    fa, fb = a.frontiers[0], b.frontiers[0]
    assert fb.midpoint_m[0] == pytest.approx(fa.midpoint_m[0] - 5.0)
    assert fb.midpoint_m[1] == pytest.approx(fa.midpoint_m[1] + 2.0)
    assert b.area_at(*fb.midpoint_m) == fb.area_id


def test_area_ids_are_stable_while_the_map_grows():
    full = parse_ascii_grid(H)
    prev = None
    history: list[TopometricMap] = []
    for x_m in (1.3, 2.0, 2.7, 3.7):
        g = full.copy()
        g[:, int(x_m / RES_M) :] = UNKNOWN  # the right part is not explored yet
        prev = segment_map(g, RES_M, CLEARANCE_M, previous=prev)
        history.append(prev)
    first, last = history[1], history[-1]
    assert counts(first) == (1, 0, 2, 1)  # the left T, its frontier pathway towards the right
    assert counts(last) == (2, 1, 4, 0)
    # every area of the left T keeps its id; the frontier pathway becomes the pathway
    for a in first.areas.values():
        b = last.areas[a.id]
        assert math.dist(a.centre_m, b.centre_m) < 1.0
    (fp,) = first.areas_of_type(FRONT)
    assert last.areas[fp.id].type == PATH
    # new areas get new ids
    assert len(set(last.areas) - set(first.areas)) == 3
    assert max(last.areas) < last.extras["next_area_id"]


def test_ids_without_previous_are_compact_and_deterministic():
    _, a = seg(H)
    _, b = seg(H)
    assert sorted(a.areas) == list(range(len(a.areas)))
    assert np.array_equal(a.area_ids, b.area_ids)
    assert [o.midpoint_m for o in a.openings] == [o.midpoint_m for o in b.openings]


def test_area_type_raster_matches_areas():
    _, m = seg(H)
    t = m.area_type_raster()
    assert t.dtype == np.int16
    for a in m.areas.values():
        assert (t[m.area_ids == a.id] == int(a.type)).all()
    assert (t[m.area_ids < 0] == -1).all()


def test_debug_extras():
    _, m = seg(PLUS, params=SegmentationParams(keep_debug=True))
    sk = m.extras["skeleton_cells"]
    assert sk.ndim == 2 and sk.shape[1] == 2 and len(sk) > 20
    assert set(m.extras["stage_ms"]) >= {"distance", "skeleton", "graph", "regions", "frontiers"}
    assert m.time_ms > 0


def test_records_match_their_constructors():
    _, m = seg(T_OPEN)
    for obj in [m.openings[0], next(iter(m.areas.values())), m.edges[0], m.frontiers[0]]:
        again = type(obj)(*obj)  # the generated constructor, field by field
        assert type(obj)._fields == again._fields
        for name in obj._fields:
            a, b = getattr(obj, name), getattr(again, name)
            assert type(a) is type(b)
            if isinstance(a, np.ndarray):
                assert np.array_equal(a, b)
            elif name != "paths_m":
                assert a == b
        with pytest.raises(AttributeError):
            obj.id = 99  # type: ignore[misc]  (records are immutable)
    o = m.openings[0]
    assert type(o.area_ids) is tuple and type(o.midpoint_m) is tuple and type(o.width_m) is float
    a = next(iter(m.areas.values()))
    assert isinstance(a.type, AreaType) and type(a.opening_ids) is tuple and type(a.n_cells) is int


def test_segmenter_reuses_scratch_without_changing_results():
    """A TopometricSegmenter gives segment_map's results on maps that grow, shrink and grow,
    and a later call never alters an earlier result (no output aliases the scratch arrays)."""
    import pickle

    segmenter = TopometricSegmenter()
    grids = [_corridor_grid(s, seed) for s, seed in ((150, 0), (90, 1), (200, 2), (60, 3))]
    maps = [segmenter(g, RES_M, CLEARANCE_M) for g in grids]
    first_raster = maps[0].area_ids.copy()
    first_paths = [e.path_m.copy() for e in maps[0].edges]
    for g, m in zip(grids, maps, strict=True):
        ref = segment_map(g, RES_M, CLEARANCE_M)
        assert np.array_equal(m.area_ids, ref.area_ids)
        assert m.counts() == ref.counts() and len(m.edges) == len(ref.edges)
        assert [o.width_m for o in m.openings] == [o.width_m for o in ref.openings]
        assert [f.midpoint_m for f in m.frontiers] == [f.midpoint_m for f in ref.frontiers]
        for e, r in zip(m.edges, ref.edges, strict=True):
            assert e.length_m == r.length_m and np.array_equal(e.path_m, r.path_m)
    assert np.array_equal(maps[0].area_ids, first_raster)
    assert all(np.array_equal(e.path_m, p) for e, p in zip(maps[0].edges, first_paths, strict=True))
    # the scratch stays behind when the segmenter is pickled (policies travel to workers)
    assert len(pickle.dumps(segmenter)) < 1000
    again = pickle.loads(pickle.dumps(segmenter))
    assert np.array_equal(again(grids[2], RES_M, CLEARANCE_M).area_ids, maps[2].area_ids)
    with pytest.raises(TypeError, match="SegmentationParams"):
        TopometricSegmenter(params={"spur_ratio": 1.0})  # type: ignore[arg-type]


def _corridor_grid(size: int, seed: int) -> np.ndarray:
    """Crossing 10-cell corridors every 50 cells, some segments walled off, open at the edges."""
    rng = np.random.default_rng(seed)
    g = np.full((size, size), OCCUPIED, dtype=np.uint8)
    starts = np.arange(20, size - 9, 50)
    for s in starts:
        g[s : s + 10, :] = FREE
        g[:, s : s + 10] = FREE
    for s in starts:
        for m in rng.integers(0, size - 4, size=2):
            if rng.random() < 0.5:
                g[s : s + 10, m : m + 4] = OCCUPIED
            else:
                g[m : m + 4, s : s + 10] = OCCUPIED
    return g


def _reference_graph_quantities(m: TopometricMap):
    """p_l per frontier and L_path straight from their definitions (Dijkstra over the edges)."""
    import heapq

    inter = {a.id for a in m.areas.values() if a.type == INTER}
    adj: dict[int, list[tuple[int, float]]] = {}
    for e in m.edges:
        if e.area_id not in inter:
            adj.setdefault(e.opening_a, []).append((e.opening_b, e.length_m))
            adj.setdefault(e.opening_b, []).append((e.opening_a, e.length_m))
    out = []
    for f in m.frontiers:
        dist, heap, hit = {f.opening_id: 0.0}, [(0.0, f.opening_id)], None
        while heap:
            d, u = heapq.heappop(heap)
            if d > dist[u]:
                continue
            on = [a for a in m.openings[u].area_ids if a in inter]
            if on:
                hit = (on[0], d)
                break
            for v, w in adj.get(u, ()):
                if d + w < dist.get(v, math.inf):
                    dist[v] = d + w
                    heapq.heappush(heap, (d + w, v))
        out.append(hit)
    leg = {}  # (area, opening) -> length of the area's path from that opening
    for e in m.edges:
        if e.area_id not in inter:
            leg.setdefault((e.area_id, e.opening_a), e.length_m)
    for a in m.areas.values():
        for oid, p in a.paths_m.items():
            if a.id in inter:
                leg[(a.id, oid)] = float(np.sum(np.hypot(*np.diff(p, axis=0).T)))
    lengths = []
    for a in m.areas.values():
        if a.type == PATH:
            o1, o2 = a.opening_ids
            ends = [
                [b for b in m.openings[o].area_ids if b in inter and b != a.id] for o in (o1, o2)
            ]
            if ends[0] and ends[1]:
                lengths.append(leg[(ends[0][0], o1)] + leg[(a.id, o1)] + leg[(ends[1][0], o2)])
    for o in m.openings:
        a0, a1 = o.area_ids
        if a0 != a1 and a0 in inter and a1 in inter:
            lengths.append(leg[(a0, o.id)] + leg[(a1, o.id)])
    return out, (float(np.mean(lengths)) if lengths and len(inter) >= 2 else math.nan)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_frontier_distances_and_l_path_match_their_definitions(seed):
    m = segment_map(_corridor_grid(170, seed), RES_M, CLEARANCE_M)
    assert m.frontiers and m.counts()["intersections"] >= 2
    expected, l_path = _reference_graph_quantities(m)
    for f, hit in zip(m.frontiers, expected, strict=True):
        if hit is None:
            assert f.intersection_id is None
        else:
            assert f.intersection_id == hit[0]
            assert f.path_length_m == pytest.approx(hit[1], abs=1e-9)
    assert m.mean_intersection_path_m == pytest.approx(l_path, rel=1e-6)
