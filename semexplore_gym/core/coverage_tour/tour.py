"""A full-knowledge coverage tour: a set cover of viewpoints, ordered as an open tour.

:func:`plan_coverage_tour` solves the static problem on the true map of a
:class:`~semexplore_gym.core.coverage_tour.problem.PrivilegedWorld`:

1. candidate viewpoints on the standing mask (:mod:`.viewpoints`), and each one's visible
   cells of the env's reachable mask with the env's LiDAR model;
2. a **greedy set cover** (:func:`greedy_cover`) of ``coverage_target`` (99.3 %) of the
   reachable mask, counting what the first scan at the start already sees. Greedy picks at
   most ``H(max set size) <= 1 + ln(max set size)`` times the fewest viewpoints possible
   (Chvatal 1979); we take it for speed and determinism (an ILP would be exact on small maps);
3. **geodesic distances** between the chosen viewpoints and the start: 8-connected shortest
   paths over the standing mask (:func:`geodesic_matrix`, the project's grid Dijkstra);
4. an **open tour** from the start through every viewpoint (:func:`open_tour_order`): LKH
   (Helsgaun's Lin-Kernighan heuristic, through the ``elkai`` package; optional extra
   ``oracle``) on the distance matrix with a dummy node between the path's end and the start
   (see :func:`open_tour_order`), so the closed tour through it is the open path. LKH with a fixed seed is deterministic;
5. **cover and order together** (:func:`~.refine.refine_tour`): the scans along the legs
   count too; viewpoints are dropped and moved and the order re-solved while the tour shortens.

The tour length is an upper bound on the shortest drive that sees the target share with this
sensor model: set cover and TSP are both solved approximately, and the viewpoints are limited to
a lattice. Where the optimum is known (``tests/core/coverage_tour/test_tour.py``, LiDAR range
1 m) it is close: an 8 m corridor, 6.72 m against 6.70 m; a tree of three corridors, 11.80 m
against 12.0 m for the best open tour (the closed one is 15.0 m; the cover may leave 0.7 % of
the cells unseen, hence a little below). It ignores turning
time and the robot's motion limits, so ``time_at_top_speed_s`` is a lower bound on driving it.
"""

from __future__ import annotations

import heapq
import math
from dataclasses import dataclass, field

import numpy as np
from scipy import sparse

from semexplore_gym.core.coverage_tour.problem import PrivilegedWorld
from semexplore_gym.core.coverage_tour.refine import (
    GeodesicFields,
    LegVisibility,
    refine_tour,
    tour_visible,
)
from semexplore_gym.core.coverage_tour.viewpoints import (
    candidate_viewpoints,
    nearest_allowed_cell,
    row_counts,
    standing_mask,
    visible_sets,
    wall_clearance_m,
)
from semexplore_gym.core.grid import GridGeometry
from semexplore_gym.core.mapping.raycast import SegmentIndex
from semexplore_gym.core.planning.grid_search import distance_field

#: What to install when the tour solver is missing.
SOLVER_HINT = "the oracle's tour solver needs elkai (LKH): pip install 'semexplore-gym[oracle]' or pip install elkai"


