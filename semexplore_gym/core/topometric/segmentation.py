"""Semantic topometric segmentation of an occupancy grid: :func:`segment_map`.

Algorithm (a clearance-aware skeleton segmentation, in the spirit of GRID-FAST's semantics)
--------------------------------------------------------------------------------------------
1. **Crop and clean.** Work on the bounding box of the free cells (plus a 2-cell border; the
   space outside the map counts as unknown). Occupied specks up to ``max_speckle_area_m2`` that
   sit in free space are erased; unknown holes up to ``max_hole_area_m2`` are closed (free when
   surrounded by free cells, occupied when they touch a wall).
2. **Configuration space.** An exact Euclidean distance transform to the nearest non-free cell
   (occupied *or* unknown) gives every cell's clearance ``d`` (metres from the cell centre to the
   nearest blocked cell's edge). ``C = {free, d >= clearance}`` is where the robot centre may be.
   Gaps narrower than the robot are not in ``C``, so they never become openings.
3. **Skeleton.** ``C`` is thinned (Zhang-Suen with a work list) to a one-pixel skeleton, read as
   a graph under m-adjacency: nodes are junction blobs and end points, edges are pixel chains.
4. **Pruning.** A branch from a junction ``J`` (inscribed radius ``r``) to an end ``E`` is a spur
   when it protrudes less than ``spur_ratio * r + min_dead_end_depth_m`` beyond the inscribed
   circle (``|E - J| + d(E) - r``): room corners (about ``0.41 r``), wall noise and shallow
   niches go; real dead ends stay. Repeated until nothing changes.
5. **Intersections and openings.** Every edge end at a junction leaves the junction's core (its
   inscribed circle times ``core_radius_ratio``). When the cores of the two junctions of an edge
   overlap along it (less than ``min_pathway_length_m`` between them), the junctions merge into
   one intersection (a room's several skeleton junctions become one). Otherwise an opening is
   placed on the edge just outside the core, slid outwards to the narrowest point
   (``2 d + opening_distance_weight * s`` minimal). The opening's segment is the shortest
   wall-to-wall chord through that skeleton point (within ``chord_search_deg`` of the normal).
6. **Regions.** Openings cut the skeleton into regions (union-find over nodes and edge pieces);
   each region grows over ``C`` and then over the rest of free space (``cover_depth_m``), never
   across an opening chord, giving a per-cell area raster and one shortest-path tree per region.
7. **Frontiers.** Labelled free cells 4-adjacent to unknown are clustered per region. A cluster
   at least ``min_frontier_width_m`` wide with at least ``min_frontier_depth_m`` of unknown behind
   it is a frontier; its target is the nearest configuration-space cell (where the robot can
   stand, ``>= clearance`` from walls and unknown space).
8. **Types** (GRID-FAST's rule, frontiers counting as openings): a region with ``>= 3`` openings
   is an intersection, 2 a pathway (a *frontier pathway* when one is a frontier), 1 a dead end
   (a *frontier pathway* when it is a frontier: a lone corridor or the robot's first scan). A
   frontier on an intersection's wall gets a zero-area frontier pathway, as in GRID-FAST.
9. **Paths and graph.** Per area, paths follow its tree (skeleton and configuration space) and
   are shortcut along lines of sight inside the area's ``C``: opening -> centre (intersections),
   opening -> opening (pathways), opening -> far end (dead ends). Graph edges join the openings
   of each area with metric lengths. ``p_l`` is the graph distance from a frontier to the nearest
   intersection; ``L_path`` the mean centre-to-centre length between adjacent intersections.
10. **Identity.** With ``previous``, areas inherit the id of the previous area their skeleton
    overlaps most (one-to-one, by position in the world frame), so ids are stable while the map
    grows; zero-area frontier pathways are matched by frontier position.

Cost is linear in the number of cells (no pairwise loops over openings). See
``scripts/bench_segmentation.py`` for measured times.
"""

from __future__ import annotations

import heapq
import math
import time
from typing import Any

import numpy as np
import numpy.typing as npt

from semexplore_gym.core.grid import FREE, OCCUPIED, UNKNOWN, GridGeometry, from_ros_values, validate_encoded_grid
from semexplore_gym.core.topometric import _kernels as K
from semexplore_gym.core.topometric.params import SegmentationParams
from semexplore_gym.core.topometric.types import Area, AreaType, Frontier, GraphEdge, Opening, TopometricMap

_MARGIN = 2


# ----------------------------------------------------------------------------------------------
# Input checking
# ----------------------------------------------------------------------------------------------


def _as_encoded_grid(grid: npt.ArrayLike) -> np.ndarray:
    a = np.asarray(grid)
    if a.ndim != 2:
        raise ValueError(f"grid must be 2-D (rows, cols), got shape {a.shape}")
    if a.size == 0:
        raise ValueError(f"grid is empty (shape {a.shape})")
    if a.dtype == np.uint8:
        return a
    if a.dtype == np.bool_ or not np.issubdtype(a.dtype, np.integer):
        raise TypeError(
            f"grid must be the uint8 encoding (UNKNOWN={UNKNOWN}, FREE={FREE}, OCCUPIED={OCCUPIED}) "
            f"or a ROS integer grid (-1 / 0..100), got dtype {a.dtype}"
        )
    return from_ros_values(a)


