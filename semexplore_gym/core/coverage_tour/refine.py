"""Cover and order chosen together: what the LiDAR sees while driving, and a local search.

A viewpoint tour built from a set cover alone counts only the scans at its viewpoints; the robot
scans all the way along each leg, so many viewpoints (the ends of short dead ends, the corners a
leg passes anyway) add nothing. :func:`refine_tour` works on an open tour that already meets the
target:

1. **leg visibility** (:class:`LegVisibility`): each leg is the path the oracle drives (least
   cost on the standing mask, the same wall-averse cost the policy plans with), and scans are
   taken every ``sample_m`` along it with the env's LiDAR model (:func:`.visible_sets`). What the
   tour sees is the start scan, every viewpoint's scan and every leg's scans;
2. **drop**: in order of the distance it saves, each viewpoint is removed when the tour without
   it (its neighbours joined by a new leg, whose scans count too) still sees the target;
3. **move**: each viewpoint is replaced by the candidate with the smallest detour between its
   neighbours that keeps the target seen (tried in increasing detour, a few per viewpoint);
4. **re-solve**: the order of the survivors by LKH; kept when it is shorter and still sees the
   target. Steps 2-4 repeat while the tour shortens.

Every accepted change keeps the predicted cover at or above ``required`` and shortens the
tour, so the search ends, and never returns a longer or a less covering tour than it was given.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from scipy import sparse

from semexplore_gym.core.coverage_tour.problem import SensorModel
from semexplore_gym.core.coverage_tour.viewpoints import row_counts, visible_sets
from semexplore_gym.core.grid import GridGeometry
from semexplore_gym.core.mapping.raycast import SegmentIndex
from semexplore_gym.core.planning.grid_search import distance_field, shortest_path_cells
from semexplore_gym.core.worlds.world import World

_EMPTY = np.zeros(0, dtype=np.int64)
#: Candidates tried per viewpoint in the move step (least detour first).
_MOVE_TRIES = 4
#: Distance fields kept at once (each is a float32 grid).
_MAX_FIELDS = 256


class LegVisibility:
    """The columns of a count mask that scans along a driven leg map FREE (cached).

    Args:
        world: The true world.
        geometry: Grid of ``count_mask``.
        sensor: The LiDAR.
        count_mask: The cells counted (the env's reachable mask).
        drive_cost: ``(H, W)`` cost of entering each cell (``inf`` off the standing mask): the
            leg is the least-cost path, as the driving policy plans it.
        sample_m: Scans are taken this far apart along the path (its ends excluded: they are
            the tour's nodes, counted on their own).
        index: The world's :class:`SegmentIndex` if already built.
        robust_cells: A pose sees what the scans from its cell and from the four cells this
            many cells away along the axes (those on ``drive_cost``'s finite cells) all see:
            the robot passes near its poses, not on them, and a view through a gap between two
            walls can vanish 0.1 m aside (0: the one scan).
    """

    def __init__(
        self,
        world: World,
        geometry: GridGeometry,
        sensor: SensorModel,
        count_mask: np.ndarray,
        drive_cost: np.ndarray,
        sample_m: float,
        index: SegmentIndex | None = None,
        robust_cells: int = 0,
    ) -> None:
        self._world, self._geo, self._sensor = world, geometry, sensor
        self._mask = count_mask
        self._n_cols = int(np.count_nonzero(count_mask))
        self._cost = drive_cost
        self._index = index if index is not None else SegmentIndex(world.segments_m)
        self._step_cells = max(1, int(round(sample_m / geometry.resolution_m)))
        self._robust = int(robust_cells)
        self._scans: dict[tuple[int, int], np.ndarray] = {}
        self._cells: dict[tuple[int, int], np.ndarray] = {}
        self._legs: dict[tuple[tuple[int, int], tuple[int, int]], np.ndarray] = {}
        self._paths: dict[tuple[tuple[int, int], tuple[int, int]], np.ndarray | None] = {}

    def cells(self, cells_rc: np.ndarray) -> list[np.ndarray]:
        """Per cell, the sorted columns its pose sees (see ``robust_cells``)."""
        keys = [(int(r), int(c)) for r, c in np.asarray(cells_rc, dtype=np.int64).reshape(-1, 2)]
        todo = sorted({k for k in keys if k not in self._cells})
        if todo:
            groups = [self._around(k) for k in todo]
            self._scan(sorted({a for g in groups for a in g}))
            for k, g in zip(todo, groups, strict=True):
                seen = self._scans[g[0]]
                for other in g[1:]:
                    seen = np.intersect1d(seen, self._scans[other], assume_unique=True)
                self._cells[k] = seen
        return [self._cells[k] for k in keys]

    def _around(self, rc: tuple[int, int]) -> list[tuple[int, int]]:
        """The cell and its offsets on finite cost (see ``robust_cells``)."""
        out = [rc]
        d = self._robust
        if d <= 0:
            return out
        h, w = self._cost.shape
        for dr, dc in ((d, 0), (-d, 0), (0, d), (0, -d)):
            r, c = rc[0] + dr, rc[1] + dc
            if 0 <= r < h and 0 <= c < w and np.isfinite(self._cost[r, c]):
                out.append((r, c))
        return out

    def _scan(self, cells: list[tuple[int, int]]) -> None:
        todo = [k for k in cells if k not in self._scans]
        if not todo:
            return
        vis = visible_sets(
            self._world,
            self._geo,
            np.array(todo, dtype=np.int64),
            self._sensor,
            self._mask,
            self._index,
        )
        for i, k in enumerate(todo):
            cols = vis.indices[vis.indptr[i] : vis.indptr[i + 1]]
            self._scans[k] = np.sort(cols).astype(np.int64)

    def path(self, a_rc: tuple[int, int], b_rc: tuple[int, int]) -> np.ndarray | None:
        """The cells of the leg from ``a_rc`` to ``b_rc`` in driving order: the least-cost path
        whose scans :meth:`leg` counts (one path per pair of ends, whichever way it is driven:
        where two ways cost about the same, a search from a cell beside ``a_rc`` may take the
        other, which sees other cells), or None when ``b_rc`` is unreachable."""
        a_rc, b_rc = (int(a_rc[0]), int(a_rc[1])), (int(b_rc[0]), int(b_rc[1]))
        key = (a_rc, b_rc) if a_rc <= b_rc else (b_rc, a_rc)
        if key not in self._paths:
            found = shortest_path_cells(self._cost, key[0], key[1])
            self._paths[key] = None if found is None else found[0]
        cells = self._paths[key]
        if cells is None or key[0] == a_rc:
            return cells
        return cells[::-1]

    def leg(self, a_rc: tuple[int, int], b_rc: tuple[int, int]) -> np.ndarray:
        """Sorted columns seen by the scans along the driven path from ``a_rc`` to ``b_rc``."""
        key = (a_rc, b_rc) if a_rc <= b_rc else (b_rc, a_rc)
        got = self._legs.get(key)
        if got is not None:
            return got
        cells = self.path(key[0], key[1])
        if cells is None or cells.shape[0] <= 2:
            seen = _EMPTY
        else:
            inner = cells[1:-1]
            samples = inner[self._step_cells // 2 :: self._step_cells]
            keys = [(int(r), int(c)) for r, c in samples]
            self._scan(keys)
            flags = np.zeros(self._n_cols, dtype=bool)
            for k in keys:
                flags[self._scans[k]] = True
            seen = np.flatnonzero(flags)
        self._legs[key] = seen
        return seen


class _CoverCount:
    """How many of the tour's scans (start, viewpoints, legs) see each column."""

    def __init__(self, n_cols: int, base: np.ndarray) -> None:
        self.count = np.zeros(n_cols, dtype=np.int32)
        self.count[np.flatnonzero(base)] += 1

    def add(self, cols: np.ndarray, sign: int) -> None:
        self.count[cols] += sign

    def covered(self) -> int:
        return int(np.count_nonzero(self.count))


def refine_tour(
    nodes_rc: np.ndarray,
    covered0: np.ndarray,
    required: int,
    legs: LegVisibility,
    candidates: tuple[np.ndarray, sparse.csr_matrix],
    solve_order: Callable[[np.ndarray], list[int]],
    geo_cost: np.ndarray | GeodesicFields,
    max_rounds: int = 4,
) -> tuple[np.ndarray, np.ndarray]:
    """Shorten the open tour ``nodes_rc`` (row 0: the start) keeping ``required`` columns seen.

    Args:
        nodes_rc: ``(K + 1, 2)`` start then viewpoints, in tour order.
        covered0: ``(M,)`` bool columns the start scan sees.
        required: Columns the tour must see (start, viewpoints and legs together).
        legs: The leg and viewpoint visibility.
        candidates: ``(N, 2)`` cells a viewpoint may move to, and ``(N, M)`` what each sees.
        solve_order: Open tour order (node 0 first) of a distance matrix (LKH).
        geo_cost: ``(H, W)`` cost for the tour's distances (metres per cell on the standing
            mask), or a :class:`GeodesicFields` over it whose kept fields are reused.
        max_rounds: Rounds of drop, move and re-solve at most.

    Returns:
        ``(K' + 1, 2)`` the refined tour, start first, and its ``(K' + 1, K' + 1)`` geodesic
        distances.
    """
    tour = [(int(r), int(c)) for r, c in np.asarray(nodes_rc, dtype=np.int64)]
    dist = _Distances(geo_cost)
    count = _CoverCount(covered0.size, covered0)
    for cols in legs.cells(np.array(tour[1:], dtype=np.int64).reshape(-1, 2)):
        count.add(cols, 1)
    for a, b in zip(tour[:-1], tour[1:], strict=True):
        count.add(legs.leg(a, b), 1)
    cand = np.asarray(candidates[0], dtype=np.int64).reshape(-1, 2)
    if count.covered() < required:  # robust views see less than the cover counted
        _fill(tour, count, required, legs, dist, (cand, candidates[1]))
        if count.covered() < required:
            return np.array(tour, dtype=np.int64), dist.matrix(tour).astype(np.float64)
    moves = (cand, candidates[1])
    for _ in range(max_rounds):
        before = dist.length(tour)
        _drop_pass(tour, count, required, legs, dist)
        _move_pass(tour, count, required, legs, dist, moves, _MOVE_TRIES)
        _resolve(tour, count, required, legs, dist, solve_order)
        if dist.length(tour) >= before - 1e-6:
            break
    return np.array(tour, dtype=np.int64), dist.matrix(tour).astype(np.float64)


class GeodesicFields:
    """Dijkstra distance fields (float64, metres) over one cell-cost grid, one per source cell,
    kept while ``budget_bytes`` allows: the cover, the distance matrix and the refinement all
    ask for the fields of the same viewpoints, and each costs a Dijkstra over the whole map.

    Args:
        cost: ``(H, W)`` cost of entering each cell (``inf`` off the standing mask).
        budget_bytes: Memory for the kept fields (at least 8 are kept whatever their size).
    """

    def __init__(self, cost: np.ndarray, budget_bytes: float = 256e6) -> None:
        self.cost = cost
        self._fields: dict[tuple[int, int], np.ndarray] = {}
        self._max = max(8, int(budget_bytes // max(1, cost.size * 8)))

    def kept(self, a: tuple[int, int]) -> np.ndarray | None:
        """The field from ``a`` if it was computed and kept, else None (computes nothing)."""
        return self._fields.get(a)

    def field(self, a: tuple[int, int]) -> np.ndarray:
        """The field from ``a`` (read-only: shared), kept when the budget allows."""
        got = self._fields.get(a)
        if got is None:
            got = distance_field(self.cost, a)[0]
            got.flags.writeable = False
            if len(self._fields) < self._max:
                self._fields[a] = got
        return got


class _Distances:
    """Geodesic distances between cells, one Dijkstra per source cell (cached as float32; the
    fields ``shared`` already holds are reused)."""

    def __init__(self, geo_cost: np.ndarray | GeodesicFields) -> None:
        self._shared = geo_cost if isinstance(geo_cost, GeodesicFields) else None
        self.cost = geo_cost.cost if isinstance(geo_cost, GeodesicFields) else geo_cost
        self._fields: dict[tuple[int, int], np.ndarray] = {}

    def field(self, a: tuple[int, int]) -> np.ndarray:
        got = self._fields.get(a)
        if got is None:
            if len(self._fields) >= _MAX_FIELDS:  # big maps: bounded memory
                self._fields.clear()
            known = self._shared.kept(a) if self._shared is not None else None
            full = known if known is not None else distance_field(self.cost, a)[0]
            got = full.astype(np.float32)
            self._fields[a] = got
        return got

    def d(self, a: tuple[int, int], b: tuple[int, int]) -> float:
        if b in self._fields and a not in self._fields:
            a, b = b, a
        return float(self.field(a)[b])

    def length(self, tour: list[tuple[int, int]]) -> float:
        return sum(self.d(a, b) for a, b in zip(tour[:-1], tour[1:], strict=True))

    def matrix(self, tour: list[tuple[int, int]]) -> np.ndarray:
        cells = np.array(tour, dtype=np.int64)
        out = np.array([self.field(a)[cells[:, 0], cells[:, 1]] for a in tour])
        out = np.minimum(out, out.T)
        np.fill_diagonal(out, 0.0)
        return out


def _swap(
    tour: list[tuple[int, int]],
    i: int,
    new: tuple[int, int] | None,
    count: _CoverCount,
    legs: LegVisibility,
) -> None:
    """Replace node ``i`` by ``new`` (None: remove it), updating ``count``."""
    prev, cur = tour[i - 1], tour[i]
    nxt = tour[i + 1] if i + 1 < len(tour) else None
    count.add(legs.cells(np.array([cur]))[0], -1)
    count.add(legs.leg(prev, cur), -1)
    if nxt is not None:
        count.add(legs.leg(cur, nxt), -1)
    if new is None:
        del tour[i]
        if nxt is not None:
            count.add(legs.leg(prev, nxt), 1)
        return
    tour[i] = new
    count.add(legs.cells(np.array([new]))[0], 1)
    count.add(legs.leg(prev, new), 1)
    if nxt is not None:
        count.add(legs.leg(new, nxt), 1)


def _saving(tour: list[tuple[int, int]], i: int, dist: _Distances) -> float:
    prev, cur = tour[i - 1], tour[i]
    if i + 1 == len(tour):
        return dist.d(prev, cur)
    nxt = tour[i + 1]
    return dist.d(prev, cur) + dist.d(cur, nxt) - dist.d(prev, nxt)


def _drop_pass(
    tour: list[tuple[int, int]],
    count: _CoverCount,
    required: int,
    legs: LegVisibility,
    dist: _Distances,
) -> None:
    """Remove each viewpoint (largest saving first) whose removal keeps the target seen."""
    order = sorted(tour[1:], key=lambda n: -_saving(tour, tour.index(n), dist))
    for node in order:
        i = tour.index(node)
        if _saving(tour, i, dist) <= 0.0:
            continue
        _swap(tour, i, None, count, legs)
        if count.covered() >= required:
            continue
        # Undo: put it back where it was.
        tour.insert(i, node)
        prev = tour[i - 1]
        nxt = tour[i + 1] if i + 1 < len(tour) else None
        if nxt is not None:
            count.add(legs.leg(prev, nxt), -1)
            count.add(legs.leg(node, nxt), 1)
        count.add(legs.leg(prev, node), 1)
        count.add(legs.cells(np.array([node]))[0], 1)


def _move_pass(
    tour: list[tuple[int, int]],
    count: _CoverCount,
    required: int,
    legs: LegVisibility,
    dist: _Distances,
    candidates: tuple[np.ndarray, sparse.csr_matrix],
    tries: int,
) -> None:
    """Move each viewpoint to the candidate of least detour that keeps the target seen.

    Only candidates that see enough of what the viewpoint alone sees (all but the tour's
    surplus over ``required``) are tried, least detour first, ``tries`` at most.
    """
    cand, sets = candidates
    unique_flags = np.zeros(sets.shape[1], dtype=bool)
    for i in range(1, len(tour)):
        prev, cur = tour[i - 1], tour[i]
        nxt = tour[i + 1] if i + 1 < len(tour) else None
        detour = dist.field(prev)[cand[:, 0], cand[:, 1]].astype(np.float64)
        if nxt is not None:
            detour = detour + dist.field(nxt)[cand[:, 0], cand[:, 1]]
        now = dist.d(prev, cur) + (dist.d(cur, nxt) if nxt is not None else 0.0)
        better = np.flatnonzero(detour < now - 0.05)
        if better.size == 0:
            continue
        own = legs.cells(np.array([cur]))[0]
        unique = own[count.count[own] == 1]
        need = unique.size - (count.covered() - required)
        if need > 0:
            unique_flags[unique] = True
            hits = row_counts(unique_flags, sets.indptr, sets.indices, better)
            unique_flags[unique] = False
            better = better[hits >= need]
        for k in better[np.argsort(detour[better], kind="stable")][:tries]:
            new = (int(cand[k, 0]), int(cand[k, 1]))
            if new in tour:
                continue
            _swap(tour, i, new, count, legs)
            if count.covered() >= required:
                break
            _swap(tour, i, cur, count, legs)


def _fill(
    tour: list[tuple[int, int]],
    count: _CoverCount,
    required: int,
    legs: LegVisibility,
    dist: _Distances,
    candidates: tuple[np.ndarray, sparse.csr_matrix],
    offset_m: float = 1.0,
) -> None:
    """Insert candidates (most unseen cells per metre of insertion, ``offset_m`` added to the
    metres) where they cost least, until ``required`` columns are seen or none adds any."""
    cand, sets = candidates
    to_cand = [dist.field(n)[cand[:, 0], cand[:, 1]].astype(np.float64) for n in tour]
    tried = np.zeros(cand.shape[0], dtype=bool)
    while count.covered() < required:
        gains = row_counts(count.count == 0, sets.indptr, sets.indices)
        ins, where = _insertion_costs(tour, to_cand, dist)
        score = np.where((gains > 0) & ~tried & np.isfinite(ins), gains / (ins + offset_m), -1.0)
        k = int(np.argmax(score))
        if score[k] <= 0.0:
            return
        tried[k] = True
        node = (int(cand[k, 0]), int(cand[k, 1]))
        if node in tour:
            continue
        pos = int(where[k]) + 1
        tour.insert(pos, node)
        to_cand.insert(pos, dist.field(node)[cand[:, 0], cand[:, 1]].astype(np.float64))
        count.add(legs.cells(np.array([node]))[0], 1)
        if pos + 1 < len(tour):
            count.add(legs.leg(tour[pos - 1], tour[pos + 1]), -1)
            count.add(legs.leg(node, tour[pos + 1]), 1)
        count.add(legs.leg(tour[pos - 1], node), 1)


def _insertion_costs(
    tour: list[tuple[int, int]], to_cand: list[np.ndarray], dist: _Distances
) -> tuple[np.ndarray, np.ndarray]:
    """Per candidate, the least extra length of inserting it into the open tour, and after
    which tour position."""
    best = to_cand[-1].copy()  # appended at the end
    where = np.full(best.shape, len(tour) - 1, dtype=np.int64)
    for p in range(len(tour) - 1):
        extra = to_cand[p] + to_cand[p + 1] - dist.d(tour[p], tour[p + 1])
        better = extra < best
        best[better] = extra[better]
        where[better] = p
    return best, where


def _resolve(
    tour: list[tuple[int, int]],
    count: _CoverCount,
    required: int,
    legs: LegVisibility,
    dist: _Distances,
    solve_order: Callable[[np.ndarray], list[int]],
) -> None:
    """Reorder by LKH; keep the new order when it is shorter and still sees the target."""
    if len(tour) <= 2:
        return
    order = solve_order(dist.matrix(tour))
    new = [tour[j] for j in order]
    if dist.length(new) >= dist.length(tour) - 1e-6:
        return
    old_legs = [legs.leg(a, b) for a, b in zip(tour[:-1], tour[1:], strict=True)]
    new_legs = [legs.leg(a, b) for a, b in zip(new[:-1], new[1:], strict=True)]
    for cols in old_legs:
        count.add(cols, -1)
    for cols in new_legs:
        count.add(cols, 1)
    if count.covered() >= required:
        tour[:] = new
        return
    for cols in new_legs:
        count.add(cols, -1)
    for cols in old_legs:
        count.add(cols, 1)


def tour_visible(legs: LegVisibility, tour_rc: np.ndarray, n_cols: int) -> sparse.csr_matrix:
    """``(K, n_cols)`` bool CSR: row ``j`` holds what viewpoint ``j + 1`` of ``tour_rc`` sees."""
    parts = legs.cells(np.asarray(tour_rc, dtype=np.int64)[1:])
    indptr = np.concatenate([[0], np.cumsum([p.size for p in parts])]).astype(np.int64)
    indices = np.concatenate(parts) if parts else _EMPTY
    return sparse.csr_matrix(
        (np.ones(indices.size, dtype=bool), indices, indptr), shape=(len(parts), n_cols)
    )


def predicted_drive_m(
    legs: LegVisibility,
    route_rc: np.ndarray,
    leg_lengths_m: np.ndarray,
    unseen: np.ndarray,
    need: int,
) -> tuple[bool, float, int]:
    """How far a route must be driven until its scans see ``need`` of the ``unseen`` columns.

    The route is driven leg by leg from ``route_rc[0]`` (where the robot is); what a leg's
    scans and the scan at its end see counts once the leg is driven, so the distance is that of
    the whole leg that completes the count (the same rounding for every route compared).

    Args:
        legs: The tour's leg and viewpoint visibility.
        route_rc: ``(K + 1, 2)`` the robot's cell, then the viewpoints in the order driven.
        leg_lengths_m: ``(K,)`` length of each leg.
        unseen: ``(M,)`` bool: the columns not seen yet.
        need: Columns still to see.

    Returns:
        ``(reached, distance_m, seen)``: whether the route sees ``need`` columns, the distance
        driven when it does (else its whole length) and how many it sees by then.
    """
    route = [(int(r), int(c)) for r, c in np.asarray(route_rc, dtype=np.int64).reshape(-1, 2)]
    todo = np.asarray(unseen, dtype=bool).copy()
    seen = 0
    driven = 0.0
    if need <= 0:
        return True, 0.0, 0
    ends = legs.cells(np.array(route[1:], dtype=np.int64).reshape(-1, 2)) if len(route) > 1 else []
    for i, (a, b) in enumerate(zip(route[:-1], route[1:], strict=True)):
        driven += float(leg_lengths_m[i])
        for cols in (legs.leg(a, b), ends[i]):
            new = cols[todo[cols]]
            todo[new] = False
            seen += int(new.size)
        if seen >= need:
            return True, driven, seen
    return False, driven, seen
