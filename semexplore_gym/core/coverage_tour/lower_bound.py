"""A certified lower bound on the drive (and time) any explorer needs to reach the coverage goal.

:func:`lower_bound` relaxes the exploration problem in steps, each of which can only lower the
optimum, so the result is below the path length of every explorer with this robot and LiDAR:

1. **Robot cells.** Pymunk keeps the robot's centre ``radius_m`` (circle of ``radius - skin``
   plus the wall's ``skin``) from every wall, less a penetration tolerance (0.01 m; the physics'
   collision slop is at most 0.005 m): clearance ``c_min``. A cell that holds such a point has
   its centre at least ``c_min - h/sqrt(2)`` from every wall, so the robot's centre only ever
   lies in cells meeting that test, 8-connected to the start's cell (the allowed cells).
2. **K-hop distances never exceed a real path.** Checkpoint a continuous path each time it first
   reaches Chebyshev distance K (cells) from the last checkpoint's cell: each piece stays in the
   previous checkpoint's ball, so a breadth-first search over allowed cells inside the ball
   finds it. It reaches a checkpoint's cell from inside the last ball, so on the side of its
   square facing that ball (a ring corner at its inner corner, on that side too), and the next
   piece is at least the gap from that side to the next cell's square (the first: from anywhere
   in the start's square). The piece also drives at least a map cell size between first
   entering a cell of breadth-first depth ``m`` and one of ``m + 1`` (it enters the first from
   a cell of depth ``m - 1``, which shares no move with, so does not touch, one of ``m + 1``):
   a hop counts the larger of the gap and (depth - 1) cell sizes. The Dijkstra distance over
   such hops, one state per (cell, side), the last hop possibly ending inside a ball, is <=
   the length.
3. **Where a group can be seen from (a superset).** A scan marks a cell FREE only along a beam
   from the sensor that reaches a point of the cell's square within the LiDAR's range and
   crosses no wall first. For a rectangle A of cells, a robot cell U is excluded only when
   every segment from U's square (widened by the LiDAR's mount offset) to A is longer than the
   range or meets a wall. That holds when the two are farther apart than the range; when one
   wall (collinear touching walls merged) meets every segment: its line separates them
   strictly and the 16 corner-pair segments cross it inside the wall (the segments from U to A
   fill the convex hull of both, whose crossing with the line is spanned by the corner pairs);
   or when it holds for each quarter of A in turn, down to ``visibility_splits`` levels (the
   segments to A are those to its quarters, so walls meeting at a corner block it together).
4. **Route through must-see groups.** Groups are the coverage-mask cells of the blocks of a
   lattice. If the explorer never entered a group's region, none of its cells is FREE; the goal
   leaves at most ``budget`` mask cells unseen, so the explorer enters the regions of a set S
   of the chosen groups whose others hold at most ``budget`` cells, in order of first entry.
   It first enters a region at the start (if the start is in it) or by a move from a cell
   outside it, so at one of its entry cells (cells of the region with a move to a cell
   outside); those are split into a few entry pieces. Between first entering one region (at a
   cell of one piece) and first entering the next (at a cell of one of its pieces) it drives at
   least the K-hop distance between the two pieces (either direction: a path reversed is a
   path; a value the search stopped short of counts as the limit it stopped at, below it).
   The bound is the least such route over every feasible S, every order and every choice of
   entry pieces (Held-Karp over subsets and last piece, exact), for any choice of groups:
   lattice blocks of two sizes, and groups grown from the branch bound's small blocks around
   the places seen from few cells (:mod:`.grown_groups`; a group's region is the union of its
   blocks' regions). The largest route counts.

5. **Or the branch bound** (:mod:`.branch_bound`, on the same distances and visibility), the
   larger of the two. Time at top speed is ``distance_m / max_linear_speed_mps``. The bound assumes a noise-free
LiDAR fused at the true pose (the env's default: no range noise, no odometry drift).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field, replace

import numpy as np
from scipy import ndimage

from semexplore_gym.core.coverage_tour.bound_geometry import (
    group_parents,
    mask_groups,
    merge_walls,
    wall_corners,
)
from semexplore_gym.core.coverage_tour.bound_params import LowerBoundParams
from semexplore_gym.core.coverage_tour.branch_bound import (
    BranchInputs,
    branch_bound_m,
    branch_regions,
)
from semexplore_gym.core.coverage_tour.grown_groups import grown_pool
from semexplore_gym.core.coverage_tour.khop_kernels import coarse_moves, khop_balls, khop_distances
from semexplore_gym.core.coverage_tour.lower_bound_kernels import group_region, held_karp_entries
from semexplore_gym.core.coverage_tour.problem import PrivilegedWorld
from semexplore_gym.core.coverage_tour.thread_map import thread_map
from semexplore_gym.core.grid import GridGeometry
from semexplore_gym.core.worlds.geometry import segment_distance_field

_EIGHT = np.ones((3, 3), dtype=bool)
_VISIBILITY_TOL_M = 1e-6
_CLEARANCE_TOL_M = 1e-4
_MAX_BALL_ENTRIES = 50_000_000  # 200 MB of cached breadth-first balls at most


@dataclass(frozen=True)
class LowerBound:
    """A certified lower bound on the drive to the coverage goal, with what it is made of.

    Attributes:
        distance_m: No explorer reaches the goal after a shorter drive (inf: none can): the
            larger of the route's bound and ``branch_m``.
        time_s: ``distance_m`` at top speed.
        n_groups: Groups in the route's problem.
        group_cells: Coverage-mask cells of each group.
        group_centres_m: ``(x, y)`` centre of each group's bounding box.
        region_cells: Distance cells of each group's region.
        route: Group indices in the order of the bound's route (the groups it visits).
        budget_cells: Mask cells the goal lets an explorer leave unseen.
        block_cells: Side of the lattice blocks (map cells) of the groups (grown groups: of
            the blocks they were grown from).
        planning_s: Wall time spent.
        branch_m: The branch bound (0 when not computed).
    """

    distance_m: float
    time_s: float
    n_groups: int
    group_cells: tuple[int, ...]
    group_centres_m: tuple[tuple[float, float], ...]
    region_cells: tuple[int, ...]
    route: tuple[int, ...]
    budget_cells: int
    block_cells: int
    planning_s: float
    branch_m: float = 0.0


def skip_budget_cells(n_cells: int, share: float) -> int:
    """Most of ``n_cells`` that may stay unseen with coverage ``count / n_cells`` at ``share``
    (compared as the mission's T99 is, with a 1e-12 tolerance)."""
    need = min(n_cells, max(0, math.ceil(share * n_cells) - 2))
    while need < n_cells and need / n_cells < share - 1e-12:
        need += 1
    return n_cells - need


def allowed_cells(facts: PrivilegedWorld, tolerance_m: float) -> tuple[np.ndarray, tuple[int, int]]:
    """The cells the robot's centre can lie in (step 1) and the start's cell.

    Raises:
        ValueError: a start outside the grid or too close to a wall, or free space that reaches
            the edge of the grid (the map is larger than the grid holds).
    """
    geo = facts.geometry
    h = geo.resolution_m
    c_min = facts.radius_m - tolerance_m
    need = c_min - h / math.sqrt(2.0) - _CLEARANCE_TOL_M
    field = segment_distance_field(facts.world.segments_m, geo, max(need, 0.0) + h)
    ok = field >= need
    x, y = facts.start_pose[0], facts.start_pose[1]
    row, col = (int(v) for v in geo.world_to_grid(x, y))
    if not (0 <= row < geo.height and 0 <= col < geo.width):
        raise ValueError(f"start ({x:g}, {y:g}) lies outside the map grid")
    if not ok[row, col]:
        raise ValueError(
            f"start ({x:g}, {y:g}) is inside a wall: closer than the robot's radius "
            f"({facts.radius_m:g} m) to one"
        )
    labels, _ = ndimage.label(ok, structure=_EIGHT)
    allowed = labels == labels[row, col]
    if allowed[0, :].any() or allowed[-1, :].any() or allowed[:, 0].any() or allowed[:, -1].any():
        raise ValueError(
            "the free space around the start reaches the edge of the map grid: the world is "
            "larger than the grid holds (or not closed by walls)"
        )
    return allowed, (row, col)


@dataclass(frozen=True)
class _Problem:
    """The fixed parts: allowed map cells, walls, the coarse distance grid's moves."""

    allowed: np.ndarray
    coarse: np.ndarray
    factor: int
    walls: np.ndarray
    geometry: GridGeometry
    reach_m: float
    widen_m: float
    hop_cells: int
    split_depth: int = 0
    hop_depth: bool = True
    corners: np.ndarray = field(default_factory=lambda: np.zeros((0, 8)))
    balls: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None

    def with_balls(self, max_entries: int = _MAX_BALL_ENTRIES) -> _Problem:
        """The same problem with its searches' breadth-first balls computed once
        (:func:`~.khop_kernels.khop_balls`: the same distances, quicker for many
        searches), unless they could hold more than ``max_entries`` cells (memory)."""
        n_cells = int(np.count_nonzero((self.coarse >> 4) & 1))
        if n_cells * (2 * self.hop_cells + 1) ** 2 > max_entries:
            return replace(self, balls=None)
        return replace(self, balls=khop_balls(self.coarse, self.hop_cells))

    def to_coarse_each(self, flat: np.ndarray) -> np.ndarray:
        """The coarse cell of each map cell (flat indices)."""
        r, c = np.divmod(np.asarray(flat, dtype=np.int64), self.geometry.width)
        return (r // self.factor) * self.coarse.shape[1] + c // self.factor

    def to_coarse(self, flat: np.ndarray) -> np.ndarray:
        return np.unique(self.to_coarse_each(flat))

    def region(self, rect: np.ndarray, stride: int = 1) -> np.ndarray:
        """Coarse cells of the region of the group in ``rect`` (with ``stride`` > 1 a sample
        of it, only to rank groups)."""
        g = self.geometry
        frame = np.array(
            [
                g.origin_x_m,
                g.origin_y_m,
                g.resolution_m,
                self.reach_m,
                self.widen_m,
                _VISIBILITY_TOL_M,
                self.split_depth,
                stride,
            ],
            dtype=np.float64,
        )
        return self.to_coarse(group_region(self.allowed, rect, self.walls, frame, self.corners))

    def entry_pieces(self, region: np.ndarray, start: int, tile: int, cap: int) -> list[np.ndarray]:
        """Where a route can first enter ``region`` (coarse cells): its cells with a move to a
        cell outside it, and the start's cell if inside; split into 8-connected pieces cut by
        ``tile``-cell tiles, at most ``cap`` of them (the rest merged into the nearest)."""
        hc, wc = self.coarse.shape
        if np.any(region == start):  # entered at the start, before any move
            return [np.array([start], dtype=np.int64)]
        inside = np.zeros(hc * wc, dtype=bool)
        inside[region] = True
        bits = self.coarse.reshape(-1)[region]
        r, c = np.divmod(region, wc)
        edge = np.zeros(region.size, dtype=bool)
        for dr in (-1, 0, 1):
            for dc in (-1, 0, 1):
                if dr == 0 and dc == 0:
                    continue
                has = ((bits >> (3 * (dr + 1) + dc + 1)) & 1).astype(bool)
                r2 = np.clip(r + dr, 0, hc - 1)
                c2 = np.clip(c + dc, 0, wc - 1)
                edge |= has & ~inside[r2 * wc + c2]
        cells = region[edge]
        if cells.size == 0:
            return []
        image = np.zeros(hc * wc, dtype=bool)
        image[cells] = True
        labels, _ = ndimage.label(image.reshape(hc, wc), structure=_EIGHT)
        er, ec = np.divmod(cells, wc)
        key = labels.reshape(-1)[cells] * (hc * wc) + (er // tile) * wc + ec // tile
        _, piece = np.unique(key, return_inverse=True)
        sizes = np.bincount(piece)
        if sizes.size > cap:
            big = np.argsort(-sizes, kind="stable")[:cap]
            cy = np.bincount(piece, er) / sizes
            cx = np.bincount(piece, ec) / sizes
            near = big[np.argmin(np.hypot(cy[:, None] - cy[big], cx[:, None] - cx[big]), axis=1)]
            piece = near[piece]
        return [cells[piece == q] for q in np.unique(piece)]

    def distances(
        self,
        coarse_sources: np.ndarray,
        targets: list[np.ndarray] | None = None,
        limit_m: float = math.inf,
    ) -> np.ndarray:
        """K-hop distances from the sources; with ``targets`` (coarse cell sets), exact only
        as far as each set's least value needs; values above ``limit_m`` lowered to it."""
        src = np.asarray(coarse_sources, dtype=np.int64)
        res = self.geometry.resolution_m * self.factor
        target_of = np.full(self.coarse.shape, -1, dtype=np.int64)
        flat = target_of.reshape(-1)
        sets = [t for t in (targets or []) if t.size]
        for j, t in enumerate(sets):
            flat[t] = j
        step = self.geometry.resolution_m if self.hop_depth else 0.0
        d = khop_distances(
            self.coarse,
            src,
            self.hop_cells,
            res,
            target_of,
            len(sets),
            float(limit_m),
            step,
            self.balls,
        )
        return d.reshape(-1)


def lower_bound(facts: PrivilegedWorld, params: LowerBoundParams | None = None) -> LowerBound:
    """A certified lower bound on the drive to the coverage goal from ``facts.start_pose``.

    Raises:
        ValueError: nothing reachable to cover, a start inside a wall or outside the grid, or a
            map larger than its grid.
    """
    p = params or LowerBoundParams()
    t0 = time.perf_counter()
    geo = facts.geometry
    mask = np.asarray(facts.reachable_mask, dtype=bool)
    if mask.shape != geo.shape:
        raise ValueError(f"reachable mask shape {mask.shape} != map grid {geo.shape}")
    n_mask = int(mask.sum())
    if n_mask == 0:
        raise ValueError("nothing to cover: the reachable mask has no cell")
    allowed, (sr, sc) = allowed_cells(facts, p.penetration_tolerance_m)
    share = facts.coverage_goal if p.coverage_share is None else p.coverage_share
    budget = skip_budget_cells(n_mask, share)
    f = p.distance_cell_factor
    walls = merge_walls(facts.world.segments_m)
    prob = _Problem(
        allowed=allowed,
        coarse=coarse_moves(allowed, f),
        factor=f,
        walls=walls,
        geometry=geo,
        reach_m=facts.sensor.max_range_m + _VISIBILITY_TOL_M,
        widen_m=p.mount_offset_m + _VISIBILITY_TOL_M,
        hop_cells=p.hop_cells,
        split_depth=p.visibility_splits,
        hop_depth=p.hop_depth,
    ).with_balls()
    start = prob.to_coarse(np.array([sr * geo.width + sc]))
    from_start = prob.distances(start)
    best: _Route | None = None
    for scale in p.group_scales:
        block = max(1, int(math.ceil(scale * math.sqrt(budget + 1))))
        found = _bound_for_blocks(prob, mask, block, (int(start[0]), from_start), budget, p)
        if best is None or found.length_m > best.length_m:
            best = found
    assert best is not None
    branch_m = 0.0
    if p.branch_block_m > 0:
        segments = facts.world.segments_m
        branch_m, blocks = _branch_m(prob, mask, (sr * geo.width + sc, budget), p, segments)
        for share in p.grown_shares:
            found = _grown_route(prob, blocks, (int(start[0]), from_start), budget, share, p)
            if found.length_m > best.length_m:
                best = found
    length_m = max(best.length_m, branch_m)
    return LowerBound(
        distance_m=length_m,
        time_s=length_m / facts.max_linear_speed_mps,
        n_groups=len(best.cells),
        group_cells=best.cells,
        group_centres_m=best.centres_m,
        region_cells=best.region_cells,
        route=best.route,
        budget_cells=budget,
        block_cells=best.block_cells,
        planning_s=time.perf_counter() - t0,
        branch_m=branch_m,
    )


def _branch_m(
    prob: _Problem,
    mask: np.ndarray,
    start_budget: tuple[int, int],
    p: LowerBoundParams,
    segments_m: np.ndarray,
) -> tuple[float, tuple[np.ndarray, np.ndarray, list[np.ndarray]]]:
    """The branch bound (step 5) on ``p.branch_block_m`` groups of ``mask``, from the map cell
    ``start`` (flat) with the skip ``budget`` (cells); with ``p.wall_corners``, the corners of
    the world's ``segments_m`` block views too (only here and in the grown groups: the
    route's relaxation is not monotone in its regions, the branches are, so the bound is never
    lower with them). Also returns the groups' cells, centres and regions."""
    start, budget = start_budget
    geo = prob.geometry
    side = max(1, round(p.branch_block_m / geo.resolution_m))
    rects, cells, centres = mask_groups(mask, geo, side)
    nest = p.branch_nested
    outer = (mask_groups(mask, geo, 2 * side)[0], group_parents(mask, side)) if nest else ()
    frame = np.array([geo.origin_x_m, geo.origin_y_m, geo.resolution_m, prob.reach_m])
    frame = np.append(frame, [prob.widen_m, _VISIBILITY_TOL_M, p.visibility_splits])
    frame = np.append(frame, p.branch_max_walls)
    fine = replace(prob, coarse=coarse_moves(prob.allowed, 1), factor=1, balls=None)
    phi = fine.distances(np.array([start]))
    inputs = BranchInputs(
        prob.allowed,
        prob.factor,
        prob.walls,
        frame,
        fine.coarse,
        phi,
        rects,
        cells,
        budget,
        *outer,
        corners=wall_corners(segments_m, prob.walls) if p.wall_corners else np.zeros((0, 8)),
    )
    found = branch_regions(inputs, p.threads)
    branch_m = branch_bound_m(inputs, threads=p.threads, found=found)
    return branch_m, (cells, centres, found)


def _grown_route(
    prob: _Problem,
    blocks: tuple[np.ndarray, np.ndarray, list[np.ndarray]],
    start: tuple[int, np.ndarray],
    budget: int,
    share: float,
    p: LowerBoundParams,
) -> _Route:
    """The route (step 4) over groups grown from the branch bound's ``blocks`` (cells,
    centres, regions) to ``share`` of the budget (:func:`.grown_groups.grown_pool`)."""
    geo = prob.geometry
    side = max(1, round(p.branch_block_m / geo.resolution_m))
    regions, cells, centres = grown_pool(
        blocks,
        (geo.origin_x_m, geo.origin_y_m, side * geo.resolution_m),
        (start[1], prob.coarse.size),
        share * (budget + 1),
        p,
    )
    return _route_over(prob, regions, cells, centres, start, budget, p, side)


@dataclass(frozen=True)
class _Route:
    length_m: float
    cells: tuple[int, ...]
    centres_m: tuple[tuple[float, float], ...]
    region_cells: tuple[int, ...]
    route: tuple[int, ...]
    block_cells: int


def _bound_for_blocks(
    prob: _Problem,
    mask: np.ndarray,
    block: int,
    start: tuple[int, np.ndarray],
    budget: int,
    p: LowerBoundParams,
) -> _Route:
    """Groups of ``block``-cell lattice blocks, chosen farthest first (from the start and the
    groups chosen so far, by distance to the group's own cells: a choice, not a proof step),
    then the exact route over their entry pieces. ``start``: its coarse cell and distances."""
    start_cell, from_start = start
    rects, cells, _ = mask_groups(mask, prob.geometry, block)
    rows, cols = np.nonzero(mask)
    bw = -(-mask.shape[1] // block)
    _, group_of = np.unique((rows // block) * bw + cols // block, return_inverse=True)
    coarse_of = prob.to_coarse_each(rows * mask.shape[1] + cols)
    score = np.full(rects.shape[0], np.inf)
    np.minimum.at(score, group_of, from_start[coarse_of])
    # Well-filled groups only (a scrap of a block is cheap to leave unseen), and of those the
    # share seen from the fewest cells (a sample of each region).
    score[cells < 0.5 * block * block] = 0.0
    live = np.flatnonzero(score > 0)
    if p.keep_share < 1 and live.size > p.pool_groups:
        sample = np.array(
            thread_map(lambda g: prob.region(rects[g], p.sample_stride).size, live, p.threads)
        )
        cut = np.quantile(sample, p.keep_share)
        score[live[sample > cut]] = 0.0
    centres = 0.5 * (rects[:, :2] + rects[:, 2:])
    chosen: list[int] = []
    while len(chosen) < min(p.pool_groups, rects.shape[0]):
        g = int(np.argmax(score))
        if not score[g] > 0:
            break
        chosen.append(g)
        np.minimum(score, np.hypot(*(centres - centres[g]).T), out=score)
    regions = thread_map(lambda g: prob.region(rects[g]), chosen, p.threads)
    return _route_over(prob, regions, cells[chosen], centres[chosen], start, budget, p, block)


def _route_over(
    prob: _Problem,
    regions: list[np.ndarray],
    cells: np.ndarray,
    centres: np.ndarray,
    start: tuple[int, np.ndarray],
    budget: int,
    p: LowerBoundParams,
    block: int,
) -> _Route:
    """The exact route over the entry pieces of the groups with these ``regions`` (coarse
    cells), ``cells`` and ``centres``, of the groups :func:`_choose_groups` keeps."""
    start_cell, from_start = start
    tile = max(1, int(round(p.entry_tile_m / (prob.geometry.resolution_m * prob.factor))))
    pieces = [prob.entry_pieces(r, start_cell, tile, p.max_entries) for r in regions]
    node_group = np.array([i for i, ps in enumerate(pieces) for _ in ps], dtype=np.int64)
    nodes = [q for ps in pieces for q in ps]
    first, legs = _entry_legs(prob, nodes, node_group, from_start, p.leg_limit_share, p.threads)
    cells = np.asarray(cells, dtype=np.int64)
    pick = _choose_groups(first, legs, node_group, cells, budget, p)
    length, order = _route(first, legs, node_group, cells, budget, pick)
    return _Route(
        length_m=float(length),
        cells=tuple(int(c) for c in cells[pick]),
        centres_m=tuple((float(x), float(y)) for x, y in centres[pick]),
        region_cells=tuple(int(regions[i].size) for i in pick),
        route=tuple(int(i) for i in order),
        block_cells=block,
    )


def _route(
    first: np.ndarray,
    legs: np.ndarray,
    node_group: np.ndarray,
    cells: np.ndarray,
    budget: int,
    pick: list[int],
) -> tuple[float, np.ndarray]:
    """The exact route over the groups ``pick`` (indices into ``cells``), in their numbering."""
    if not pick:
        return 0.0, np.zeros(0, dtype=np.int64)
    renumber = np.full(cells.size, -1, dtype=np.int64)
    renumber[pick] = np.arange(len(pick))
    keep = renumber[node_group] >= 0
    return held_karp_entries(
        first[keep],
        legs[np.ix_(keep, keep)].copy(),
        renumber[node_group[keep]],
        cells[pick].copy(),
        int(budget),
    )


def _choose_groups(
    first: np.ndarray,
    legs: np.ndarray,
    node_group: np.ndarray,
    cells: np.ndarray,
    budget: int,
    p: LowerBoundParams,
) -> list[int]:
    """Groups added one at a time, each the one whose route is longest (ties: the farther from
    the start), up to ``max_groups``; the prefix with the longest route is kept (a choice, not
    a proof step: any subset of groups gives a valid bound). A group the budget lets the route
    skip adds nothing alone, so the search goes on past steps that do not lengthen the route."""
    far = np.full(cells.size, 0.0)
    ok = np.isfinite(first)
    np.maximum.at(far, node_group[ok], first[ok])
    pick: list[int] = []
    best, best_k = 0.0, 0
    while len(pick) < min(p.max_groups, cells.size):
        trial = [
            (_route(first, legs, node_group, cells, budget, pick + [g])[0], far[g], g)
            for g in range(cells.size)
            if g not in pick
        ]
        value, _, g = max(trial)
        pick.append(g)
        if value > best:
            best, best_k = value, len(pick)
    pick = pick[:best_k]
    return pick


def _entry_legs(
    prob: _Problem,
    nodes: list[np.ndarray],
    node_group: np.ndarray,
    from_start: np.ndarray,
    share: float,
    threads: int,
) -> tuple[np.ndarray, np.ndarray]:
    """The start-to-node and node-to-node K-hop distances (the least over each piece's cells;
    either direction of a leg bounds it, so the larger of the two), one search a node, on up
    to ``threads`` threads."""
    n = len(nodes)
    first = np.array([_least(from_start, q) for q in nodes], dtype=np.float64)
    # Legs longer than a share of the farthest node's distance from the start are lowered to
    # it (still a bound; it saves searching the far side of the map from every node).
    ok = np.isfinite(first)
    limit = share * float(first[ok].max()) if ok.any() and share < 1 else math.inf
    legs = np.zeros((n, n), dtype=np.float64)

    def row(v: int) -> np.ndarray:
        others = [nodes[u] for u in range(n) if node_group[u] != node_group[v]]
        field = prob.distances(nodes[v], others, limit_m=limit)
        return np.array([_least(field, q) if node_group[u] != node_group[v] else 0.0
                         for u, q in enumerate(nodes)])  # fmt: skip

    for v, leg in enumerate(thread_map(row, range(n), threads)):
        legs[v] = leg
    return first, np.maximum(legs, legs.T)


def _least(field: np.ndarray, cells: np.ndarray) -> float:
    """Least of ``field`` over ``cells`` (inf for none: a region nothing can stand in)."""
    return float(field[cells].min()) if cells.size else math.inf
