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

Where each stage lives
----------------------
``stages.SegmentationStages.run`` calls one method per stage, in order. The numba kernels are
in the package :mod:`.kernels`, one module per stage (paths relative to ``core/topometric/``):

=============================  ===========================================  =========================
Stage                          Module                                       ``SegmentationStages``
                                                                            method
=============================  ===========================================  =========================
1. Crop and clean              ``kernels/clean.py``                         ``_crop``, ``_clean``
2. Configuration space         ``kernels/cspace.py``                        ``_configuration_space``
3. Skeleton                    ``kernels/skeleton.py`` (thinning),          ``_skeleton``
                               ``kernels/skeleton_graph.py`` (graph)
4. Pruning                     ``kernels/prune.py``                         ``_prune``
5. Intersections and openings  ``kernels/openings.py``                      ``_openings``
6. Regions                     ``kernels/regions.py`` (the cut at the       ``_regions``
                               openings runs in ``_openings``)
7. Frontiers                   ``kernels/frontiers.py``                     ``_frontiers``
8. Types                       ``kernels/graph.py`` (``area_types``)        ``_types``
9. Paths and graph             ``kernels/paths.py``, ``kernels/graph.py``,  ``_paths``, ``_assemble``
                               records: ``map_records.py``
10. Identity                   ``area_identity.py``                         ``_identities``
=============================  ===========================================  =========================

This module holds the entry points and the input checks; ``scratch.py`` the scratch arrays
a :class:`TopometricSegmenter` keeps between calls.

Cost is linear in the number of cells (no pairwise loops over openings): numba kernels for the
grid work, Python only to build the output records. See ``scripts/bench_segmentation.py`` for
measured times. The kernels are compiled once per machine (numba cache); a new process loads
them on its first call.
"""

from __future__ import annotations

import gc
import math
import time
from typing import Any

import numpy as np
import numpy.typing as npt

from semexplore_gym.core.grid import FREE, OCCUPIED, UNKNOWN, GridGeometry, from_ros_values
from semexplore_gym.core.topometric.params import SegmentationParams
from semexplore_gym.core.topometric.scratch import ScratchArrays
from semexplore_gym.core.topometric.stages import SegmentationStages
from semexplore_gym.core.topometric.types import TopometricMap

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
        self._scratch = ScratchArrays(keep=True)

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
        self._scratch = ScratchArrays(keep=True)


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
        grid, geometry_or_resolution, clearance_m, params, previous, ScratchArrays(keep=False)
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
        return SegmentationStages(
            enc, geometry, clearance, params, previous, t_start, scratch
        ).run()
    finally:
        if was_enabled:
            gc.enable()