@dataclass(frozen=True)
class TourParams:
    """Settings of :func:`plan_coverage_tour`.

    Attributes:
        coverage_target: Share of the reachable mask the tour must see, counting the scans
            along its legs (the cells no candidate sees at all are left out, which the result
            reports). The env's goal (0.99) plus 0.3 % for what the driven robot sees less than
            the plan: it cuts corners and passes near, not on, the viewpoints; its live map
            makes up any shortfall (see the oracle policy).
        viewpoint_spacing_m: Side of the blocks holding one candidate viewpoint each.
        prefer_clearance_m: Clearance cap of the candidate score (beyond it all cells tie).
        lkh_runs: LKH restarts.
        detour_m: The cover's cost offset (:func:`travel_aware_cover`); 0 = plain greedy.
        max_candidates: On bigger maps the lattice is coarsened until it has at most this many
            candidates (memory: each holds up to ``pi R^2`` visible cells).
        refine_rounds: Rounds of :func:`~.refine.refine_tour` (leg scans counted, viewpoints
            dropped and moved, order re-solved); 0 keeps the plain cover and its LKH order.
        leg_sample_m: Spacing of the scans counted along each leg.
        leg_prefer_clearance_m: The legs are the paths the oracle drives: least cost where a
            cell nearer a wall than this costs up to ...
        leg_wall_cost: ... this much more per metre (the oracle policy's path cost).
        robust_cells: The refined tour counts a cell seen from a pose only when the scans from
            the four cells this far aside see it too (:class:`~.refine.LegVisibility`).
    """

    coverage_target: float = 0.993
    viewpoint_spacing_m: float = 0.3
    prefer_clearance_m: float = 0.6
    lkh_runs: int = 3
    detour_m: float = 2.0
    max_candidates: int = 6000
    refine_rounds: int = 4
    leg_sample_m: float = 0.25
    leg_prefer_clearance_m: float = 0.2
    leg_wall_cost: float = 4.0
    robust_cells: int = 2

    def __post_init__(self) -> None:
        if not 0.0 < self.coverage_target <= 1.0:
            raise ValueError(
                f"TourParams.coverage_target must be in (0, 1], got {self.coverage_target!r}"
            )
        if not (math.isfinite(self.viewpoint_spacing_m) and self.viewpoint_spacing_m > 0):
            raise ValueError(
                f"TourParams.viewpoint_spacing_m must be positive, got {self.viewpoint_spacing_m!r}"
            )
        if not (math.isfinite(self.prefer_clearance_m) and self.prefer_clearance_m > 0):
            raise ValueError(
                f"TourParams.prefer_clearance_m must be positive, got {self.prefer_clearance_m!r}"
            )
        if not (math.isfinite(self.detour_m) and self.detour_m >= 0):
            raise ValueError(f"TourParams.detour_m must be >= 0, got {self.detour_m!r}")
        if not (isinstance(self.max_candidates, int) and self.max_candidates >= 1):
            raise ValueError(
                f"TourParams.max_candidates must be an integer >= 1, got {self.max_candidates!r}"
            )
        if not (isinstance(self.refine_rounds, int) and self.refine_rounds >= 0):
            raise ValueError(
                f"TourParams.refine_rounds must be an integer >= 0, got {self.refine_rounds!r}"
            )
        for name in ("leg_sample_m", "leg_prefer_clearance_m"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0):
                raise ValueError(f"TourParams.{name} must be positive, got {value!r}")
        if not (math.isfinite(self.leg_wall_cost) and self.leg_wall_cost >= 0):
            raise ValueError(f"TourParams.leg_wall_cost must be >= 0, got {self.leg_wall_cost!r}")
        if not (isinstance(self.robust_cells, int) and self.robust_cells >= 0):
            raise ValueError(
                f"TourParams.robust_cells must be an integer >= 0, got {self.robust_cells!r}"
            )
        if not (isinstance(self.lkh_runs, int) and self.lkh_runs >= 1):
            raise ValueError(f"TourParams.lkh_runs must be an integer >= 1, got {self.lkh_runs!r}")


@dataclass
class CoverageTour:
    """A static coverage tour and what it needs to be replanned (see :func:`plan_coverage_tour`).

    Attributes:
        viewpoints_rc: ``(K, 2)`` viewpoint cells in tour order (the start excluded).
        viewpoints_xy_m: Their centres in metres.
        leg_lengths_m: ``(K,)`` geodesic length of each leg (start -> first, ...).
        length_m: Total length of the open tour.
        covered_share: Share of the reachable mask the start scan and the viewpoints see.
        coverable_share: Share any candidate (or the start) sees at all.
        n_candidates: Candidate viewpoints considered.
        standing: The standing mask (where paths go).
        mask_flat: Flat indices of the reachable mask (the columns of ``visible``).
        visible: ``(K, M)`` visible cells of each tour viewpoint, rows in tour order.
        distances_m: ``(K, K)`` geodesic distances between the tour viewpoints.
        candidates_rc: ``(N, 2)`` all candidate viewpoints (for replanning).
        seen: ``(M,)`` bool: the columns the start scan, the viewpoints and the legs see.
        candidate_visible: ``(N, M)`` what one scan from each candidate sees (for shortcuts).
        legs: What the scans along a driven leg see (cached; for judging a replanned rest of
            the tour, :func:`~.refine.predicted_drive_m`).
    """

    viewpoints_rc: np.ndarray
    viewpoints_xy_m: np.ndarray
    leg_lengths_m: np.ndarray
    length_m: float
    covered_share: float
    coverable_share: float
    n_candidates: int
    standing: np.ndarray = field(repr=False)
    mask_flat: np.ndarray = field(repr=False)
    visible: sparse.csr_matrix = field(repr=False)
    distances_m: np.ndarray = field(repr=False)
    candidates_rc: np.ndarray = field(
        repr=False, default_factory=lambda: np.zeros((0, 2), np.int64)
    )
    seen: np.ndarray = field(repr=False, default_factory=lambda: np.zeros(0, dtype=bool))
    candidate_visible: sparse.csr_matrix | None = field(repr=False, default=None)
    legs: LegVisibility | None = field(repr=False, default=None)

    @property
    def n_viewpoints(self) -> int:
        return int(self.viewpoints_rc.shape[0])