def _as_geometry(geometry_or_resolution: GridGeometry | float, shape: tuple[int, int]) -> GridGeometry:
    if isinstance(geometry_or_resolution, GridGeometry):
        g = geometry_or_resolution
        if g.shape != shape:
            raise ValueError(f"grid shape {shape} does not match geometry shape {g.shape}")
        return g
    res = geometry_or_resolution
    if isinstance(res, bool) or not isinstance(res, (int, float, np.integer, np.floating)):
        raise TypeError(f"geometry_or_resolution must be a GridGeometry or a resolution in metres, got {type(res).__name__}")
    res = float(res)
    if not (math.isfinite(res) and res > 0):
        raise ValueError(f"resolution_m must be a positive finite number, got {geometry_or_resolution!r}")
    return GridGeometry(res, 0.0, 0.0, shape[0], shape[1])


def _check_clearance(clearance_m: float) -> float:
    if isinstance(clearance_m, bool) or not isinstance(clearance_m, (int, float, np.integer, np.floating)):
        raise TypeError(f"clearance_m must be a number of metres, got {type(clearance_m).__name__}")
    c = float(clearance_m)
    if not (math.isfinite(c) and c >= 0):
        raise ValueError(f"clearance_m must be a finite number >= 0, got {clearance_m!r}")
    return c


# ----------------------------------------------------------------------------------------------
# Entry point
# ----------------------------------------------------------------------------------------------


def segment_map(
    grid: npt.ArrayLike,
    geometry_or_resolution: GridGeometry | float,
    clearance_m: float,
    params: SegmentationParams | None = None,
    previous: TopometricMap | None = None,
) -> TopometricMap:
    """Segment an occupancy grid into intersections, pathways, dead ends and frontier pathways.

    Args:
        grid: ``(H, W)`` occupancy grid, row 0 = lowest y: the uint8 encoding of
            :mod:`semexplore_gym.core.grid` (UNKNOWN 128 / FREE 255 / OCCUPIED 0) or a ROS integer
            grid (-1 unknown, 0..100 occupancy; >= 50 occupied).
        geometry_or_resolution: The grid's :class:`GridGeometry`, or its resolution in metres
            (origin at (0, 0)).
        clearance_m: Robot radius plus safety margin, metres. Paths keep at least this distance
            from occupied and unknown cells; passages narrower than twice it are closed.
        params: :class:`SegmentationParams` (defaults if None).
        previous: The map returned for the previous (smaller) version of this grid; area ids are
            carried over by position.

    Returns:
        A :class:`TopometricMap` (see :mod:`semexplore_gym.core.topometric.types`).

    Raises:
        TypeError: wrong dtype or argument types.
        ValueError: wrong shape, values outside the encoding, non-positive resolution, negative
            clearance, or a geometry that does not match the grid.
    """
    t_start = time.perf_counter()
    enc = _as_encoded_grid(grid)
    geometry = _as_geometry(geometry_or_resolution, enc.shape)
    clearance = _check_clearance(clearance_m)
    if params is None:
        params = SegmentationParams()
    elif not isinstance(params, SegmentationParams):
        raise TypeError(f"params must be a SegmentationParams, got {type(params).__name__}")
    if previous is not None and not isinstance(previous, TopometricMap):
        raise TypeError(f"previous must be a TopometricMap or None, got {type(previous).__name__}")
    return _Segmenter(enc, geometry, clearance, params, previous, t_start).run()


def _empty_map(geometry: GridGeometry, clearance: float, previous: TopometricMap | None, t_start: float, stage_ms: dict) -> TopometricMap:
    next_id = _next_id_of(previous)
    return TopometricMap(
        geometry=geometry,
        area_ids=np.full(geometry.shape, -1, dtype=np.int32),
        areas={},
        openings=[],
        frontiers=[],
        edges=[],
        mean_intersection_path_m=float("nan"),
        clearance_m=clearance,
        time_ms=(time.perf_counter() - t_start) * 1000.0,
        extras={"next_area_id": next_id, "stage_ms": stage_ms},
    )


def _next_id_of(previous: TopometricMap | None) -> int:
    if previous is None:
        return 0
    nid = previous.extras.get("next_area_id") if isinstance(previous.extras, dict) else None
    base = max(previous.areas) + 1 if previous.areas else 0
    return max(int(nid), base) if nid is not None else base


