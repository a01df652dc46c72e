"""The stages of :func:`~semexplore_gym.core.topometric.segmentation.segment_map`, in order.

:meth:`SegmentationStages.run` calls one method per stage of the algorithm described in
:mod:`semexplore_gym.core.topometric.segmentation`; each method hands the crop's arrays to the
numba kernels of that stage (:mod:`.kernels`) and keeps what later stages need. The output
records are built by :mod:`.map_records`, the area ids by :mod:`.area_identity`.
"""

from __future__ import annotations

import math
import time
from typing import Any, cast

import numpy as np

from semexplore_gym.core.grid import UNKNOWN, GridGeometry, validate_encoded_grid
from semexplore_gym.core.topometric.area_identity import match_area_ids, next_area_id
from semexplore_gym.core.topometric.kernels.clean import filter_small_blobs, scan_grid
from semexplore_gym.core.topometric.kernels.cspace import clearance_field
from semexplore_gym.core.topometric.kernels.frontiers import frontier_cells, frontier_groups
from semexplore_gym.core.topometric.kernels.graph import (
    area_types,
    graph_summary,
    opening_sides,
    plan_paths,
    world_coordinates,
)
from semexplore_gym.core.topometric.kernels.openings import opening_chords, place_openings
from semexplore_gym.core.topometric.kernels.paths import smooth_paths, tree_paths
from semexplore_gym.core.topometric.kernels.prune import remove_pixels, spur_pixels
from semexplore_gym.core.topometric.kernels.regions import (
    build_regions,
    grow_regions,
    region_centres,
    window_labels,
)
from semexplore_gym.core.topometric.kernels.skeleton import thin
from semexplore_gym.core.topometric.kernels.skeleton_graph import skeleton_graph
from semexplore_gym.core.topometric.map_records import (
    area_records,
    edge_records,
    frontier_records,
    opening_records,
    world_paths,
)
from semexplore_gym.core.topometric.params import SegmentationParams
from semexplore_gym.core.topometric.scratch import ScratchArrays
from semexplore_gym.core.topometric.types import AreaRasterCrop, AreaType, TopometricMap

_MARGIN = 2
_GRAPH_FIELDS = ("n", "rep", "r", "deg", "noff", "npx", "ne", "ea", "eb", "eoff", "epx", "alive")


def empty_map(
    geometry: GridGeometry,
    clearance: float,
    previous: TopometricMap | None,
    t_start: float,
    stage_ms: dict,
) -> TopometricMap:
    """The map of a grid without free space (or without configuration space)."""
    next_id = next_area_id(previous)
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