def greedy_cover(
    visible: sparse.csr_matrix, required: int, covered: np.ndarray | None = None
) -> list[int]:
    """Rows of ``visible`` that together with ``covered`` see at least ``required`` columns.

    Lazy greedy: each step takes the row that sees the most uncovered columns (ties: the
    lowest row), until ``required`` are covered or no row adds any.

    Args:
        visible: ``(N, M)`` bool CSR matrix.
        required: Columns to cover in all (counting ``covered``).
        covered: ``(M,)`` bool columns covered already (default none).

    Returns:
        The chosen rows, in the order chosen.
    """
    n, m = visible.shape
    cov = np.zeros(m, dtype=bool) if covered is None else np.asarray(covered, dtype=bool).copy()
    n_cov = int(cov.sum())
    indptr, indices = visible.indptr, visible.indices
    gains = row_counts(~cov, indptr, indices)
    heap = [(-int(g), i) for i, g in enumerate(gains) if g > 0]
    heapq.heapify(heap)
    chosen: list[int] = []
    while heap and n_cov < required:
        neg, i = heapq.heappop(heap)
        cols = indices[indptr[i] : indptr[i + 1]]
        g = int((~cov[cols]).sum())
        if g == 0:
            continue
        if heap and g < -heap[0][0] or (heap and g == -heap[0][0] and heap[0][1] < i):
            heapq.heappush(heap, (-g, i))  # stale gain: re-queue with the fresh one
            continue
        chosen.append(i)
        cov[cols] = True
        n_cov += g
    return chosen


def travel_aware_cover(
    visible: sparse.csr_matrix,
    required: int,
    covered: np.ndarray,
    cells_rc: np.ndarray,
    fields: GeodesicFields,
    start_rc: tuple[int, int],
    detour_m: float,
) -> list[int]:
    """Greedy cover by cells per metre: each step takes the row with the most uncovered columns
    per ``detour_m`` + path length from the nearest point chosen so far (the start first).
    Path lengths are ``fields``' (metres per cell on the standing mask); the fields of the
    start and of every chosen cell stay there for the tour's distance matrix.

    Plain greedy (:func:`greedy_cover`) reaches deep into every dead end for the last cells; this
    grows the chosen set outward from the start, which keeps the tour through it short. Lazy:
    gains only shrink and distances are exact each step, so a row's bound is its last gain over
    its current distance.
    """
    n = visible.shape[0]
    cov = np.asarray(covered, dtype=bool).copy()
    n_cov = int(cov.sum())
    indptr, indices = visible.indptr, visible.indices
    gain_ub = row_counts(~cov, indptr, indices).astype(np.float64)
    dist = fields.field((int(start_rc[0]), int(start_rc[1]))).copy()
    cells = np.asarray(cells_rc, dtype=np.int64)
    chosen: list[int] = []
    taken = np.zeros(n, dtype=bool)
    while n_cov < required:
        d = dist[cells[:, 0], cells[:, 1]]
        bound = np.where(taken | ~np.isfinite(d), -1.0, gain_ub / (d + detour_m))
        order = np.argsort(-bound, kind="stable")
        best, best_val, best_gain = -1, 0.0, 0
        for i in order:
            if bound[i] <= best_val:
                break
            cols = indices[indptr[i] : indptr[i + 1]]
            g = int((~cov[cols]).sum())
            gain_ub[i] = g
            val = g / (d[i] + detour_m)
            if val > best_val:
                best, best_val, best_gain = int(i), val, g
        if best < 0:
            break
        chosen.append(best)
        taken[best] = True
        cov[indices[indptr[best] : indptr[best + 1]]] = True
        n_cov += best_gain
        np.minimum(dist, fields.field((int(cells[best, 0]), int(cells[best, 1]))), out=dist)
    return chosen


