"""The branch bound: every branch of the world that hides too much must be driven into and out.

A second certified lower bound beside :func:`.lower_bound.lower_bound`'s route bound (the
larger of the two is the bound). With ``phi`` the K-hop distance from the start, take for every
level ``t > 0`` the branches at ``t``: the connected pieces of the cells with ``phi >= t``
(connected by the moves a path's cells make). They form a tree (the merge tree of ``phi``'s
superlevel sets), and:

1. **A branch hides the groups it holds.** A group of mask cells (a lattice block) can only be
   seen from its region (the visibility superset of :mod:`.lower_bound`, step 3, of each cell
   block's allowed map cells). If the region lies inside a branch that the explorer never
   enters, all of the group stays unseen.
2. **How much phi can change along a drive.** ``phi(x) <= `` the drive from the start to x
   (the drive's own checkpoints are a chain of hops). Between two points x, y of a drive,
   ``phi(y) <= phi(x) + drive(x, y) + e`` with ``e = sqrt(2) h``: continue x's best chain along
   the drive; x's last hop was measured to the near side of x's cell, the drive leaves from a
   point of it up to a cell's diagonal farther (one splice).
3. **Entering a branch crosses its level; leaving crosses it again.** Let the walk enter the
   branches ``E`` (closed under parents) and take, for each leaf of ``E`` in order of first
   entry, the point of entry, and between two consecutive ones the lowest point of ``phi``. At
   every level ``t`` this sequence starts below ``t``, visits every branch of ``E`` at ``t`` and
   drops below ``t`` between two of them (a walk between two pieces of ``{phi >= t}`` passes
   below ``t``), so its variation is at least the integral over ``t`` of the crossings: twice
   the length (in ``t``) of every branch of ``E``, less the chain the walk ends in. By step 2
   the drive is at least that variation less ``2 e`` for each leaf of ``E`` but the first (the
   first rise, from the start, is exact). Any ancestor-closed part of ``E`` gives the same
   argument, so ``E`` is pruned of branches that hide nothing or are less than ``e`` deep.
4. **The skip budget.** The branches never entered leave every group they hide unseen: their
   cells, and the cells no pose sees at all, may hold at most the goal's skip budget. The bound
   is the least such drive over every set of entered branches that keeps to the budget (a
   knapsack over the tree, exact, with cell counts rounded down to ``budget / units``: a
   relaxation).

It is tight where a world is a tree of corridors (a perfect maze: each dead end driven in and
out, the last one not) and weak where loops let one pass serve two branches, or a branch is
seen from its mouth (rooms behind doors).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from semexplore_gym.core.coverage_tour.branch_kernels import (
    branch_route,
    coarse_region,
    coarse_region_among,
    merge_tree,
    preorder,
    region_extremes,
    set_levels,
)
from semexplore_gym.core.coverage_tour.thread_map import thread_map


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
        outer_rects: None, or the rectangles of larger groups, each group's region sought
            only within that of its own (``outer_of``): every segment to a group is one to
            a larger group that holds it, so the larger region holds the smaller (tighter
            where the larger group's test proves a block blind that the smaller's does not).
        outer_of: The larger group of each group (with ``outer_rects``).
        corners: Pairs of walls that block a view together (:func:`.bound_geometry.wall_corners`;
            none by default).
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
    outer_rects: np.ndarray | None = None
    outer_of: np.ndarray | None = None
    corners: np.ndarray = field(default_factory=lambda: np.zeros((0, 8)))


def branch_regions(inputs: BranchInputs, threads: int = 1) -> list[np.ndarray]:
    """Each group's region (step 1): the coarse cells (``region_factor`` blocks, flat indices,
    increasing) not proven blind to it, found on up to ``threads`` threads."""
    allowed, walls, frame = inputs.allowed, inputs.walls, inputs.frame
    group_rects, corners = inputs.group_rects, inputs.corners
    f = int(inputs.region_factor)
    if inputs.outer_rects is None:
        return thread_map(
            lambda g: coarse_region(allowed, f, group_rects[g], walls, frame, corners),
            range(group_rects.shape[0]),
            threads,
        )
    outer_rects, outer_of = inputs.outer_rects, inputs.outer_of
    outer = thread_map(
        lambda g: coarse_region(allowed, f, outer_rects[g], walls, frame, corners),
        range(outer_rects.shape[0]),
        threads,
    )
    return thread_map(
        lambda g: coarse_region_among(
            allowed, f, group_rects[g], walls, frame, outer[outer_of[g]], corners
        ),
        range(group_rects.shape[0]),
        threads,
    )


def branch_bound_m(
    inputs: BranchInputs,
    units: int = 128,
    threads: int = 1,
    found: list[np.ndarray] | None = None,
) -> float:
    """The branch bound (module docstring) in metres; ``units``: budget steps of the knapsack
    (cell counts rounded down to ``budget / units``); the groups' regions are found on up to
    ``threads`` threads, or given as ``found`` (:func:`branch_regions`).

    Returns:
        The bound (inf when the cells no pose sees already exceed the budget; 0 when the
        map cells do not form one tree).
    """
    allowed, frame = inputs.allowed, inputs.frame
    group_cells = inputs.group_cells
    moves, from_start, budget_cells = inputs.moves, inputs.from_start, inputs.budget_cells
    f = int(inputs.region_factor)
    phi = np.asarray(from_start, dtype=np.float64)
    _, node_of, parent, level = merge_tree(moves, phi)
    if parent.size == 0 or int(np.sum(parent == np.arange(parent.size))) != 1:
        return 0.0
    if found is None:
        found = branch_regions(inputs, threads)
    block_start = np.zeros(len(found) + 1, dtype=np.int64)
    block_start[1:] = np.cumsum([b.size for b in found])
    blocks = np.concatenate(found).astype(np.int64, copy=False) if found else np.zeros(0, np.int64)
    # The robot's centre is only ever in allowed cells: a region is its blocks' allowed cells;
    # the common branch of its cells is that of its first and last in the tree's preorder.
    tin, _ = preorder(parent)
    sizes, bad, ends = region_extremes(blocks, block_start, f, allowed, node_of, tin)
    unseeable = int(group_cells[sizes == 0].sum())
    budget = int(budget_cells) - unseeable
    if budget < 0:
        return float("inf")
    pairs = np.arange(0, ends.size + 1, 2, dtype=np.int64)
    lca, _ = set_levels(parent, level, ends, pairs)
    # A region cell outside the tree cannot happen (the tree holds every reachable distance
    # cell); a group with one is left out (never counted as hidden: still a bound).
    use = (lca >= 0) & ~bad
    m = parent.size
    own = np.zeros(m)
    np.add.at(own, lca[use], group_cells[use].astype(np.float64))
    hidden = own.copy()
    for v in range(m - 1):  # children before parents: a parent's index is above its children's
        hidden[parent[v]] += hidden[v]
    # phi's last hop measures from a cell's near side: between two points of a drive it may
    # differ by the drive plus a cell's diagonal, once per splice (docs/oracle.md, step 5)
    splice_m = math.sqrt(2.0) * float(frame[2])
    return _knapsack(parent, level, (own, hidden), budget, units, 2.0 * splice_m)


def _knapsack(
    parent: np.ndarray,
    level: np.ndarray,
    cells: tuple[np.ndarray, np.ndarray],
    budget: int,
    units: int,
    leaf_m: float,
) -> float:
    """The tree knapsack of step 3 on the merge tree, less ``leaf_m`` for each leaf of the
    entered set but one. ``cells``: the mask cells each node hides itself and in its subtree.

    The bound only needs a drive's entered set pruned to an ancestor-closed part of it: the
    branches that hide nothing are left out (never worth entering), and so are those less than
    ``leaf_m / 2`` deep (entering one would only lower the bound; their cells count as seen
    from their parent); chains of one child that hide nothing themselves are merged (the same
    choices)."""
    own, hidden = (np.asarray(c, dtype=np.float64).copy() for c in cells)
    m = parent.size
    root = m - 1
    is_root = np.arange(m) == root
    top = level.astype(np.float64).copy()
    for v in range(m - 1):  # children before parents: a parent's index is above its children's
        top[parent[v]] = max(top[parent[v]], top[v])
    thin = ~is_root & (top - level[parent] < 0.5 * leaf_m)
    np.add.at(own, parent[thin & ~thin[parent]], hidden[thin & ~thin[parent]])
    kept = ((hidden > 0) & ~thin) | is_root
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
    route = branch_route(new_parent.astype(np.int64), edge, weight, budget // unit, leaf_m)
    return max(0.0, float(route))