class _Segmenter:
    """One segmentation run (internal; holds the intermediate arrays of the crop)."""

    def __init__(self, enc, geometry, clearance, params, previous, t_start) -> None:
        self.enc = enc
        self.g = geometry
        self.res = geometry.resolution_m
        self.clear_m = clearance
        self.p = params
        self.previous = previous
        self.t_start = t_start
        self.stage_ms: dict[str, float] = {}
        self._t = t_start

    def _lap(self, name: str) -> None:
        now = time.perf_counter()
        self.stage_ms[name] = round((now - self._t) * 1000.0, 3)
        self._t = now

    # ------------------------------------------------------------------------------------------
    def run(self) -> TopometricMap:
        p = self.p
        res = self.res
        enc = np.ascontiguousarray(self.enc)
        H0, W0 = enc.shape
        bad, rmin, rmax, cmin, cmax = K.scan_grid(enc)
        if bad >= 0:
            validate_encoded_grid(enc)  # raises with the offending value and position
        if rmin < 0:
            self._lap("prepare")
            return _empty_map(self.g, self.clear_m, self.previous, self.t_start, self.stage_ms)
        r0, r1 = rmin - _MARGIN, rmax + _MARGIN + 1
        c0, c1 = cmin - _MARGIN, cmax + _MARGIN + 1
        work = np.full((r1 - r0, c1 - c0), UNKNOWN, dtype=np.uint8)
        sr0, sr1, sc0, sc1 = max(r0, 0), min(r1, H0), max(c0, 0), min(c1, W0)
        work[sr0 - r0 : sr1 - r0, sc0 - c0 : sc1 - c0] = enc[sr0:sr1, sc0:sc1]
        self.r0, self.c0 = r0, c0
        self.work = work
        H, W = work.shape
        self.H, self.W = H, W

        cell_area = res * res
        K.filter_small_blobs(work, int(p.max_speckle_area_m2 / cell_area + 1e-9), int(p.max_hole_area_m2 / cell_area + 1e-9))
        free = work == FREE
        self.free = free
        self._lap("filter")

        dcell, cs_u8 = K.clearance_field(free, self.clear_m / res - 1e-6)
        cspace = cs_u8.view(np.bool_)
        self.dcell = dcell
        self.cspace = cspace
        self._lap("distance")
        if not cspace.any():
            return _empty_map(self.g, self.clear_m, self.previous, self.t_start, self.stage_ms)

        sk, px = K.thin(cs_u8)
        self._lap("skeleton")

        st = np.full(H * W, -1, dtype=np.int32)
        min_depth_cells = p.min_dead_end_depth_m / res
        graph = None
        for _ in range(max(1, int(p.max_prune_iterations))):
            graph = self._extract(sk, px, dcell, st)
            spur = K.spur_pixels(W, graph["rep"], graph["r"], graph["deg"], graph["noff"], graph["npx"], graph["ne"],
                                 graph["ea"], graph["eb"], graph["eoff"], graph["epx"], dcell, p.spur_ratio, min_depth_cells)
            if spur.size == 0:
                break
            sk.ravel()[spur] = 0
            px = px[sk.ravel()[px] != 0]
            px = K.reduce_blobs(sk, px)
        else:
            graph = self._extract(sk, px, dcell, st)
        self.sk, self.px = sk, px
        self._lap("graph")

        internal, open_a, open_b = K.place_openings(
            W, graph["n"], graph["rep"], graph["r"], graph["deg"], graph["ne"], graph["ea"], graph["eb"], graph["eoff"],
            graph["epx"], dcell, free, p.core_radius_ratio, p.opening_distance_weight,
            max(2, int(round(p.min_pathway_length_m / res))), math.radians(p.chord_search_deg),
        )
        lab = np.full(H * W, -1, dtype=np.int32)
        n_reg, node_reg, mid_reg, op_px, op_edge, op_idx, op_core, op_far = K.build_regions(
            graph["n"], graph["alive"], graph["noff"], graph["npx"], graph["ne"], graph["ea"], graph["eb"], graph["eoff"],
            graph["epx"], internal, open_a, open_b, lab,
        )
        barrier = np.zeros(H * W, dtype=np.int32)
        ends, widths = K.opening_chords(
            free, dcell, op_px, op_edge, op_idx, graph["eoff"], graph["epx"], barrier, 4, math.radians(p.chord_search_deg)
        )
        self._lap("openings")

        centres = K.region_centres(px, lab, dcell, n_reg)
        parent = np.full(H * W, -1, dtype=np.int32)
        depth = np.zeros(H * W, dtype=np.int32)
        cover_m = p.cover_depth_m if p.cover_depth_m is not None else 2.0 * self.clear_m + 2.0 * res
        K.grow_regions(W, sk, px, centres, lab, cspace, free, barrier, op_core, int(math.ceil(cover_m / res)), parent, depth)
        self.lab, self.parent, self.depth, self.barrier = lab, parent, depth, barrier
        self._lap("regions")

        fronts = self._frontiers(n_reg)
        self._lap("frontiers")

        side_core, side_far = self._opening_sides(graph, op_edge, op_idx, open_a)
        return self._assemble(n_reg, centres, op_px, op_core, op_far, ends, widths, side_core, side_far, fronts)

    # ------------------------------------------------------------------------------------------
    def _extract(self, sk, px, dcell, st) -> dict[str, Any]:
        (n, rep, r, deg, noff, npx, ne, ea, eb, eoff, epx) = K.extract_graph(sk, px, dcell, st)
        alive = np.ones(n, dtype=np.bool_)
        if ne and np.any(deg == 2):
            alive, ne, ea, eb, eoff, epx = K.splice_pass_nodes(n, deg, noff, npx, ne, ea, eb, eoff, epx)
            deg = np.zeros(n, dtype=np.int64)
            np.add.at(deg, ea, 1)
            np.add.at(deg, eb, 1)
        return {"n": n, "rep": rep, "r": r, "deg": deg, "noff": noff, "npx": npx, "ne": ne, "ea": ea, "eb": eb,
                "eoff": eoff, "epx": epx, "alive": alive}

    def _opening_sides(self, graph, op_edge, op_idx, open_a):
        """Region cells on either side of each opening pixel (core side, far side)."""
        eoff, epx, ea, eb, rep = graph["eoff"], graph["epx"], graph["ea"], graph["eb"], graph["rep"]
        n = op_edge.size
        side_core = np.empty(n, dtype=np.int64)
        side_far = np.empty(n, dtype=np.int64)
        for k in range(n):
            e = int(op_edge[k])
            lo, hi = int(eoff[e]), int(eoff[e + 1])
            i = int(op_idx[k])
            at_a = open_a[e] == i
            if at_a:
                side_core[k] = epx[lo + i - 1] if i >= 1 else rep[ea[e]]
                side_far[k] = epx[lo + i + 1]
            else:
                side_core[k] = epx[lo + i + 1] if lo + i + 1 < hi else rep[eb[e]]
                side_far[k] = epx[lo + i - 1]
        return side_core, side_far

    # ------------------------------------------------------------------------------------------
    def _frontiers(self, n_reg: int) -> list[dict]:
        """Valid frontier groups: dicts with region, cells, width, endpoints, mid cell, anchor."""
        p = self.p
        res = self.res
        W = self.W
        lab = self.lab
        cells, cluster, orow, ocol, n_cl = K.frontier_cells(W, self.work, lab)
        if n_cl == 0:
            return []
        min_w_cells = (p.min_frontier_width_m if p.min_frontier_width_m is not None else 2.0 * self.clear_m) / res
        depth_cells = (p.min_frontier_depth_m if p.min_frontier_depth_m is not None else self.clear_m) / res
        regs = lab[cells].astype(np.int64)
        order = np.argsort(cluster, kind="stable")
        bounds = np.searchsorted(cluster[order], np.arange(n_cl + 1))
        cs_flat = self.cspace.ravel()
        out: list[dict] = []
        for k in range(n_cl):
            idx = order[bounds[k] : bounds[k + 1]]
            if idx.size == 0:
                continue
            rk = regs[idx]
            if rk.min() == rk.max():
                groups = [(idx, int(rk[0]))]
            else:
                # a frontier seen from several areas: split it when each part is wide enough,
                # else give all of it to the area holding most of it
                parts = [(idx[rk == g], int(g)) for g in np.unique(rk)]
                groups = [(q, g) for q, g in parts if _geom(cells[q], W)["width"] + 1e-9 >= min_w_cells]
                if not groups:
                    groups = [(idx, max(parts, key=lambda qg: len(qg[0]))[1])]
            for gidx, region in groups:
                self._frontier_from(gidx, region, cells, orow, ocol, min_w_cells, depth_cells, cs_flat, out)
        return out

    def _frontier_from(self, gidx, region, cells, orow, ocol, min_w_cells, depth_cells, cs_flat, out) -> None:
        W = self.W
        gc = cells[gidx]
        geo = _geom(gc, W)
        if geo["width"] + 1e-9 < min_w_cells:
            return
        vr = float(orow[gidx].sum())
        vc = float(ocol[gidx].sum())
        nrm = math.hypot(vr, vc)
        # the target: the configuration-space cell that the frontier cell nearest the middle leads to
        anchor = -1
        mid = -1
        for j in geo["by_centre"][:32]:
            cell = int(gc[j])
            a, ok = K.chain_to_tree(self.parent, cs_flat, cell, 10 * (self.H + self.W))
            if ok and self.lab[a] == region:
                anchor, mid = int(a), cell
                break
        if anchor < 0:
            return
        if nrm == 0.0:
            mr, mc = divmod(mid, W)
            ar, ac = divmod(anchor, W)
            vr, vc = float(mr - ar), float(mc - ac)
            nrm = math.hypot(vr, vc)
        if nrm > 0.0:
            ur, uc = vr / nrm, vc / nrm
            starts = [mid, int(gc[geo["q1"]]), int(gc[geo["q3"]])]
            if not any(K.unknown_depth_ok(self.work, s // W, s % W, ur, uc, depth_cells) for s in starts):
                return
        out.append({
            "region": region,
            "n": int(gidx.size),
            "width_cells": geo["width"],
            "ends": geo["ends"],
            "mid_cell": mid,
            "anchor": anchor,
        })

    # ------------------------------------------------------------------------------------------
    def _to_world(self, rows: np.ndarray, cols: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Fractional work-grid (row, col) (cell centres at +0.5) to world metres."""
        g = self.g
        x = g.origin_x_m + (np.asarray(cols, dtype=np.float64) + self.c0) * g.resolution_m
        y = g.origin_y_m + (np.asarray(rows, dtype=np.float64) + self.r0) * g.resolution_m
        return x, y

    def _cell_xy(self, cell: int) -> tuple[float, float]:
        r, c = divmod(int(cell), self.W)
        x, y = self._to_world(np.float64(r + 0.5), np.float64(c + 0.5))
        return (float(x), float(y))

    def _assemble(self, n_reg, centres, op_px, op_core, op_far, ends, widths, side_core, side_far, fronts) -> TopometricMap:
        p = self.p
        res = self.res
        W = self.W
        lab = self.lab
        n_op = op_px.size

        # --- types ------------------------------------------------------------------------------
        n_regular = np.bincount(op_core, minlength=n_reg) + np.bincount(op_far, minlength=n_reg)
        f_reg = np.array([f["region"] for f in fronts], dtype=np.int64)
        n_front = np.bincount(f_reg, minlength=n_reg) if f_reg.size else np.zeros(n_reg, dtype=np.int64)
        total = n_regular + n_front
        rtype = np.full(n_reg, int(AreaType.DEAD_END), dtype=np.int64)
        rtype[total >= 3] = int(AreaType.INTERSECTION)
        two = total == 2
        rtype[two & (n_front >= 1)] = int(AreaType.FRONTIER_PATHWAY)
        rtype[two & (n_front == 0)] = int(AreaType.PATHWAY)
        rtype[(total == 1) & (n_front == 1)] = int(AreaType.FRONTIER_PATHWAY)
        n_cells = np.bincount(lab[lab >= 0], minlength=n_reg)

        # --- openings ---------------------------------------------------------------------------
        # provisional area index: regions 0..n_reg-1, zero-area frontier pathways after them
        er0, ec0 = self._to_world(ends[:, 0], ends[:, 1])
        er1, ec1 = self._to_world(ends[:, 2], ends[:, 3])
        op_rec: list[dict] = []  # provisional openings
        for k in range(n_op):
            op_rec.append({
                "ends": np.array([[er0[k], ec0[k]], [er1[k], ec1[k]]]),
                "width": float(widths[k] * res),
                "areas": (int(op_core[k]), int(op_far[k])),
                "frontier": False,
                "anchor": int(op_px[k]),
            })
        region_ops: list[list[int]] = [[] for _ in range(n_reg)]
        for k in range(n_op):
            region_ops[int(op_core[k])].append(k)
            region_ops[int(op_far[k])].append(k)
        zero_fp: list[dict] = []  # {"host": region, "twin": op, "front": op, "f": frontier}
        region_fronts: list[list[tuple[int, dict]]] = [[] for _ in range(n_reg)]
        front_of_op: dict[int, dict] = {}
        for f in fronts:
            g = f["region"]
            (fr0, fc0), (fr1, fc1) = f["ends"]
            wx0, wy0 = self._to_world(np.float64(fr0 + 0.5), np.float64(fc0 + 0.5))
            wx1, wy1 = self._to_world(np.float64(fr1 + 0.5), np.float64(fc1 + 0.5))
            seg = np.array([[float(wx0), float(wy0)], [float(wx1), float(wy1)]])
            mx, my = self._cell_xy(f["mid_cell"])
            geo = {"ends": seg, "width": float(f["width_cells"] * res), "anchor": f["anchor"], "mid": (mx, my)}
            if rtype[g] == int(AreaType.INTERSECTION):
                z = n_reg + len(zero_fp)
                twin = len(op_rec)
                op_rec.append({**geo, "areas": (g, z), "frontier": False})
                fo = len(op_rec)
                op_rec.append({**geo, "areas": (z, -1), "frontier": True})
                region_ops[g].append(twin)
                zero_fp.append({"host": g, "twin": twin, "front": fo, "f": f})
                front_of_op[fo] = f
            else:
                fo = len(op_rec)
                op_rec.append({**geo, "areas": (g, -1), "frontier": True})
                region_fronts[g].append((fo, f))
                front_of_op[fo] = f
        n_prov = n_reg + len(zero_fp)

        # --- path requests ----------------------------------------------------------------------
        starts: list[int] = []
        ends_: list[int] = []
        pre: list[int] = []
        post: list[int] = []
        preg: list[int] = []
        keys: list[tuple[int, int]] = []  # (provisional area, opening) per request

        def side(k: int, g: int) -> int:
            return int(side_core[k]) if int(op_core[k]) == g else int(side_far[k])

        def req(area: int, oid: int, s: int, e: int, a: int = -1, b: int = -1, reg: int | None = None) -> None:
            starts.append(s)
            ends_.append(e)
            pre.append(a)
            post.append(b)
            preg.append(area if reg is None else reg)
            keys.append((area, oid))

        sk = self.sk
        for g in range(n_reg):
            t = rtype[g]
            ops = region_ops[g]
            frs = region_fronts[g]
            root = int(centres[g])
            if t == int(AreaType.INTERSECTION):
                for k in ops:
                    rec = op_rec[k]
                    if k < n_op:
                        req(g, k, side(k, g), root, a=int(op_px[k]))
                    else:
                        req(g, k, rec["anchor"], root)
            elif t == int(AreaType.PATHWAY):
                k1, k2 = ops
                req(g, k1, side(k1, g), side(k2, g), a=int(op_px[k1]), b=int(op_px[k2]))
                req(g, k2, side(k2, g), side(k1, g), a=int(op_px[k2]), b=int(op_px[k1]))
            elif t == int(AreaType.FRONTIER_PATHWAY):
                if ops:
                    k = ops[0]
                    fo, f = frs[0]
                    req(g, k, side(k, g), f["anchor"], a=int(op_px[k]))
                    req(g, fo, f["anchor"], side(k, g), b=int(op_px[k]))
                elif len(frs) == 2:
                    (fo1, f1), (fo2, f2) = frs
                    req(g, fo1, f1["anchor"], f2["anchor"])
                    req(g, fo2, f2["anchor"], f1["anchor"])
                else:
                    fo, f = frs[0]
                    seed = _seed_of(self.parent, sk.ravel(), f["anchor"])
                    far = K.far_skeleton_pixel(W, sk, lab, seed, g) if seed >= 0 else f["anchor"]
                    req(g, fo, f["anchor"], int(far))
            elif ops:  # dead end with its opening
                k = ops[0]
                s = side(k, g)
                far = K.far_skeleton_pixel(W, sk, lab, s, g)
                req(g, k, s, int(far), a=int(op_px[k]))
        if starts:
            cells, off = K.tree_paths(self.parent, self.depth, np.array(starts, np.int64), np.array(ends_, np.int64),
                                      np.array(pre, np.int64), np.array(post, np.int64))
            max_seg = p.path_max_segment_m / res if p.path_max_segment_m > 0 else 0.0
            vcells, voff, vlen = K.smooth_paths(W, cells, off, np.array(preg, np.int64), self.cspace.ravel(), lab,
                                                self.barrier, max_seg, res)
            vr, vc = np.divmod(vcells, W)
            vx, vy = self._to_world(vr + 0.5, vc + 0.5)
            vxy = np.column_stack([vx, vy])
        else:
            voff = np.zeros(1, np.int64)
            vlen = np.zeros(0)
            vxy = np.zeros((0, 2))
        paths: dict[tuple[int, int], tuple[np.ndarray, float]] = {}
        for j, key in enumerate(keys):
            paths[key] = (vxy[voff[j] : voff[j + 1]], float(vlen[j]))
        for z in zero_fp:
            a = self._cell_xy(z["f"]["anchor"])
            pt = np.array([a, a])
            paths[(n_reg + zero_fp.index(z), z["twin"])] = (pt, 0.0)
            paths[(n_reg + zero_fp.index(z), z["front"])] = (pt, 0.0)

        # --- identities -------------------------------------------------------------------------
        centre_xy: list[tuple[float, float]] = []
        for g in range(n_reg):
            centre_xy.append(self._cell_xy(int(centres[g])) if centres[g] >= 0 else (float("nan"), float("nan")))
        for z in zero_fp:
            centre_xy.append(self._cell_xy(z["f"]["anchor"]))
        prov_type = np.concatenate([rtype, np.full(len(zero_fp), int(AreaType.FRONTIER_PATHWAY), np.int64)])
        ids, next_id = self._match_ids(n_reg, n_prov, centre_xy, prov_type)
        self._lap("paths")

        # --- objects ----------------------------------------------------------------------------
        openings: list[Opening] = []
        for k, rec in enumerate(op_rec):
            a0, a1 = rec["areas"]
            ids_pair = (int(ids[a0]), int(ids[a1]) if a1 >= 0 else -1)
            e = rec["ends"]
            if rec["frontier"] or k >= n_op:
                mid = rec["mid"]
            else:
                mid = (float((e[0, 0] + e[1, 0]) / 2.0), float((e[0, 1] + e[1, 1]) / 2.0))
            openings.append(Opening(
                id=k, endpoints_m=e, midpoint_m=mid, width_m=rec["width"], area_ids=ids_pair,
                is_frontier=bool(rec["frontier"]), anchor_m=self._cell_xy(rec["anchor"]),
            ))
        area_ops: list[list[int]] = [list(region_ops[g]) + [fo for fo, _ in region_fronts[g]] for g in range(n_reg)]
        for z in zero_fp:
            area_ops.append([z["twin"], z["front"]])
        areas: dict[int, Area] = {}
        for a in range(n_prov):
            pm = {k: paths[(a, k)][0] for k in area_ops[a] if (a, k) in paths}
            areas[int(ids[a])] = Area(
                id=int(ids[a]), type=AreaType(int(prov_type[a])), centre_m=centre_xy[a],
                opening_ids=tuple(int(k) for k in area_ops[a]), paths_m=pm,
                n_cells=int(n_cells[a]) if a < n_reg else 0,
            )

        edges: list[GraphEdge] = []
        for a in range(n_prov):
            t = prov_type[a]
            ops = area_ops[a]
            aid = int(ids[a])
            if t == int(AreaType.INTERSECTION):
                for i in range(len(ops)):
                    pa, la = paths[(a, ops[i])]
                    for j in range(i + 1, len(ops)):
                        pb, lb = paths[(a, ops[j])]
                        edges.append(GraphEdge(ops[i], ops[j], aid, la + lb, np.concatenate((pa, pb[-2::-1]))))
            elif len(ops) == 2 and (a, ops[0]) in paths:
                pa, la = paths[(a, ops[0])]
                edges.append(GraphEdge(ops[0], ops[1], aid, la, pa))

        frontiers = self._frontier_objects(op_rec, areas, ids, paths, region_fronts, zero_fp, n_reg, edges, openings)
        l_path = _mean_intersection_path(areas, openings, paths, ids)

        area_raster = np.full(self.g.shape, -1, dtype=np.int32)
        lut = np.concatenate(([-1], ids[:n_reg])).astype(np.int32)
        sub = lut[lab.reshape(self.H, self.W) + 1]
        H0, W0 = self.g.shape
        sr0, sr1 = max(self.r0, 0), min(self.r0 + self.H, H0)
        sc0, sc1 = max(self.c0, 0), min(self.c0 + self.W, W0)
        area_raster[sr0:sr1, sc0:sc1] = sub[sr0 - self.r0 : sr1 - self.r0, sc0 - self.c0 : sc1 - self.c0]
        self._lap("assemble")
        extras: dict[str, Any] = {"next_area_id": next_id, "stage_ms": self.stage_ms}
        if p.keep_debug:
            srow, scol = np.divmod(self.px, W)
            extras["skeleton_cells"] = np.column_stack([srow + self.r0, scol + self.c0])
            extras["filtered_grid_crop"] = (self.r0, self.c0, self.work.copy())
            extras["cspace_crop"] = (self.r0, self.c0, self.cspace.copy())
        return TopometricMap(
            geometry=self.g,
            area_ids=area_raster,
            areas=areas,
            openings=openings,
            frontiers=frontiers,
            edges=edges,
            mean_intersection_path_m=l_path,
            clearance_m=self.clear_m,
            time_ms=(time.perf_counter() - self.t_start) * 1000.0,
            extras=extras,
        )

    # ------------------------------------------------------------------------------------------
    def _frontier_objects(self, op_rec, areas, ids, paths, region_fronts, zero_fp, n_reg, edges, openings) -> list[Frontier]:
        """Frontier records with the nearest intersection and ``p_l`` (graph distance to it)."""
        adj: dict[int, list[tuple[int, float]]] = {}
        for e in edges:
            if areas[e.area_id].type == AreaType.INTERSECTION:
                continue
            adj.setdefault(e.opening_a, []).append((e.opening_b, e.length_m))
            adj.setdefault(e.opening_b, []).append((e.opening_a, e.length_m))

        def intersection_of(oid: int) -> int | None:
            for aid in openings[oid].area_ids:
                if aid >= 0 and areas[aid].type == AreaType.INTERSECTION:
                    return aid
            return None

        out: list[Frontier] = []
        items: list[tuple[int, int, dict]] = []  # (provisional area, frontier opening, f)
        for g in range(n_reg):
            for fo, f in region_fronts[g]:
                items.append((g, fo, f))
        for zi, z in enumerate(zero_fp):
            items.append((n_reg + zi, z["front"], z["f"]))
        for a, fo, f in items:
            # Dijkstra from the frontier until an opening on an intersection is reached
            dist = {fo: 0.0}
            heap = [(0.0, fo)]
            found: tuple[int, float] | None = None
            while heap:
                d, u = heapq.heappop(heap)
                if d > dist.get(u, math.inf):
                    continue
                iid = intersection_of(u)
                if iid is not None:
                    found = (iid, d)
                    break
                for v, w in adj.get(u, ()):
                    nd = d + w
                    if nd < dist.get(v, math.inf):
                        dist[v] = nd
                        heapq.heappush(heap, (nd, v))
            if found is not None:
                iid, p_l = found[0], found[1]
            else:
                iid = None
                p_l = paths[(a, fo)][1] if (a, fo) in paths else 0.0
            out.append(Frontier(
                area_id=int(ids[a]), opening_id=int(fo), midpoint_m=self._cell_xy(f["anchor"]),
                width_m=float(f["width_cells"] * self.res), intersection_id=iid, path_length_m=float(p_l),
            ))
        return out

    # ------------------------------------------------------------------------------------------
    def _match_ids(self, n_reg: int, n_prov: int, centre_xy, prov_type) -> tuple[np.ndarray, int]:
        """Final area ids: carried over from ``previous`` by skeleton overlap, else fresh."""
        prev = self.previous
        next_id = _next_id_of(prev)
        ids = np.full(n_prov, -1, dtype=np.int64)
        if prev is not None and prev.areas:
            used: set[int] = set()
            sel = self.px[self.lab[self.px] >= 0]
            if sel.size and n_reg:
                g_new = self.lab[sel].astype(np.int64)
                rr, cc = np.divmod(sel, self.W)
                x, y = self._to_world(rr + 0.5, cc + 0.5)
                pr, pc = prev.geometry.world_to_grid(x, y)
                inside = prev.geometry.contains(pr, pc)
                prev_id = np.full(sel.size, -1, dtype=np.int64)
                prev_id[inside] = prev.area_ids[pr[inside], pc[inside]]
                ok = prev_id >= 0
                if ok.any():
                    base = int(prev_id.max()) + 1
                    codes, counts = np.unique(g_new[ok] * base + prev_id[ok], return_counts=True)
                    for j in np.argsort(-counts, kind="stable"):
                        if counts[j] < 2:
                            break
                        g, pid = divmod(int(codes[j]), base)
                        if ids[g] >= 0 or pid in used or pid not in prev.areas:
                            continue
                        ids[g] = pid
                        used.add(pid)
            # zero-area frontier pathways: nearest previous frontier pathway without cells
            cand = [a for a in prev.areas.values() if a.type == AreaType.FRONTIER_PATHWAY and a.n_cells == 0 and a.id not in used]
            r2 = self.p.match_radius_m ** 2
            for a in range(n_reg, n_prov):
                cx, cy = centre_xy[a]
                best, bd = None, r2
                for pa in cand:
                    if pa.id in used:
                        continue
                    d2 = (pa.centre_m[0] - cx) ** 2 + (pa.centre_m[1] - cy) ** 2
                    if d2 <= bd:
                        best, bd = pa.id, d2
                if best is not None:
                    ids[a] = best
                    used.add(best)
        for a in range(n_prov):
            if ids[a] < 0:
                ids[a] = next_id
                next_id += 1
        return ids, next_id


# ----------------------------------------------------------------------------------------------
# Helpers
# ----------------------------------------------------------------------------------------------


def _geom(cells: np.ndarray, W: int) -> dict:
    """Extent of a set of cells along its principal axis: width (cells), end cells, order by centre."""
    rr, cc = np.divmod(cells, W)
    rr = rr.astype(np.float64)
    cc = cc.astype(np.float64)
    mr, mc = rr.mean(), cc.mean()
    dr, dc = rr - mr, cc - mc
    theta = 0.5 * math.atan2(2.0 * float((dr * dc).mean()), float((dc * dc).mean() - (dr * dr).mean()))
    t = dc * math.cos(theta) + dr * math.sin(theta)
    i0, i1 = int(np.argmin(t)), int(np.argmax(t))
    width = float(t[i1] - t[i0]) + 1.0
    ts = np.sort(t)
    q1v = ts[len(ts) // 4]
    q3v = ts[(3 * len(ts)) // 4]
    return {
        "width": width,
        "ends": ((rr[i0], cc[i0]), (rr[i1], cc[i1])),
        "by_centre": np.argsort(dr * dr + dc * dc, kind="stable"),
        "q1": int(np.argmin(np.abs(t - q1v))),
        "q3": int(np.argmin(np.abs(t - q3v))),
    }


def _seed_of(parent: np.ndarray, sk_flat: np.ndarray, cell: int) -> int:
    """The first skeleton pixel on the parent chain of ``cell`` (-1 if none)."""
    i = int(cell)
    for _ in range(1_000_000):
        if sk_flat[i]:
            return i
        i = int(parent[i])
        if i < 0:
            return -1
    return -1


def _mean_intersection_path(areas: dict[int, Area], openings: list[Opening], paths, ids) -> float:
    """``L_path``: mean centre-to-centre length between adjacent intersections."""
    inter = {a.id for a in areas.values() if a.type == AreaType.INTERSECTION}
    if len(inter) < 2:
        return float("nan")

    def leg(area_id: int, oid: int) -> float | None:
        pm = areas[area_id].paths_m.get(oid)
        if pm is None or len(pm) < 2:
            return 0.0 if pm is not None else None
        return float(np.hypot(*np.diff(pm, axis=0).T).sum())

    lengths: list[float] = []
    for a in areas.values():
        if a.type == AreaType.PATHWAY and len(a.opening_ids) == 2:
            o1, o2 = a.opening_ids
            i1 = [x for x in openings[o1].area_ids if x != a.id and x in inter]
            i2 = [x for x in openings[o2].area_ids if x != a.id and x in inter]
            if i1 and i2:
                mid = leg(a.id, o1)
                l1 = leg(i1[0], o1)
                l2 = leg(i2[0], o2)
                if mid is not None and l1 is not None and l2 is not None:
                    lengths.append(l1 + mid + l2)
    for o in openings:
        a0, a1 = o.area_ids
        if a0 in inter and a1 in inter and a0 != a1:
            l1, l2 = leg(a0, o.id), leg(a1, o.id)
            if l1 is not None and l2 is not None:
                lengths.append(l1 + l2)
    return float(np.mean(lengths)) if lengths else float("nan")
