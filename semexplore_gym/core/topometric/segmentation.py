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
   circle (``|E - J| + d(E) - r``) *and* has no corridor stretch (clearance within 25 % of its
   maximum ``m <= neck_ratio * r`` over ``min_dead_end_depth_m + m/2``): room corners (they
   protrude about ``0.41 r``), wall noise and shallow niches go; dead-end corridors and closets
   stay, however big the room they leave. A junction never loses all but one branch in a round
   (its longest spur waits for the next round, judged as part of the branch it continues).
   Repeated until nothing changes.
5. **Intersections and openings.** Every edge end at a junction leaves the junction's core (its
   inscribed circle times ``core_radius_ratio``). When the cores of the two junctions of an edge
   overlap along it (less than ``min_pathway_length_m`` between them), the junctions merge into
   one intersection (a room's several skeleton junctions become one). Otherwise an opening is
   placed on the edge just outside the core, slid outwards to the narrowest point
   (``2 d + opening_distance_weight * s`` minimal) and, at a mouth where the chord is longer
   than the inscribed width, moved a few pixels to the shortest chord (a door, not the room in
   front of it). The opening's segment is the shortest wall-to-wall chord through that skeleton
   point (within ``chord_search_deg`` of the normal); it is never narrower than the robot.
6. **Regions.** Openings cut the skeleton into regions (union-find over nodes and edge pieces);
   each region grows by BFS over ``C`` and then, by a row sweep and a short BFS, over the rest
   of free space within ``cover_depth_m``, never across an opening chord: a per-cell area raster
   and one shortest-path tree per region (skeleton tree from the region's centre, C-space cells
   hanging from it).
7. **Frontiers.** Labelled free cells 4-adjacent to unknown are clustered per region. A cluster
   at least ``min_frontier_width_m`` wide with at least ``min_frontier_depth_m`` of unknown behind
   it is a frontier; its target is the nearest configuration-space cell (where the robot can
   stand, ``>= clearance`` from walls and unknown space).
8. **Types** (GRID-FAST's rule, frontiers counting as openings): a region with ``>= 3`` openings
   is an intersection, 2 a pathway (a *frontier pathway* when one is a frontier), 1 a dead end
   (a *frontier pathway* when it is a frontier: a lone corridor or the robot's first scan). A
   frontier on an intersection's wall gets a zero-area frontier pathway, as in GRID-FAST.
9. **Paths and graph.** Per area, paths follow its tree (skeleton and configuration space) and
   are simplified (Douglas-Peucker, ``path_tolerance_m``) with every segment kept inside the
   area's ``C``: opening -> centre (intersections),
   opening -> opening (pathways), opening -> far end (dead ends). Graph edges join the openings
   of each area with metric lengths. ``p_l`` is the graph distance from a frontier to the nearest
   intersection; ``L_path`` the mean centre-to-centre length between adjacent intersections.
10. **Identity.** With ``previous``, areas inherit the id of the previous area their skeleton
    overlaps most (one-to-one, by position in the world frame), so ids are stable while the map
    grows; zero-area frontier pathways are matched by frontier position.

Cost is linear in the number of cells (no pairwise loops over openings): numba kernels for the
grid work, Python only to build the output records. See ``scripts/bench_segmentation.py`` for
measured times. The kernels are compiled once per machine (numba cache); a new process loads
them on its first call.
"""

from __future__ import annotations

import gc
import math
import time
from collections import deque
from itertools import repeat
from operator import setitem
from typing import Any

import numpy as np
import numpy.typing as npt

from semexplore_gym.core.grid import (
    FREE,
    OCCUPIED,
    UNKNOWN,
    GridGeometry,
    from_ros_values,
    validate_encoded_grid,
)
from semexplore_gym.core.topometric import _graph_kernels as GK
from semexplore_gym.core.topometric import _kernels as K
from semexplore_gym.core.topometric.params import SegmentationParams
from semexplore_gym.core.topometric.types import (
    Area,
    AreaType,
    Frontier,
    GraphEdge,
    Opening,
    TopometricMap,
)

_MARGIN = 2
_TYPE_OF = {int(t): t for t in AreaType}
# Records are named tuples, built straight from their field tuples: tuple.__new__ over zipped
# columns runs without a Python frame per record (thousands of records on a large map).
_tnew = tuple.__new__


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


def _as_geometry(
    geometry_or_resolution: GridGeometry | float, shape: tuple[int, int]
) -> GridGeometry:
    if isinstance(geometry_or_resolution, GridGeometry):
        g = geometry_or_resolution
        if g.shape != shape:
            raise ValueError(f"grid shape {shape} does not match geometry shape {g.shape}")
        return g
    res = geometry_or_resolution
    if isinstance(res, bool) or not isinstance(res, (int, float, np.integer, np.floating)):
        raise TypeError(
            f"geometry_or_resolution must be a GridGeometry or a resolution in metres, got {type(res).__name__}"
        )
    res = float(res)
    if not (math.isfinite(res) and res > 0):
        raise ValueError(
            f"resolution_m must be a positive finite number, got {geometry_or_resolution!r}"
        )
    return GridGeometry(res, 0.0, 0.0, shape[0], shape[1])


def _check_clearance(clearance_m: float) -> float:
    if isinstance(clearance_m, bool) or not isinstance(
        clearance_m, (int, float, np.integer, np.floating)
    ):
        raise TypeError(f"clearance_m must be a number of metres, got {type(clearance_m).__name__}")
    c = float(clearance_m)
    if not (math.isfinite(c) and c >= 0):
        raise ValueError(f"clearance_m must be a finite number >= 0, got {clearance_m!r}")
    return c


# ----------------------------------------------------------------------------------------------
# Entry point
# ----------------------------------------------------------------------------------------------


class _Scratch:
    """Grid-sized scratch arrays, kept by a :class:`TopometricSegmenter` between calls.

    Fresh arrays of a few MB cost more in page faults than the pass that fills them (a 1600^2
    map needs about 50 MB of scratch: 10-15 % of its segmentation time when freshly mapped).
    """

    def __init__(self, keep: bool) -> None:
        self.keep = keep
        self._bufs: dict[str, np.ndarray] = {}

    def take(self, name: str, n: int, dtype: type, fill: int | None = None) -> np.ndarray:
        """A 1-D array of ``n`` elements, all ``fill`` (or undefined), reused while large enough."""
        b = self._bufs.get(name)
        if b is not None and b.size >= n:
            b = b[:n]
            if fill is not None:
                b.fill(fill)
            return b
        # headroom when kept: an explored map grows a little between successive calls
        size = n + n // 4 + 1024 if self.keep else n
        # zeros come from calloc: pages nobody touches are never faulted in
        b = np.zeros(size, dtype) if fill == 0 else np.empty(size, dtype)
        if self.keep:
            self._bufs[name] = b
        b = b[:n]
        if fill:
            b.fill(fill)
        return b


class TopometricSegmenter:
    """:func:`segment_map` as an object that keeps its scratch memory between calls.

    An exploration loop segments a growing map at every update; reusing the grid-sized
    scratch arrays saves their page faults (about 10-15 % of the time on maps of 400^2 cells
    and more). The results are identical to :func:`segment_map`'s. The scratch arrays (about
    20 bytes per cell of the largest map seen) are not pickled.

    Not thread-safe: use one segmenter per thread (or per policy).

    Args:
        params: Default :class:`SegmentationParams` for calls that pass none.

    Example::

        segmenter = TopometricSegmenter()
        tmap = None
        for grid in growing_maps:
            tmap = segmenter(grid, geometry, clearance_m=0.155, previous=tmap)
    """

    def __init__(self, params: SegmentationParams | None = None) -> None:
        if params is not None and not isinstance(params, SegmentationParams):
            raise TypeError(f"params must be a SegmentationParams, got {type(params).__name__}")
        self.params = params if params is not None else SegmentationParams()
        self._scratch = _Scratch(keep=True)

    def __call__(
        self,
        grid: npt.ArrayLike,
        geometry_or_resolution: GridGeometry | float,
        clearance_m: float,
        params: SegmentationParams | None = None,
        previous: TopometricMap | None = None,
    ) -> TopometricMap:
        """Segment ``grid``; the arguments are those of :func:`segment_map`."""
        return _segment(
            grid,
            geometry_or_resolution,
            clearance_m,
            params if params is not None else self.params,
            previous,
            self._scratch,
        )

    def __getstate__(self) -> dict[str, Any]:
        return {"params": self.params}

    def __setstate__(self, state: dict[str, Any]) -> None:
        self.params = state["params"]
        self._scratch = _Scratch(keep=True)


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

    To segment many maps (an exploration loop), :class:`TopometricSegmenter` gives the same
    results faster by reusing its scratch memory.
    """
    return _segment(
        grid, geometry_or_resolution, clearance_m, params, previous, _Scratch(keep=False)
    )


def _segment(grid, geometry_or_resolution, clearance_m, params, previous, scratch) -> TopometricMap:
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
    # Thousands of small records are built at once: collector passes over them would cost more
    # than the segmentation itself on large maps, so the collector is paused for the call.
    was_enabled = gc.isenabled()
    gc.disable()
    try:
        return _Segmenter(enc, geometry, clearance, params, previous, t_start, scratch).run()
    finally:
        if was_enabled:
            gc.enable()


def _empty_map(
    geometry: GridGeometry,
    clearance: float,
    previous: TopometricMap | None,
    t_start: float,
    stage_ms: dict,
) -> TopometricMap:
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

    def __init__(self, enc, geometry, clearance, params, previous, t_start, scratch) -> None:
        self.enc = enc
        self.scratch = scratch
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
        H, W = r1 - r0, c1 - c0
        take = self.scratch.take
        work = take("work", H * W, np.uint8, UNKNOWN).reshape(H, W)
        sr0, sr1, sc0, sc1 = max(r0, 0), min(r1, H0), max(c0, 0), min(c1, W0)
        work[sr0 - r0 : sr1 - r0, sc0 - c0 : sc1 - c0] = enc[sr0:sr1, sc0:sc1]
        self.r0, self.c0 = r0, c0
        self.work = work
        self.H, self.W = H, W
        cell_area = res * res
        _, self.fcand = K.filter_small_blobs(
            work,
            int(p.max_speckle_area_m2 / cell_area + 1e-9),
            int(p.max_hole_area_m2 / cell_area + 1e-9),
            take("state", H * W, np.uint8, 0),
        )
        self._lap("filter")

        self.min_clear = self.clear_m / res - 1e-6
        dcell = take("dcell", H * W, np.float32).reshape(H, W)
        sk = take("sk", H * W, np.uint8, 0).reshape(H, W)
        c_list, n_free = K.clearance_field(
            work, self.min_clear, dcell, sk, take("ilist", H * W + 1, np.int32)
        )
        self.dcell = dcell
        self._lap("distance")
        if p.keep_debug:
            self.cspace_debug = sk.astype(bool)
        px = K.thin(
            sk, c_list, take("thin", 3 * (c_list.size + 1), np.int32)
        )  # sk: C-space mask, thinned in place to the skeleton
        self._lap("skeleton")
        if px.size == 0:
            return _empty_map(self.g, self.clear_m, self.previous, self.t_start, self.stage_ms)

        st = take("st", H * W, np.int32, -1)
        min_depth_cells = p.min_dead_end_depth_m / res
        for _ in range(max(1, int(p.max_prune_iterations))):
            graph = self._extract(sk, px, dcell, st)
            spur = K.spur_pixels(
                W,
                graph["rep"],
                graph["r"],
                graph["deg"],
                graph["noff"],
                graph["npx"],
                graph["ne"],
                graph["ea"],
                graph["eb"],
                graph["eoff"],
                graph["epx"],
                dcell,
                p.spur_ratio,
                min_depth_cells,
                p.neck_ratio,
            )
            if spur.size == 0:
                break
            px = K.remove_pixels(sk, px, spur)
        else:
            graph = self._extract(sk, px, dcell, st)
        self.sk, self.px = sk, px
        self._lap("graph")

        internal, open_a, open_b = K.place_openings(
            W,
            graph["n"],
            graph["rep"],
            graph["r"],
            graph["deg"],
            graph["ne"],
            graph["ea"],
            graph["eb"],
            graph["eoff"],
            graph["epx"],
            dcell,
            work,
            p.core_radius_ratio,
            p.opening_distance_weight,
            max(2, int(round(p.min_pathway_length_m / res))),
            math.radians(p.chord_search_deg),
        )
        lab = take("lab", H * W, np.int32, -1)
        n_reg, _node_reg, _mid_reg, op_px, op_edge, op_idx, op_core, op_far = K.build_regions(
            graph["n"],
            graph["alive"],
            graph["noff"],
            graph["npx"],
            graph["ne"],
            graph["ea"],
            graph["eb"],
            graph["eoff"],
            graph["epx"],
            internal,
            open_a,
            open_b,
            lab,
        )
        ends, widths, chord_cells = K.opening_chords(
            work,
            dcell,
            op_px,
            op_edge,
            op_idx,
            graph["eoff"],
            graph["epx"],
            lab,
            3,
            math.radians(p.chord_search_deg),
        )
        self._lap("openings")

        centres = K.region_centres(px, lab, dcell, n_reg, W)
        cover_m = p.cover_depth_m if p.cover_depth_m is not None else 2.0 * self.clear_m + 2.0 * res
        sk_par, sk_dep, counts = K.grow_regions(
            W,
            sk,
            px,
            st,
            centres,
            lab,
            dcell,
            self.min_clear,
            work,
            int(math.ceil(cover_m / res - 1e-9)),
            chord_cells,
            op_core,
            n_reg,
            n_free,
            take("ilist", n_free + 1, np.int32),  # the C-space list is no longer needed
        )
        self.lab, self.st, self.sk_par, self.sk_dep = lab, st, sk_par, sk_dep
        self._lap("regions")

        self.n_reg = n_reg
        fronts = self._frontiers()
        self._lap("frontiers")

        side_core, side_far = GK.opening_sides(
            op_edge,
            op_idx,
            open_a,
            graph["eoff"],
            graph["epx"],
            graph["ea"],
            graph["eb"],
            graph["rep"],
        )
        return self._assemble(
            n_reg,
            centres,
            counts,
            op_px,
            op_core,
            op_far,
            ends,
            widths,
            side_core,
            side_far,
            fronts,
        )

    # ------------------------------------------------------------------------------------------
    def _extract(self, sk, px, dcell, st) -> dict[str, Any]:
        names = ("n", "rep", "r", "deg", "noff", "npx", "ne", "ea", "eb", "eoff", "epx", "alive")
        return dict(zip(names, K.skeleton_graph(sk, px, dcell, st), strict=True))

    # ------------------------------------------------------------------------------------------
    def _frontiers(self) -> dict[str, np.ndarray]:
        """Valid frontiers as arrays: region, width (cells), end cells, middle cell, target cell."""
        p = self.p
        res = self.res
        fc, cluster, orow, ocol, n_cl = K.frontier_cells(self.W, self.work, self.lab, self.fcand)
        min_w_cells = (
            p.min_frontier_width_m if p.min_frontier_width_m is not None else 2.0 * self.clear_m
        ) / res
        depth_cells = (
            p.min_frontier_depth_m if p.min_frontier_depth_m is not None else 2.0 * self.clear_m
        ) / res
        reg, wid, ends, mid, anchor = K.frontier_groups(
            self.W,
            self.work,
            self.lab,
            self.st,
            self.sk,
            self.dcell,
            self.min_clear,
            fc,
            cluster,
            orow,
            ocol,
            n_cl,
            float(min_w_cells),
            float(depth_cells),
            int(self.n_reg),
        )
        return {"region": reg, "width": wid, "ends": ends, "mid": mid, "anchor": anchor}

    # ------------------------------------------------------------------------------------------
    def _xy(self, rows, cols) -> np.ndarray:
        """Fractional work-grid (row, col) (cell centres at +0.5) to world (x, y) metres, (n, 2)."""
        g = self.g
        cols = np.asarray(cols, dtype=np.float64).ravel()
        rows = np.asarray(rows, dtype=np.float64).ravel()
        # filled in place: column_stack's generic concatenation costs more than the arithmetic
        out = np.empty((max(cols.size, rows.size), 2))
        out[:, 0] = g.origin_x_m + (cols + self.c0) * g.resolution_m
        out[:, 1] = g.origin_y_m + (rows + self.r0) * g.resolution_m
        return out

    def _cells_xy(self, cells) -> np.ndarray:
        r, c = np.divmod(np.asarray(cells, dtype=np.int64), self.W)
        return self._xy(r + 0.5, c + 0.5)

    def _assemble(
        self, n_reg, centres, counts, op_px, op_core, op_far, ends, widths, side_core, side_far, fr
    ) -> TopometricMap:
        p = self.p
        res = self.res
        W = self.W
        lab = self.lab
        n_op = int(op_px.size)
        front = int(AreaType.FRONTIER_PATHWAY)

        # --- types, openings and path requests (provisional indices, see _graph_kernels) -------
        rtype = GK.area_types(n_reg, op_core, op_far, fr["region"])
        op_a0, op_a1, op_front, op_anchor, aoff, aops, zf_twin, zf_fo, req = GK.plan_paths(
            rtype,
            op_core,
            op_far,
            fr["region"],
            centres,
            side_core,
            side_far,
            op_px,
            fr["anchor"],
            W,
            self.sk,
            self.px,
            self.st,
            lab,
        )
        n_zf = int(zf_fo.size)
        n_prov = n_reg + n_zf
        n_all = int(op_a0.size)
        n_req = int(req.shape[1])
        if n_req:
            cells, off = K.tree_paths(
                self.sk, self.px, self.st, self.sk_par, self.sk_dep, req[2], req[3], req[4], req[5]
            )
            vcells, voff, vlen = K.smooth_paths(
                W,
                cells,
                off,
                req[0],
                self.dcell,
                self.min_clear,
                lab,
                max(p.path_tolerance_m / res, 0.0),
                res,
            )
        else:
            vcells = np.zeros(0, np.int64)
            voff = np.zeros(1, np.int64)
            vlen = np.zeros(0)

        g = self.g
        vxy, anchor_xy, centre_xy, ends_xy, mids, widths_m = GK.world_coordinates(
            vcells,
            op_anchor,
            centres,
            zf_fo,
            fr["mid"],
            op_front[n_op:],
            ends,
            fr["ends"],
            widths,
            fr["width"],
            W,
            self.r0,
            self.c0,
            g.origin_x_m,
            g.origin_y_m,
            g.resolution_m,
        )
        voff_l = voff.tolist()
        pieces = list(map(vxy.__getitem__, map(slice, voff_l[:n_req], voff_l[1 : n_req + 1])))
        area_paths: list[dict[int, np.ndarray]] = [{} for _ in range(n_prov)]
        # area_paths[a][k] = piece for every request, in request order, without a Python loop
        deque(
            map(setitem, map(area_paths.__getitem__, req[0].tolist()), req[1].tolist(), pieces),
            maxlen=0,
        )

        for z, (twin, fo) in enumerate(zip(zf_twin.tolist(), zf_fo.tolist(), strict=True)):
            pt = np.repeat(anchor_xy[fo : fo + 1], 2, axis=0)
            area_paths[n_reg + z] = {twin: pt, fo: pt}

        # --- identities -------------------------------------------------------------------------
        prov_type = np.concatenate([rtype, np.full(n_zf, front, np.int64)])
        ids, next_id = self._match_ids(n_reg, n_prov, centre_xy, prov_type)
        ids_l = ids.tolist()
        edges2, pairs, plen, fronts, fronts_len, lpath = GK.graph_summary(
            prov_type, aoff, aops, op_a0, op_a1, req, vlen, zf_twin, zf_fo, n_reg
        )
        self._lap("paths")

        # --- records ----------------------------------------------------------------------------
        side_b = np.where(op_a1 >= 0, ids[op_a1], -1) if n_all else op_a1
        openings: list[Opening] = list(
            map(
                _tnew,
                repeat(Opening),
                zip(
                    range(n_all),
                    list(ends_xy),
                    map(tuple, mids.tolist()),
                    widths_m.tolist(),
                    zip(ids[op_a0].tolist(), side_b.tolist(), strict=True),
                    (op_a1 < 0).tolist(),
                    map(tuple, anchor_xy.tolist()),
                    strict=True,
                ),
            )
        )
        aops_l = aops.tolist()
        aoff_l = aoff.tolist()
        area_ids = ids_l[:n_prov]
        area_recs = map(
            _tnew,
            repeat(Area),
            zip(
                area_ids,
                map(_TYPE_OF.__getitem__, prov_type.tolist()),
                map(tuple, centre_xy.tolist()),
                map(tuple, map(aops_l.__getitem__, map(slice, aoff_l[:n_prov], aoff_l[1:]))),
                area_paths,
                counts.tolist()[:n_reg] + [0] * n_zf,
                strict=True,
            ),
        )
        areas: dict[int, Area] = dict(zip(area_ids, area_recs, strict=True))

        # graph edges: areas with two openings, then every pair of an intersection's legs
        vlen_l = vlen.tolist()
        edges: list[GraphEdge] = [
            _tnew(GraphEdge, (o1, o2, ids_l[a], vlen_l[j], pieces[j]))
            if j >= 0
            else _tnew(GraphEdge, (o1, o2, ids_l[a], 0.0, area_paths[a][o1]))
            for o1, o2, a, j in edges2.tolist()
        ]
        if pairs.shape[1]:
            jxy, joff = K.join_legs(vxy, voff, pairs[0], pairs[1])
            joff_l = joff.tolist()
            n_pair = int(pairs.shape[1])
            jpieces = map(jxy.__getitem__, map(slice, joff_l[:n_pair], joff_l[1 : n_pair + 1]))
            edges.extend(
                map(
                    _tnew,
                    repeat(GraphEdge),
                    zip(
                        pairs[2].tolist(),
                        pairs[3].tolist(),
                        map(ids_l.__getitem__, pairs[4].tolist()),
                        plen.tolist(),
                        jpieces,
                        strict=True,
                    ),
                )
            )

        frontiers = [
            Frontier(
                ids_l[a],
                fo,
                openings[fo].anchor_m,
                openings[fo].width_m,
                ids_l[hit] if hit >= 0 else None,
                p_l,
            )
            for (a, fo, hit), p_l in zip(fronts.tolist(), fronts_len.tolist(), strict=True)
        ]
        n_inter = int(np.count_nonzero(prov_type == int(AreaType.INTERSECTION)))
        l_path = float(np.mean(lpath)) if n_inter >= 2 and lpath.size else float("nan")

        # --- raster -----------------------------------------------------------------------------
        area_raster = np.empty(self.g.shape, dtype=np.int32)
        K.scatter_labels(area_raster, lab, ids[:n_reg].astype(np.int32), W, self.r0, self.c0)
        self._lap("assemble")
        extras: dict[str, Any] = {"next_area_id": next_id, "stage_ms": self.stage_ms}
        if p.keep_debug:
            srow, scol = np.divmod(self.px, W)
            extras["skeleton_cells"] = np.column_stack([srow + self.r0, scol + self.c0])
            extras["filtered_grid_crop"] = (self.r0, self.c0, self.work.copy())
            extras["cspace_crop"] = (self.r0, self.c0, self.cspace_debug)
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
    def _match_ids(self, n_reg: int, n_prov: int, centre_xy, prov_type) -> tuple[np.ndarray, int]:
        """Final area ids: carried over from ``previous`` by skeleton overlap, else fresh."""
        prev = self.previous
        next_id = _next_id_of(prev)
        if prev is None:
            return np.arange(next_id, next_id + n_prov, dtype=np.int64), next_id + n_prov
        ids = np.full(n_prov, -1, dtype=np.int64)
        if prev is not None and prev.areas:
            used: set[int] = set()
            sel = self.px[self.lab[self.px] >= 0]
            if sel.size and n_reg:
                g_new = self.lab[sel].astype(np.int64)
                xy = self._cells_xy(sel)
                pr, pc = prev.geometry.world_to_grid(xy[:, 0], xy[:, 1])
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
            cand = [
                a
                for a in prev.areas.values()
                if a.type == AreaType.FRONTIER_PATHWAY and a.n_cells == 0 and a.id not in used
            ]
            r2 = self.p.match_radius_m**2
            for a in range(n_reg, n_prov):
                cx, cy = float(centre_xy[a, 0]), float(centre_xy[a, 1])
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
        fresh = np.flatnonzero(ids < 0)
        ids[fresh] = next_id + np.arange(fresh.size)
        return ids, next_id + int(fresh.size)
