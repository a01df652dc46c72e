"""Stage 10 of the segmentation, identity: area ids carried over from the previous map.

An area inherits the id of the previous area its skeleton overlaps most (one-to-one, by
position in the world frame); a zero-area frontier pathway inherits the id of the nearest
previous one within ``match_radius_m``. Every other area gets a fresh id.
"""

from __future__ import annotations

import numpy as np

from semexplore_gym.core.topometric.types import AreaType, TopometricMap


def next_area_id(previous: TopometricMap | None) -> int:
    """The first id that ``previous`` (and the maps before it) never used."""
    if previous is None:
        return 0
    nid = previous.extras.get("next_area_id") if isinstance(previous.extras, dict) else None
    base = max(previous.areas) + 1 if previous.areas else 0
    return max(int(nid), base) if nid is not None else base


def match_area_ids(
    previous: TopometricMap | None,
    n_reg: int,
    n_prov: int,
    centre_xy: np.ndarray,
    skeleton_region: np.ndarray,
    skeleton_xy_m: np.ndarray,
    match_radius_m: float,
    skeleton_cells: tuple[np.ndarray, np.ndarray] | None = None,
) -> tuple[np.ndarray, int]:
    """Final ids of the provisional areas, and the next fresh id.

    Args:
        previous: The previous map, or None (all ids fresh).
        n_reg: Number of regions (provisional areas ``0..n_reg-1``); the others, up to
            ``n_prov``, are zero-area frontier pathways.
        n_prov: Number of provisional areas.
        centre_xy: ``(n_prov, 2)`` area centres, world metres.
        skeleton_region: Region of each labelled skeleton pixel (empty when there is nothing to
            match by overlap).
        skeleton_xy_m: ``(n, 2)`` world position of those pixels, metres.
        match_radius_m: Largest distance at which a zero-area frontier pathway keeps its id.
        skeleton_cells: ``(rows, cols)`` of those pixels in ``previous``'s grid, if the caller
            has them (then ``skeleton_xy_m`` is not read): the cells ``skeleton_xy_m`` falls in.
    """
    next_id = next_area_id(previous)
    if previous is None:
        return np.arange(next_id, next_id + n_prov, dtype=np.int64), next_id + n_prov
    ids = np.full(n_prov, -1, dtype=np.int64)
    if previous.areas:
        used = _match_by_overlap(previous, ids, skeleton_region, skeleton_xy_m, skeleton_cells)
        _match_zero_area(previous, ids, used, n_reg, n_prov, centre_xy, match_radius_m)
    fresh = np.flatnonzero(ids < 0)
    ids[fresh] = next_id + np.arange(fresh.size)
    return ids, next_id + int(fresh.size)


def _match_by_overlap(
    previous: TopometricMap,
    ids: np.ndarray,
    skeleton_region: np.ndarray,
    skeleton_xy_m: np.ndarray,
    skeleton_cells: tuple[np.ndarray, np.ndarray] | None = None,
) -> set[int]:
    """Give regions the id of the previous area under most of their skeleton (in place)."""
    used: set[int] = set()
    if not skeleton_region.size:
        return used
    if skeleton_cells is not None:
        pr, pc = skeleton_cells
    else:
        pr, pc = previous.geometry.world_to_grid(skeleton_xy_m[:, 0], skeleton_xy_m[:, 1])
    inside = previous.geometry.contains(pr, pc)
    prev_id = np.full(skeleton_region.size, -1, dtype=np.int64)
    prev_id[inside] = previous.area_ids_at(pr[inside], pc[inside])
    ok = prev_id >= 0
    if ok.any():
        base = int(prev_id.max()) + 1
        codes, counts = np.unique(skeleton_region[ok] * base + prev_id[ok], return_counts=True)
        for j in np.argsort(-counts, kind="stable"):
            if counts[j] < 2:
                break
            g, pid = divmod(int(codes[j]), base)
            if ids[g] >= 0 or pid in used or pid not in previous.areas:
                continue
            ids[g] = pid
            used.add(pid)
    return used


def _match_zero_area(
    previous: TopometricMap,
    ids: np.ndarray,
    used: set[int],
    n_reg: int,
    n_prov: int,
    centre_xy: np.ndarray,
    match_radius_m: float,
) -> None:
    """Zero-area frontier pathways: the nearest unused previous one without cells (in place)."""
    cand = [
        a
        for a in previous.areas.values()
        if a.type == AreaType.FRONTIER_PATHWAY and a.n_cells == 0 and a.id not in used
    ]
    r2 = match_radius_m**2
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