def geodesic_matrix(
    standing: np.ndarray,
    geometry: GridGeometry,
    cells_rc: np.ndarray,
    fields: GeodesicFields | None = None,
) -> np.ndarray:
    """8-connected path lengths in metres between ``cells_rc`` over ``standing``.

    Each cell is a source of one Dijkstra on the standing mask's bounding box (a source may lie
    outside the mask: the start's own cell), unless ``fields`` (over the same standing mask at
    ``geometry``'s resolution) kept its field already. Unreachable pairs are ``inf``.
    """
    cells = np.asarray(cells_rc, dtype=np.int64).reshape(-1, 2)
    rows = np.flatnonzero(standing.any(axis=1))
    cols = np.flatnonzero(standing.any(axis=0))
    r0 = max(0, min(int(rows[0]), int(cells[:, 0].min())) - 1)
    r1 = min(standing.shape[0], max(int(rows[-1]), int(cells[:, 0].max())) + 2)
    c0 = max(0, min(int(cols[0]), int(cells[:, 1].min())) - 1)
    c1 = min(standing.shape[1], max(int(cols[-1]), int(cells[:, 1].max())) + 2)
    cost = np.where(standing[r0:r1, c0:c1], geometry.resolution_m, np.inf)
    local = cells - np.array([r0, c0])
    k = cells.shape[0]
    out = np.full((k, k), np.inf)
    for i in range(k):
        known = fields.kept((int(cells[i, 0]), int(cells[i, 1]))) if fields is not None else None
        if known is not None:
            out[i] = known[cells[:, 0], cells[:, 1]]
            continue
        dist, _ = distance_field(cost, (int(local[i, 0]), int(local[i, 1])))
        out[i] = dist[local[:, 0], local[:, 1]]
    out = np.minimum(out, out.T)  # the start's cell may sit outside the mask: use the way in
    np.fill_diagonal(out, 0.0)
    return out


def require_solver() -> None:
    """Raise ImportError (saying how to install it) when the tour solver is missing."""
    _elkai()


def _elkai() -> object:
    try:
        import elkai
    except ImportError:
        raise ImportError(SOLVER_HINT) from None
    return elkai


def open_tour_order(distances_m: np.ndarray, runs: int = 3) -> list[int]:
    """An open path from node 0 through every node, short by LKH (through ``elkai``).

    A dummy node closes the path into a tour (0 from node 0, the same large constant from every
    other node, so the tour enters node 0 from it); distances go to LKH as integer millimetres
    (LKH's weights are integers). Unreachable pairs get a large finite cost.

    Returns:
        Node indices in visiting order, starting with 0.
    """
    d = np.asarray(distances_m, dtype=np.float64)
    k = d.shape[0]
    if k <= 2:
        return list(range(k))
    finite = d[np.isfinite(d)]
    big = 10.0 * (float(finite.max()) + 1.0) * k
    mm = np.rint(np.where(np.isfinite(d), d, big) * 1000.0).astype(np.int64)
    # The dummy is 0 from node 0 and a constant M from every other node: every tour through
    # the edge (dummy, 0) pays M once, any other pays it twice, so node 0 is an end of the path.
    full = np.zeros((k + 1, k + 1), dtype=np.int64)
    full[:k, :k] = mm
    m_const = int(mm.max()) * (k + 1) + 1
    full[k, 1:k] = full[1:k, k] = m_const
    elkai = _elkai()
    cycle = elkai.DistanceMatrix(full.tolist()).solve_tsp(runs=int(runs))  # type: ignore[attr-defined]
    cycle = [int(v) for v in cycle[:-1]]
    i = cycle.index(0)
    order = cycle[i:] + cycle[:i]
    if order[1] == k:  # the dummy follows 0: walk the other way round
        order = [0, *reversed(order[1:])]
    return [v for v in order if v != k]


