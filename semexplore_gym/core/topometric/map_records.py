"""The output records of a segmentation (stage 9's areas, openings, edges and frontiers).

The kernels of :mod:`.kernels.graph` return columns of numbers with *provisional* area indices;
these functions turn them into :class:`~.types.Opening`, :class:`~.types.Area`,
:class:`~.types.GraphEdge` and :class:`~.types.Frontier` records under the final area ids.
Records are named tuples, built straight from their field tuples: ``tuple.__new__`` over
zipped columns runs without a Python frame per record (thousands of records on a large map).
"""

from __future__ import annotations

from collections import deque
from itertools import repeat
from operator import setitem
from typing import NamedTuple

import numpy as np

from semexplore_gym.core.topometric.kernels.paths import join_legs
from semexplore_gym.core.topometric.types import Area, AreaType, Frontier, GraphEdge, Opening

_TYPE_OF = {int(t): t for t in AreaType}
_tnew = tuple.__new__


class WorldPaths(NamedTuple):
    """Stage 9's simplified paths in world metres, as columns and per area.

    Attributes:
        xy: ``(n, 2)`` points of every path, one after another.
        offsets: Path ``j`` is ``xy[offsets[j]:offsets[j + 1]]``.
        lengths_m: Length of every path, metres.
        pieces: Every path as its own ``(k, 2)`` view of ``xy``, in request order.
        by_area: Per provisional area, its paths by opening index.
    """

    xy: np.ndarray
    offsets: np.ndarray
    lengths_m: np.ndarray
    pieces: list[np.ndarray]
    by_area: list[dict[int, np.ndarray]]


def world_paths(
    vxy: np.ndarray,
    voff: np.ndarray,
    vlen: np.ndarray,
    req: np.ndarray,
    zf_twin: np.ndarray,
    zf_fo: np.ndarray,
    anchor_xy: np.ndarray,
    n_reg: int,
) -> WorldPaths:
    """The path of every request (world metres), and per provisional area its paths by opening.

    A zero-area frontier pathway's two openings share one degenerate path at its anchor.
    """
    n_req = int(req.shape[1])
    voff_l = voff.tolist()
    pieces = list(map(vxy.__getitem__, map(slice, voff_l[:n_req], voff_l[1 : n_req + 1])))
    area_paths: list[dict[int, np.ndarray]] = [{} for _ in range(n_reg + int(zf_fo.size))]
    # area_paths[a][k] = piece for every request, in request order, without a Python loop
    deque(
        map(setitem, map(area_paths.__getitem__, req[0].tolist()), req[1].tolist(), pieces),
        maxlen=0,
    )
    for z, (twin, fo) in enumerate(zip(zf_twin.tolist(), zf_fo.tolist(), strict=True)):
        pt = np.repeat(anchor_xy[fo : fo + 1], 2, axis=0)
        area_paths[n_reg + z] = {twin: pt, fo: pt}
    return WorldPaths(vxy, voff, vlen, pieces, area_paths)


def opening_records(
    ids: np.ndarray,
    op_a0: np.ndarray,
    op_a1: np.ndarray,
    ends_xy: np.ndarray,
    mids: np.ndarray,
    widths_m: np.ndarray,
    anchor_xy: np.ndarray,
) -> list[Opening]:
    """One :class:`Opening` per opening (chords, then frontier twins and frontiers)."""
    n_all = int(op_a0.size)
    side_b = np.where(op_a1 >= 0, ids[op_a1], -1) if n_all else op_a1
    return list(
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


def area_records(
    area_ids: list[int],
    prov_type: np.ndarray,
    centre_xy: np.ndarray,
    aoff: np.ndarray,
    aops: np.ndarray,
    paths: WorldPaths,
    counts: np.ndarray,
    n_reg: int,
) -> dict[int, Area]:
    """The :class:`Area` records by final id (``n_reg`` regions, then zero-area frontier
    pathways)."""
    n_prov = len(area_ids)
    n_zf = n_prov - n_reg
    aops_l = aops.tolist()
    aoff_l = aoff.tolist()
    area_recs = map(
        _tnew,
        repeat(Area),
        zip(
            area_ids,
            map(_TYPE_OF.__getitem__, prov_type.tolist()),
            map(tuple, centre_xy.tolist()),
            map(tuple, map(aops_l.__getitem__, map(slice, aoff_l[:n_prov], aoff_l[1:]))),
            paths.by_area,
            counts.tolist()[:n_reg] + [0] * n_zf,
            strict=True,
        ),
    )
    return dict(zip(area_ids, area_recs, strict=True))


def edge_records(
    edges2: np.ndarray,
    pairs: np.ndarray,
    plen: np.ndarray,
    ids_l: list[int],
    paths: WorldPaths,
) -> list[GraphEdge]:
    """Graph edges: areas with two openings, then every pair of an intersection's legs."""
    vlen_l = paths.lengths_m.tolist()
    pieces, area_paths = paths.pieces, paths.by_area
    edges: list[GraphEdge] = [
        _tnew(GraphEdge, (o1, o2, ids_l[a], vlen_l[j], pieces[j]))
        if j >= 0
        else _tnew(GraphEdge, (o1, o2, ids_l[a], 0.0, area_paths[a][o1]))
        for o1, o2, a, j in edges2.tolist()
    ]
    if pairs.shape[1]:
        jxy, joff = join_legs(paths.xy, paths.offsets, pairs[0], pairs[1])
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
    return edges


def frontier_records(
    fronts: np.ndarray, fronts_len: np.ndarray, ids_l: list[int], openings: list[Opening]
) -> list[Frontier]:
    """One :class:`Frontier` per frontier, with its nearest intersection and ``p_l``."""
    return [
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