class SegmentationStages:
    """One segmentation run (internal; holds the intermediate arrays of the crop).

    Arrays of the crop (the *work grid*, ``H x W``, flat index ``row * W + col``) kept between
    stages: ``work`` (filtered encoding), ``dcell`` (clearance, cells), ``sk`` (C-space mask,
    then skeleton), ``px`` (skeleton pixels), ``st`` (per-cell skeleton / tree index), ``lab``
    (region per cell), ``sk_par`` and ``sk_dep`` (the regions' shortest-path trees).
    """

    def __init__(
        self,
        enc: np.ndarray,
        geometry: GridGeometry,
        clearance: float,
        params: SegmentationParams,
        previous: TopometricMap | None,
        t_start: float,
        scratch: ScratchArrays,
    ) -> None:
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

    def _empty(self) -> TopometricMap:
        return empty_map(self.g, self.clear_m, self.previous, self.t_start, self.stage_ms)

    # ------------------------------------------------------------------------------------------
    def run(self) -> TopometricMap:
        """Stages 1-10 of the algorithm (numbered as in the segmentation module's docstring)."""
        if not self._crop():  # 1
            return self._empty()
        self._clean()  # 1
        self._configuration_space()  # 2
        if not self._skeleton():  # 3
            return self._empty()
        graph = self._prune()  # 4
        ops = self._openings(graph)  # 5 (and the cut of stage 6)
        centres, counts = self._regions(ops)  # 6
        fronts = self._frontiers()  # 7
        return self._assemble(graph, ops, centres, counts, fronts)  # 8-10

    # --- 1. crop and clean ------------------------------------------------------------------------
    def _crop(self) -> bool:
        """Copy the free cells' bounding box (plus a margin) into ``work``; False if none."""
        enc = np.ascontiguousarray(self.enc)
        H0, W0 = enc.shape
        bad, rmin, rmax, cmin, cmax = scan_grid(enc)
        if bad >= 0:
            validate_encoded_grid(enc)  # raises with the offending value and position
        if rmin < 0:
            self._lap("prepare")
            return False
        r0, r1 = rmin - _MARGIN, rmax + _MARGIN + 1
        c0, c1 = cmin - _MARGIN, cmax + _MARGIN + 1
        H, W = r1 - r0, c1 - c0
        work = self.scratch.take("work", H * W, np.uint8, UNKNOWN).reshape(H, W)
        sr0, sr1, sc0, sc1 = max(r0, 0), min(r1, H0), max(c0, 0), min(c1, W0)
        work[sr0 - r0 : sr1 - r0, sc0 - c0 : sc1 - c0] = enc[sr0:sr1, sc0:sc1]
        self.r0, self.c0 = r0, c0
        self.work = work
        self.H, self.W = H, W
        return True

    def _clean(self) -> None:
        """Erase small specks, close small holes; keep the frontier candidate cells."""
        p = self.p
        H, W = self.H, self.W
        cell_area = self.res * self.res
        _, self.fcand = filter_small_blobs(
            self.work,
            int(p.max_speckle_area_m2 / cell_area + 1e-9),
            int(p.max_hole_area_m2 / cell_area + 1e-9),
            self.scratch.take("state", H * W, np.uint8, 0),
        )
        self._lap("filter")

    # --- 2. configuration space -------------------------------------------------------------------
    def _configuration_space(self) -> None:
        """Clearance of every cell (``dcell``) and the C-space mask (in ``sk``) and list."""
        take = self.scratch.take
        H, W = self.H, self.W
        self.min_clear = self.clear_m / self.res - 1e-6
        dcell = take("dcell", H * W, np.float32).reshape(H, W)
        sk = take("sk", H * W, np.uint8, 0).reshape(H, W)
        self.c_list, self.n_free = clearance_field(
            self.work, self.min_clear, dcell, sk, take("ilist", H * W + 1, np.int32)
        )
        self.dcell, self.sk = dcell, sk
        self._lap("distance")

    # --- 3. skeleton ------------------------------------------------------------------------------
    def _skeleton(self) -> bool:
        """Thin the C-space mask ``sk`` in place to the skeleton ``px``; False if it is empty."""
        if self.p.keep_debug:
            self.cspace_debug = self.sk.astype(bool)
        c_list = self.c_list
        self.px = thin(self.sk, c_list, self.scratch.take("thin", 3 * (c_list.size + 1), np.int32))
        self._lap("skeleton")
        return self.px.size > 0

    def _graph(self) -> dict[str, Any]:
        """The skeleton read as a graph (nodes, edges, pixel chains), by field name."""
        fields = skeleton_graph(self.sk, self.px, self.dcell, self.st)
        return dict(zip(_GRAPH_FIELDS, fields, strict=True))

    # --- 4. pruning -------------------------------------------------------------------------------
    def _prune(self) -> dict[str, Any]:
        """Remove spurs round after round; the graph of the final skeleton."""
        p = self.p
        sk, dcell = self.sk, self.dcell
        self.st = self.scratch.take("st", self.H * self.W, np.int32, -1)
        min_depth_cells = p.min_dead_end_depth_m / self.res
        for _ in range(max(1, int(p.max_prune_iterations))):
            graph = self._graph()
            spur = spur_pixels(
                self.W,
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
            self.px = remove_pixels(sk, self.px, spur)
        else:
            graph = self._graph()
        self._lap("graph")
        return graph

    # --- 5. intersections and openings ------------------------------------------------------------
    def _openings(self, graph: dict[str, Any]) -> dict[str, np.ndarray]:
        """Openings on the skeleton edges, the regions they cut (``lab``) and their chords."""
        p = self.p
        W = self.W
        chord_rad = math.radians(p.chord_search_deg)
        internal, open_a, open_b = place_openings(
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
            self.dcell,
            self.work,
            p.core_radius_ratio,
            p.opening_distance_weight,
            max(2, int(round(p.min_pathway_length_m / self.res))),
            chord_rad,
        )
        self.lab = self.scratch.take("lab", self.H * W, np.int32, -1)
        # stage 6's cut: the chords below need every skeleton pixel's region
        n_reg, _node_reg, _mid_reg, op_px, op_edge, op_idx, op_core, op_far = build_regions(
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
            self.lab,
        )
        self.n_reg = n_reg
        ends, widths, chord_cells = opening_chords(
            self.work,
            self.dcell,
            op_px,
            op_edge,
            op_idx,
            graph["eoff"],
            graph["epx"],
            self.lab,
            3,
            chord_rad,
        )
        self._lap("openings")
        return {
            "open_a": open_a,
            "px": op_px,
            "edge": op_edge,
            "idx": op_idx,
            "core": op_core,
            "far": op_far,
            "ends": ends,
            "widths": widths,
            "chord_cells": chord_cells,
        }

    # --- 6. regions -------------------------------------------------------------------------------
    def _regions(self, ops: dict[str, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
        """Grow the regions over free space; their centres and cell counts."""
        p = self.p
        res = self.res
        centres = region_centres(self.px, self.lab, self.dcell, self.n_reg, self.W)
        cover_m = p.cover_depth_m if p.cover_depth_m is not None else 2.0 * self.clear_m + 2.0 * res
        self.sk_par, self.sk_dep, counts = grow_regions(
            self.W,
            self.sk,
            self.px,
            self.st,
            centres,
            self.lab,
            self.dcell,
            self.min_clear,
            self.work,
            int(math.ceil(cover_m / res - 1e-9)),
            ops["chord_cells"],
            ops["core"],
            self.n_reg,
            self.n_free,
            # the C-space list is no longer needed
            self.scratch.take("ilist", self.n_free + 1, np.int32),
        )
        self._lap("regions")
        return centres, counts

    # --- 7. frontiers -----------------------------------------------------------------------------
    def _frontiers(self) -> dict[str, np.ndarray]:
        """Valid frontiers as arrays: region, width (cells), end cells, middle cell, target cell."""
        p = self.p
        res = self.res
        fc, cluster, orow, ocol, n_cl = frontier_cells(self.W, self.work, self.lab, self.fcand)
        min_w_cells = (
            p.min_frontier_width_m if p.min_frontier_width_m is not None else 2.0 * self.clear_m
        ) / res
        depth_cells = (
            p.min_frontier_depth_m if p.min_frontier_depth_m is not None else 2.0 * self.clear_m
        ) / res
        reg, wid, ends, mid, anchor = frontier_groups(
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
        self._lap("frontiers")
        return {"region": reg, "width": wid, "ends": ends, "mid": mid, "anchor": anchor}

    # --- 8-10. types, paths and graph, identity; the output records -------------------------------
    def _assemble(self, graph, ops, centres, counts, fr) -> TopometricMap:
        """Area types, paths, graph edges and ids (stages 8-10) as a :class:`TopometricMap`."""
        rtype, plan = self._types(graph, ops, centres, fr)  # 8. types, and stage 9's requests
        op_a0, op_a1, op_front, op_anchor, aoff, aops, zf_twin, zf_fo, req = plan
        vcells, voff, vlen = self._paths(req)  # 9. paths
        vxy, anchor_xy, centre_xy, ends_xy, mids, widths_m = self._world_coordinates(
            vcells, op_anchor, centres, zf_fo, op_front, ops, fr
        )
        n_reg = self.n_reg
        n_zf = int(zf_fo.size)
        n_prov = n_reg + n_zf
        paths = world_paths(vxy, voff, vlen, req, zf_twin, zf_fo, anchor_xy, n_reg)
        prov_type = np.concatenate([rtype, np.full(n_zf, int(AreaType.FRONTIER_PATHWAY), np.int64)])
        ids, next_id = self._identities(n_prov, centre_xy)  # 10. identity
        ids_l = ids.tolist()
        edges2, pairs, plen, fronts, fronts_len, lpath = graph_summary(
            prov_type, aoff, aops, op_a0, op_a1, req, vlen, zf_twin, zf_fo, n_reg
        )
        self._lap("paths")

        openings = opening_records(ids, op_a0, op_a1, ends_xy, mids, widths_m, anchor_xy)
        areas = area_records(ids_l[:n_prov], prov_type, centre_xy, aoff, aops, paths, counts, n_reg)
        edges = edge_records(edges2, pairs, plen, ids_l, paths)
        frontiers = frontier_records(fronts, fronts_len, ids_l, openings)
        n_inter = int(np.count_nonzero(prov_type == int(AreaType.INTERSECTION)))
        l_path = float(np.mean(lpath)) if n_inter >= 2 and lpath.size else float("nan")
        area_raster = self._area_raster(ids)
        self._lap("assemble")
        extras = self._extras(next_id)
        return TopometricMap(
            geometry=self.g,
            area_ids=cast(np.ndarray, area_raster),  # the field accepts the window too
            areas=areas,
            openings=openings,
            frontiers=frontiers,
            edges=edges,
            mean_intersection_path_m=l_path,
            clearance_m=self.clear_m,
            time_ms=(time.perf_counter() - self.t_start) * 1000.0,
            extras=extras,
        )

    def _types(self, graph, ops, centres, fr) -> tuple[np.ndarray, tuple[np.ndarray, ...]]:
        """Stage 8's region types, and stage 9's path requests (provisional indices, see
        :mod:`.kernels.graph`)."""
        side_core, side_far = opening_sides(
            ops["edge"],
            ops["idx"],
            ops["open_a"],
            graph["eoff"],
            graph["epx"],
            graph["ea"],
            graph["eb"],
            graph["rep"],
        )
        rtype = area_types(self.n_reg, ops["core"], ops["far"], fr["region"])
        plan = plan_paths(
            rtype,
            ops["core"],
            ops["far"],
            fr["region"],
            centres,
            side_core,
            side_far,
            ops["px"],
            fr["anchor"],
            self.W,
            self.sk,
            self.px,
            self.st,
            self.lab,
        )
        return rtype, plan

    def _world_coordinates(
        self, vcells, op_anchor, centres, zf_fo, op_front, ops, fr
    ) -> tuple[np.ndarray, ...]:
        """Paths, anchors, centres, opening ends and middles (world metres) and widths (m)."""
        g = self.g
        return world_coordinates(
            vcells,
            op_anchor,
            centres,
            zf_fo,
            fr["mid"],
            op_front[ops["px"].size :],
            ops["ends"],
            fr["ends"],
            ops["widths"],
            fr["width"],
            self.W,
            self.r0,
            self.c0,
            g.origin_x_m,
            g.origin_y_m,
            g.resolution_m,
        )

    def _area_raster(self, ids: np.ndarray) -> AreaRasterCrop:
        """The area ids of the work grid's window; the full raster is built if someone reads it."""
        H0, W0 = self.g.shape
        ra, rb = max(0, -self.r0), min(self.H, H0 - self.r0)
        ca, cb = max(0, -self.c0), min(self.W, W0 - self.c0)
        window = window_labels(self.lab, ids[: self.n_reg].astype(np.int32), self.W, ra, rb, ca, cb)
        return AreaRasterCrop(self.g.shape, self.r0 + ra, self.c0 + ca, window)

    def _paths(self, req: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Stage 9's cell paths for the requests, simplified: cells, offsets, lengths (m)."""
        if not req.shape[1]:
            return np.zeros(0, np.int64), np.zeros(1, np.int64), np.zeros(0)
        cells, off = tree_paths(
            self.sk, self.px, self.st, self.sk_par, self.sk_dep, req[2], req[3], req[4], req[5]
        )
        return smooth_paths(
            self.W,
            cells,
            off,
            req[0],
            self.dcell,
            self.min_clear,
            self.lab,
            max(self.p.path_tolerance_m / self.res, 0.0),
            self.res,
        )

    def _identities(self, n_prov: int, centre_xy: np.ndarray) -> tuple[np.ndarray, int]:
        """Final area ids (stage 10): carried over from ``previous`` by skeleton overlap."""
        prev = self.previous
        sk_region = np.zeros(0, np.int64)
        sk_xy = np.zeros((0, 2))
        sk_cells = None
        if prev is not None and prev.areas and self.n_reg:
            sel = self.px[self.lab[self.px] >= 0]
            if sel.size:
                sk_region = self.lab[sel].astype(np.int64)
                if self._same_frame(prev.geometry):
                    # the cell centres' world points fall in the same cells of the same grid
                    r, c = np.divmod(np.asarray(sel, dtype=np.int64), self.W)
                    sk_cells = (r + self.r0, c + self.c0)
                else:
                    sk_xy = self._cells_xy(sel)
        return match_area_ids(
            prev,
            self.n_reg,
            n_prov,
            centre_xy,
            sk_region,
            sk_xy,
            self.p.match_radius_m,
            skeleton_cells=sk_cells,
        )

    def _same_frame(self, other: GridGeometry) -> bool:
        """``other`` is this grid's frame, with coordinates small enough (< 2^40 cells from the
        world origin) that a cell centre's world point maps back to its own cell exactly."""
        g = self.g
        if other != g:
            return False
        extent = (abs(g.origin_x_m) + abs(g.origin_y_m)) / g.resolution_m + g.height + g.width
        return extent < 2.0**40

    def _cells_xy(self, cells: np.ndarray) -> np.ndarray:
        """Work-grid flat cell indices to world (x, y) metres of the cell centres, (n, 2)."""
        g = self.g
        r, c = np.divmod(np.asarray(cells, dtype=np.int64), self.W)
        cols = np.asarray(c + 0.5, dtype=np.float64).ravel()
        rows = np.asarray(r + 0.5, dtype=np.float64).ravel()
        # filled in place: column_stack's generic concatenation costs more than the arithmetic
        out = np.empty((max(cols.size, rows.size), 2))
        out[:, 0] = g.origin_x_m + (cols + self.c0) * g.resolution_m
        out[:, 1] = g.origin_y_m + (rows + self.r0) * g.resolution_m
        return out

    def _extras(self, next_id: int) -> dict[str, Any]:
        extras: dict[str, Any] = {"next_area_id": next_id, "stage_ms": self.stage_ms}
        if self.p.keep_debug:
            srow, scol = np.divmod(self.px, self.W)
            extras["skeleton_cells"] = np.column_stack([srow + self.r0, scol + self.c0])
            extras["filtered_grid_crop"] = (self.r0, self.c0, self.work.copy())
            extras["cspace_crop"] = (self.r0, self.c0, self.cspace_debug)
        return extras
