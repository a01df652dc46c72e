"""Groups for the route bound grown from small blocks around the places seen from few poses.

The route of :mod:`.lower_bound` (step 4) needs groups whose regions are small: an explorer
must enter a group's region to see any of its cells, and the route only counts the drive
between regions. A lattice block of the side that holds the skip budget is seen from wherever
any one of its cells is, which in a room is most of the room and the corridor outside its
door. :func:`grow_groups` instead starts at the small block (the branch bound's groups) seen
from the fewest coarse cells and adds the neighbouring block that widens the group's region
least, while it widens it by at most ``growth`` of its size, until the group holds
``target_cells``: a strip along a room's far wall, the inside of a dead end. Every block lies
in one group (the groups partition the mask cells, so the route's skip budget counts each cell
once), and a group's region is the union of its blocks' regions: each block's region holds
every pose that sees one of its cells, so the union holds every pose that sees one of the
group's (any grouping gives a valid bound; this one is a choice, not a proof step).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numba import njit


def block_neighbours(block_rc: np.ndarray) -> np.ndarray:
    """``(n, 4)`` index of the block one step up, down, right and left of each block on its
    lattice (``block_rc``: each block's lattice row and column), -1 where there is none."""
    rc = np.asarray(block_rc, dtype=np.int64).reshape(-1, 2)
    out = np.full((rc.shape[0], 4), -1, dtype=np.int64)
    if rc.shape[0] == 0:
        return out
    width = int(rc[:, 1].max()) + 3
    key = (rc[:, 0] + 1) * width + rc[:, 1] + 1
    order = np.argsort(key, kind="stable")
    sorted_key = key[order]
    for k, (dr, dc) in enumerate(((1, 0), (-1, 0), (0, 1), (0, -1))):
        want = key + dr * width + dc
        at = np.clip(np.searchsorted(sorted_key, want), 0, key.size - 1)
        hit = sorted_key[at] == want
        out[hit, k] = order[at[hit]]
    return out


def grow_groups(
    neighbours: np.ndarray,
    cells: np.ndarray,
    regions: list[np.ndarray],
    n_region_cells: int,
    target_cells: float,
    growth: float,
    values: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Partition the blocks into grown groups (module docstring); :func:`group_region` gives a
    group's region.

    Args:
        neighbours: :func:`block_neighbours` of the blocks.
        cells: Mask cells of each block.
        regions: Each block's region (indices below ``n_region_cells``).
        n_region_cells: Size of the region cells' index space.
        target_cells: A group stops growing once it holds this many mask cells.
        growth: ... or when the least widening a neighbour adds exceeds this share of its
            region.
        values: A value per region cell (none: zeros).

    Returns:
        ``group_of`` (the group of each block), each group's region size, and the least of
        ``values`` over each group's region.
    """
    n = len(regions)
    if n == 0:
        return np.zeros(0, dtype=np.int64), np.zeros(0, np.int64), np.zeros(0)
    sizes = np.array([r.size for r in regions], dtype=np.int64)
    ptr = np.zeros(n + 1, dtype=np.int64)
    ptr[1:] = np.cumsum(sizes)
    idx = np.concatenate(regions).astype(np.int64, copy=False)
    order = np.argsort(sizes, kind="stable").astype(np.int64)
    vals = np.zeros(int(n_region_cells)) if values is None else np.asarray(values, np.float64)
    return _grow(
        np.asarray(neighbours, dtype=np.int64),
        np.asarray(cells, dtype=np.int64),
        ptr,
        idx,
        order,
        int(n_region_cells),
        float(target_cells),
        float(growth),
        vals,
    )


def group_region(group_of: np.ndarray, regions: list[np.ndarray], g: int) -> np.ndarray:
    """Group ``g``'s region: the union of its blocks' regions (sorted, unique)."""
    members = np.flatnonzero(group_of == g)
    return np.unique(np.concatenate([regions[b] for b in members])).astype(np.int64)


def grown_pool(
    blocks: tuple[np.ndarray, np.ndarray, list[np.ndarray]],
    lattice: tuple[float, float, float],
    distances: tuple[np.ndarray, int],
    target_cells: float,
    p: Any,
) -> tuple[list[np.ndarray], np.ndarray, np.ndarray]:
    """The grown groups a route is chosen from, as the lattice's are
    (:func:`.lower_bound._bound_for_blocks`): of the well-filled groups (a quarter of
    ``target_cells`` at least), those seen from the fewest cells (``p.keep_share``), the
    farthest from the start first, each next one the farthest from those taken, up to
    ``p.pool_groups`` (a choice, not a proof step).

    Args:
        blocks: The small blocks' cells, centres ``(x, y)`` and regions.
        lattice: ``x0, y0, side_m`` of the blocks' lattice.
        distances: The start's distance to each region cell, and how many region cells.
        target_cells: See :func:`grow_groups`.
        p: The bound's parameters (``grown_growth``, ``keep_share``, ``pool_groups``).

    Returns:
        The chosen groups' regions, mask cells and centres (cell-weighted).
    """
    cells, centres, found = blocks
    x0, y0, side_m = lattice
    from_start, n_region_cells = distances
    col = np.floor((centres[:, 0] - x0) / side_m).astype(np.int64)
    row = np.floor((centres[:, 1] - y0) / side_m).astype(np.int64)
    nb = block_neighbours(np.column_stack([row, col]))
    group_of, sizes, least = grow_groups(
        nb, cells, found, n_region_cells, target_cells, p.grown_growth, from_start
    )
    n = sizes.size
    held = np.bincount(group_of, weights=cells, minlength=n).astype(np.int64)
    weighted = [np.bincount(group_of, weights=centres[:, k] * cells, minlength=n) for k in (0, 1)]
    middle = np.column_stack(weighted) / np.maximum(held, 1)[:, None]
    score = np.where(sizes > 0, least, 0.0)
    well = held >= 0.25 * target_cells
    score[~well | ~np.isfinite(score)] = 0.0
    if well.any():
        score[sizes > np.quantile(sizes[well], p.keep_share)] = 0.0
    chosen: list[int] = []
    while len(chosen) < min(p.pool_groups, n):
        g = int(np.argmax(score))
        if not score[g] > 0:
            break
        chosen.append(g)
        np.minimum(score, np.hypot(*(middle - middle[g]).T), out=score)
    return [group_region(group_of, found, g) for g in chosen], held[chosen], middle[chosen]


@njit(cache=True)
def _mark(ptr, idx, block, inside, marked, n_marked):  # pragma: no cover - numba
    """Adds ``block``'s region cells not yet ``inside`` to ``marked`` (after ``n_marked``);
    returns the new count."""
    for k in range(ptr[block], ptr[block + 1]):
        c = idx[k]
        if not inside[c]:
            inside[c] = True
            marked[n_marked] = c
            n_marked += 1
    return n_marked


@njit(cache=True)
def _grow(neighbours, cells, ptr, idx, order, n_cells, target, growth, values):  # pragma: no cover
    n = order.shape[0]
    group_of = np.full(n, -1, dtype=np.int64)
    inside = np.zeros(n_cells, dtype=np.bool_)
    marked = np.empty(n_cells, dtype=np.int64)  # cells of the current region, to clear
    members = np.empty(n, dtype=np.int64)
    sizes = np.zeros(n, dtype=np.int64)
    least = np.full(n, np.inf)
    n_groups = 0
    for seed in order:
        if group_of[seed] >= 0:
            continue
        g = n_groups
        n_groups += 1
        group_of[seed] = g
        members[0] = seed
        n_members = 1
        n_marked = _mark(ptr, idx, seed, inside, marked, 0)
        held = cells[seed]
        while held < target:
            best = -1
            best_add = -1
            for m in range(n_members):
                for d in range(4):
                    j = neighbours[members[m], d]
                    if j < 0 or group_of[j] >= 0:
                        continue
                    add = 0
                    for k in range(ptr[j], ptr[j + 1]):
                        if not inside[idx[k]]:
                            add += 1
                    if best < 0 or add < best_add or (add == best_add and j < best):
                        best = j
                        best_add = add
            if best < 0 or best_add > growth * n_marked:
                break
            group_of[best] = g
            members[n_members] = best
            n_members += 1
            held += cells[best]
            n_marked = _mark(ptr, idx, best, inside, marked, n_marked)
        sizes[g] = n_marked
        for k in range(n_marked):
            inside[marked[k]] = False
            least[g] = min(least[g], values[marked[k]])
    return group_of, sizes[:n_groups].copy(), least[:n_groups].copy()
