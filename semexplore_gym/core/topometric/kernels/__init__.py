"""Numba kernels of the topometric segmentation, one module per stage of
:mod:`semexplore_gym.core.topometric.segmentation` (single-threaded, ``@njit(cache=True)``).

======================  =================================================================
Stage                   Module
======================  =================================================================
1. Crop and clean       :mod:`.clean`
2. Configuration space  :mod:`.cspace`
3. Skeleton             :mod:`.skeleton` (thinning), :mod:`.skeleton_graph` (pixel graph)
4. Pruning              :mod:`.prune`
5. Openings             :mod:`.openings`
6. Regions              :mod:`.regions`
7. Frontiers            :mod:`.frontiers`
8. Types                :mod:`.graph` (:func:`~.graph.area_types`)
9. Paths and graph      :mod:`.paths` (cell paths), :mod:`.graph` (requests, edges, ``L_path``)
======================  =================================================================

Stage 10 (identity) is plain Python (:mod:`..area_identity`); :mod:`..stages` calls the
stages.

All grid kernels work on a *work grid*: a crop of the input grid whose free cells are at least
two cells away from its edge, so neighbour look-ups of free cells never leave the array. Cells
are addressed by flat index ``i = row * W + col``. Distances are in cells.

A kernel that calls a kernel of another module imports it by name (numba resolves jitted
globals when it compiles the caller). Numba's cache only notices edits to the caller's own
file: after editing a kernel that other modules call (:func:`.skeleton.m_degree`,
:func:`.skeleton.zhang_suen_tables`, :func:`.skeleton.reduce_blobs`,
:func:`.paths.far_skeleton_pixels`), delete this package's ``__pycache__`` so that its callers
are recompiled too.
"""