def plan_coverage_tour(facts: PrivilegedWorld, params: TourParams | None = None) -> CoverageTour:
    """Plan the static coverage tour of ``facts`` (see the module docstring).

    Raises:
        ValueError: the start is not reachable (no standing cell next to it).
        ImportError: ``elkai`` is not installed (the message says how to install it).
    """
    prm = params if params is not None else TourParams()
    _elkai()  # fail early, before the expensive part
    geo = facts.geometry
    res = geo.resolution_m
    cap = max(prm.prefer_clearance_m, facts.clearance_m + res)
    clearance = wall_clearance_m(facts.world, geo, cap)
    standing = standing_mask(facts.world, geo, facts.start_pose[:2], facts.clearance_m, clearance)
    mask = np.asarray(facts.reachable_mask, dtype=bool)
    mask_flat = np.flatnonzero(mask)
    index = SegmentIndex(facts.world.segments_m)
    spacing = max(1, int(round(prm.viewpoint_spacing_m / res)))
    candidates = candidate_viewpoints(standing, clearance, spacing)
    while candidates.shape[0] > prm.max_candidates:  # big maps: a coarser lattice
        spacing += max(1, spacing // 4)
        candidates = candidate_viewpoints(standing, clearance, spacing)
    start_rc = nearest_allowed_cell(standing, geo, facts.start_pose[:2])
    seen_start = visible_sets(facts.world, geo, np.array([start_rc]), facts.sensor, mask, index)
    vis = visible_sets(facts.world, geo, candidates, facts.sensor, mask, index)
    covered0 = np.zeros(mask_flat.size, dtype=bool)
    covered0[seen_start.indices] = True
    coverable = covered0.copy()
    coverable[vis.indices] = True
    n_mask = max(1, mask_flat.size)
    required = min(int(math.ceil(prm.coverage_target * n_mask)), int(coverable.sum()))
    legs = LegVisibility(
        facts.world,
        geo,
        facts.sensor,
        mask,
        _drive_cost(standing, clearance, res, prm),
        prm.leg_sample_m,
        index,
        prm.robust_cells,
    )
    fields = GeodesicFields(np.where(standing, res, np.inf))
    nodes, dist = _cover_then_order(vis, required, covered0, candidates, fields, start_rc, geo, prm)
    if prm.refine_rounds > 0 and nodes.shape[0] > 1:
        nodes, dist = refine_tour(
            nodes,
            covered0,
            required,
            legs,
            (candidates, vis),
            lambda d: open_tour_order(d, prm.lkh_runs),
            fields,
            prm.refine_rounds,
        )
    k = nodes.shape[0]
    legs_m = np.asarray(dist[np.arange(k - 1), np.arange(1, k)], dtype=np.float64)
    cells = nodes[1:]
    sel, covered = _tour_seen(legs, nodes, covered0)
    xs, ys = geo.grid_to_world(cells[:, 0], cells[:, 1])
    return CoverageTour(
        viewpoints_rc=cells,
        viewpoints_xy_m=np.column_stack([xs, ys]).astype(np.float64).reshape(-1, 2),
        leg_lengths_m=legs_m,
        length_m=float(legs_m.sum()),
        covered_share=float(covered.sum() / n_mask),
        coverable_share=float(coverable.sum() / n_mask),
        n_candidates=int(candidates.shape[0]),
        standing=standing,
        mask_flat=mask_flat,
        visible=sel.tocsr(),
        distances_m=dist[1:, 1:],
        candidates_rc=candidates,
        seen=covered,
        candidate_visible=vis,
        legs=legs,
    )


def _drive_cost(
    standing: np.ndarray, clearance: np.ndarray, resolution_m: float, prm: TourParams
) -> np.ndarray:
    """Cost per cell of the paths the oracle drives: wall-averse within the preferred clearance."""
    pref = np.clip(1.0 - clearance / prm.leg_prefer_clearance_m, 0.0, 1.0)
    return np.where(standing, resolution_m * (1.0 + prm.leg_wall_cost * pref), np.inf)


def _cover_then_order(
    vis: sparse.csr_matrix,
    required: int,
    covered0: np.ndarray,
    candidates: np.ndarray,
    fields: GeodesicFields,
    start_rc: tuple[int, int],
    geo: GridGeometry,
    prm: TourParams,
) -> tuple[np.ndarray, np.ndarray]:
    """The plain tour: a (travel-aware) cover of the viewpoints alone, ordered by LKH."""
    if prm.detour_m > 0:
        chosen = travel_aware_cover(
            vis, required, covered0, candidates, fields, start_rc, prm.detour_m
        )
    else:
        chosen = greedy_cover(vis, required, covered0)
    nodes = np.vstack([np.array([start_rc], dtype=np.int64), candidates[chosen]])
    dist = geodesic_matrix(np.isfinite(fields.cost), geo, nodes, fields)
    order = open_tour_order(dist, prm.lkh_runs)
    return nodes[order], dist[np.ix_(order, order)]


def _tour_seen(
    legs: LegVisibility, nodes: np.ndarray, covered0: np.ndarray
) -> tuple[sparse.csr_matrix, np.ndarray]:
    """What each viewpoint of the tour ``nodes`` (start first) sees, and all the tour sees
    (start scan, viewpoints, legs)."""
    sel = tour_visible(legs, nodes, covered0.size)
    covered = covered0.copy()
    covered[sel.indices] = True
    for a, b in zip(nodes[:-1], nodes[1:], strict=True):
        covered[legs.leg((int(a[0]), int(a[1])), (int(b[0]), int(b[1])))] = True
    return sel, covered
