"""The branch bound: every branch of the world that hides too much must be driven into and out.

A second certified lower bound beside :func:`.lower_bound.lower_bound`'s route bound (the
larger of the two is the bound). With ``phi`` the K-hop distance from the start (a metric never
above a real path's length, so ``|phi(a) - phi(b)|`` never exceeds the drive between two
cells), take for every level ``t > 0`` the branches at ``t``: the connected pieces of the cells
with ``phi >= t`` (connected by the moves a path's cells make). They form a tree (the merge
tree of ``phi``'s superlevel sets), and:

1. **A branch hides the groups it holds.** A group of mask cells (a lattice block) can only be
   seen from its region (the visibility superset of :mod:`.lower_bound`, step 3, of each cell
   block's allowed map cells). If the region lies inside a branch that the explorer never
   enters, all of the group stays unseen.
2. **Entering a branch at level t crosses level t; leaving it crosses it again.** A walk's
   cells step along moves; a step into a branch comes from a cell with ``phi < t`` (a cell
   with ``phi >= t`` next to it would belong to it). The walk starts outside every branch
   (``phi`` = 0 at the start), so it crosses level ``t`` once into each branch it enters and
   once out of each, but for the one it ends in. Since ``phi`` changes by at most the drive,
   the drive is at least the integral over ``t`` of the crossings: twice the length (in
   ``t``) of every branch entered, less the length of the chain the walk ends in.
3. **The skip budget.** The branches never entered leave every group they hide unseen: their
   cells, and the cells no pose sees at all, may hold at most the goal's skip budget. The bound
   is the least such drive over every set of entered branches that keeps to the budget (a
   knapsack over the tree, exact, with cell counts rounded down to ``budget / units``: a
   relaxation).

It is tight where a world is a tree of corridors (a perfect maze: each dead end driven in and
out, the last one not) and weak where loops let one pass serve two branches, or a branch is
seen from its mouth (rooms behind doors).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from semexplore_gym.core.coverage_tour.branch_kernels import (
    branch_route,
    coarse_region,
    merge_tree,
    set_levels,
)


@dataclass(frozen=True)
class BranchInputs:
    """What :func:`branch_bound_m` works on.

    Attributes:
        allowed: Map cells the robot's centre can lie in.
        region_factor: Map cells per side of the blocks whose visibility is tested (each
            block's region cells stand for all their allowed map cells: a superset).
        walls: Merged wall segments ``(M, 4)``.
        frame: ``gx0, gy0, map res, reach_m, widen_m, tol, visibility depth, max walls`` (see
            :func:`.branch_kernels.coarse_region`).
        moves: The map cells' move bits (:func:`.lower_bound.coarse_moves` with factor 1).
        from_start: K-hop distance of each map cell from the start's (flat).
        group_rects: Bounding rectangle ``x0, y0, x1, y1`` of each group's mask cells.
        group_cells: Mask cells of each group.
        budget_cells: Mask cells the goal lets an explorer leave unseen.
    """

    allowed: np.ndarray
    region_factor: int
    walls: np.ndarray
    frame: np.ndarray
    moves: np.ndarray
    from_start: np.ndarray
    group_rects: np.ndarray
    group_cells: np.ndarray
    budget_cells: int


def branch_bound_m(inputs: BranchInputs, units: int = 128) -> float:
    """The branch bound (module docstring) in metres; ``units``: budget steps of the knapsack
    (cell counts rounded down to ``budget / units``).

    Returns:
        The bound (inf when the cells no pose sees already exceed the budget; 0 when the
        map cells do not form one tree).
    """
    allowed, walls, frame = inputs.allowed, inputs.walls, inputs.frame
    group_rects, group_cells = inputs.group_rects, inputs.group_cells
    moves, from_start, budget_cells = inputs.moves, inputs.from_start, inputs.budget_cells
    region_factor = inputs.region_factor
    phi = np.asarray(from_start, dtype=np.float64)
    _, node_of, parent, level = merge_tree(moves, phi)
    if parent.size == 0 or int(np.sum(parent == np.arange(parent.size))) != 1:
        return 0.0
    f = int(region_factor)
    height, width = allowed.shape
    wide = -(-width // f)
    step = np.arange(f)
    regions = []
    for g in range(group_rects.shape[0]):
        blocks = coarse_region(allowed, f, group_rects[g], walls, frame)
        br, bc = np.divmod(blocks, wide)
        rows = (br[:, None, None] * f + step[None, :, None]) + 0 * step[None, None, :]
        cols = (bc[:, None, None] * f + step[None, None, :]) + 0 * step[None, :, None]
        keep = (rows < height) & (cols < width)
        rows, cols = rows[keep], cols[keep]
        keep = allowed[rows, cols]  # the robot's centre is only ever in allowed cells
        cells = rows[keep] * width + cols[keep]
        regions.append(node_of[cells])
    sizes = np.array([r.size for r in regions], dtype=np.int64)
    unseeable = int(group_cells[sizes == 0].sum())
    budget = int(budget_cells) - unseeable
    if budget < 0:
        return float("inf")
    starts = np.zeros(len(regions) + 1, dtype=np.int64)
    starts[1:] = np.cumsum(sizes)
    flat = np.concatenate(regions) if regions else np.zeros(0, dtype=np.int64)
    lca, _ = set_levels(parent, level, flat, starts)
    # A region cell outside the tree cannot happen (the tree holds every reachable distance
    # cell); a group with one is left out (never counted as hidden: still a bound).
    bad = np.zeros(len(regions), dtype=bool)
    for g, r in enumerate(regions):
        bad[g] = bool(np.any(r < 0))
    use = (lca >= 0) & ~bad
    m = parent.size
    own = np.zeros(m)
    np.add.at(own, lca[use], group_cells[use].astype(np.float64))
    hidden = own.copy()
    for v in range(m - 1):  # children before parents: a parent's index is above its children's
        hidden[parent[v]] += hidden[v]
    return _knapsack(parent, level, own, hidden, budget, units)


def _knapsack(
    parent: np.ndarray,
    level: np.ndarray,
    own: np.ndarray,
    hidden: np.ndarray,
    budget: int,
    units: int,
) -> float:
    """The tree knapsack of step 3 on the merge tree, its branches that hide nothing dropped
    (never worth entering) and chains of one child merged (the same choices)."""
    m = parent.size
    root = m - 1
    is_root = np.arange(m) == root
    kept = (hidden > 0) | is_root
    children = np.bincount(parent[kept & ~is_root], minlength=m)
    chain = kept & ~is_root & (children == 1) & (own == 0)
    survive = kept & ~chain
    above = np.arange(m)
    for v in range(m - 2, -1, -1):  # parents first: each node's nearest surviving ancestor
        p = parent[v]
        above[v] = p if survive[p] else above[p]
    idx = np.flatnonzero(survive)
    new_id = np.full(m, -1, dtype=np.int64)
    new_id[idx] = np.arange(idx.size)
    new_parent = np.where(is_root[idx], new_id[idx], new_id[above[idx]])
    edge = np.where(is_root[idx], 0.0, np.maximum(level[idx] - level[above[idx]], 0.0))
    unit = max(1, -(-budget // max(1, int(units))))
    weight = np.floor(hidden[idx] / unit).astype(np.int64)
    return float(branch_route(new_parent.astype(np.int64), edge, weight, budget // unit))
