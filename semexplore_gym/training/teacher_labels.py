"""The oracle as a teacher: at a decision point, a label for every current frontier.

**Training code only.** The labels read the true world, the
:class:`~semexplore_gym.core.coverage_tour.PrivilegedWorld` that only an env made with
``privileged=True`` hands out (``info["privileged_world"]`` at reset). A student policy never
reads it: policies cannot import this module (``policies`` sits below ``training`` in the layer
order, ``tests/test_layers.py``), and the mission runners make a privileged env only for a
policy that declares ``privileged`` (the oracle). Training code builds an
:class:`OracleTeacher` from reset's ``info`` and asks it for labels on the student's own
states (DAgger); the student learns from the labels and the observation alone.

What a label says, given the robot's pose and the live map (``obs["map"]``):

1. **the re-optimised tour**: the candidate viewpoints (the oracle's lattice on the true
   standing mask) that see the reachable cells the map has not mapped FREE yet, chosen by the
   oracle's travel-aware greedy cover grown from the robot, ordered as an open LKH tour from
   the robot (:mod:`semexplore_gym.core.coverage_tour`);
2. **which frontier each viewpoint explores**: every still-unseen true free cell belongs to the
   frontier nearest it along true free space (one multi-source Dijkstra from the frontier
   cells); a viewpoint belongs to the frontier owning most of the unseen cells it sees;
3. ``cost_to_go_m[f]``: the length of the oracle's tour when it must head for frontier ``f``
   first: path to one of ``f``'s viewpoints (the best of the ``first_stops`` nearest the
   robot; for a frontier that owns no viewpoint, the standing cell nearest the frontier), then
   an open LKH tour from there through every other viewpoint; the re-optimised tour itself
   prices the frontier it starts with. Like the oracle's tour it is an upper bound on the best
   drive;
4. ``first``: the frontier with the smallest cost-to-go, the one the oracle heads for (the
   re-optimised tour's first frontier unless pricing found a shorter tour; ties: the lower
   index).

Lengths are metres of 8-connected grid path on the true standing mask (the oracle's metric).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numba import njit
from scipy import ndimage, sparse

from semexplore_gym.core.coverage_tour import (
    PRIVILEGED_INFO_KEY,
    PrivilegedWorld,
    TourParams,
    open_tour_order,
)
from semexplore_gym.core.coverage_tour.tour import require_solver
from semexplore_gym.core.coverage_tour.viewpoints import (
    candidate_viewpoints,
    nearest_allowed_cell,
    standing_mask,
    visible_sets,
    wall_clearance_m,
)
from semexplore_gym.core.frontiers.detection import detect_frontiers
from semexplore_gym.core.grid import FREE
from semexplore_gym.core.planning.grid_search import distance_field
from semexplore_gym.core.worlds.raster import rasterize_free

__all__ = ["FrontierLabels", "NotPrivilegedError", "OracleTeacher", "TeacherParams"]


class NotPrivilegedError(ValueError):
    """The teacher was given no true world (``info`` of an env made without ``privileged``)."""


@dataclass(frozen=True)
class TeacherParams:
    """Settings of :class:`OracleTeacher`.

    Attributes:
        tour: The oracle's viewpoint lattice, cover target and LKH restarts.
        min_frontier_cells: Frontier groups detected with fewer cells are ignored (when the
            caller passes no frontiers of its own).
        first_stops: A frontier's cost-to-go tries this many of its viewpoints nearest the
            robot as the first stop and keeps the shortest tour.
        pricing_lkh_runs: LKH restarts of each of those tours (the re-optimised tour itself
            uses ``tour.lkh_runs``); the labels' cost is mostly LKH.
    """

    tour: TourParams = field(default_factory=TourParams)
    min_frontier_cells: int = 3
    first_stops: int = 3
    pricing_lkh_runs: int = 1


@dataclass(frozen=True)
class FrontierLabels:
    """The teacher's labels at one decision point (see the module docstring).

    Attributes:
        frontier_cells: The frontiers labelled, each ``(K, 2)`` ``(row, col)`` map cells.
        first: Index of the frontier the oracle heads for (smallest cost-to-go); -1 when
            nothing is left to see or no frontier has a finite cost.
        cost_to_go_m: ``(F,)`` oracle tour length when heading for each frontier first.
        tour_length_m: Length of the re-optimised tour from the robot.
        tour_frontiers: Frontier index of each tour viewpoint, in tour order (-1: none).
        viewpoints_rc: ``(V, 2)`` the tour's viewpoints in tour order.
        unseen_cells: ``(F,)`` still-unseen reachable cells each frontier owns.
    """

    frontier_cells: tuple[np.ndarray, ...]
    first: int
    cost_to_go_m: np.ndarray
    tour_length_m: float
    tour_frontiers: np.ndarray
    viewpoints_rc: np.ndarray
    unseen_cells: np.ndarray

    @property
    def n_frontiers(self) -> int:
        return len(self.frontier_cells)


class OracleTeacher:
    """Labels frontiers from the true world of one episode (training code only).

    Build it from the ``info`` of a privileged env's ``reset`` (:meth:`from_reset_info`); the
    static part (standing mask, candidate viewpoints, what each sees) is computed once here.

    Args:
        facts: The episode's true world.
        params: :class:`TeacherParams`.

    Raises:
        NotPrivilegedError: ``facts`` is not a :class:`PrivilegedWorld`.
        ImportError: the tour solver (``elkai``) is missing.
    """

    def __init__(self, facts: PrivilegedWorld, params: TeacherParams | None = None) -> None:
        if not isinstance(facts, PrivilegedWorld):
            raise NotPrivilegedError(
                "the oracle's labels need the true world: make the training env with "
                "privileged=True and pass reset's info (info['privileged_world']); a student "
                "policy never gets it"
            )
        require_solver()
        self.facts = facts
        self.params = params if params is not None else TeacherParams()
        geo = facts.geometry
        self.geometry = geo
        prm = self.params.tour
        cap = max(prm.prefer_clearance_m, facts.clearance_m + geo.resolution_m)
        clearance = wall_clearance_m(facts.world, geo, cap)
        self.standing = standing_mask(
            facts.world, geo, facts.start_pose[:2], facts.clearance_m, clearance
        )
        spacing = max(1, int(round(prm.viewpoint_spacing_m / geo.resolution_m)))
        cand = candidate_viewpoints(self.standing, clearance, spacing)
        while cand.shape[0] > prm.max_candidates:
            spacing += max(1, spacing // 4)
            cand = candidate_viewpoints(self.standing, clearance, spacing)
        self.candidates_rc = cand
        mask = np.asarray(facts.reachable_mask, dtype=bool)
        self.mask_flat = np.flatnonzero(mask)
        self.visible: sparse.csr_matrix = visible_sets(facts.world, geo, cand, facts.sensor, mask)
        self.true_free = rasterize_free(facts.world, geo)
        self._geo_cost = np.where(self.standing, geo.resolution_m, np.inf)
        self._coverable = np.zeros(self.mask_flat.size, dtype=bool)
        self._coverable[self.visible.indices] = True
        # Geodesic distances between viewpoints are static: one Dijkstra per viewpoint, on the
        # standing mask's box, the first time a cover picks it.
        rows = np.flatnonzero(self.standing.any(axis=1))
        cols = np.flatnonzero(self.standing.any(axis=0))
        self._box = (int(rows[0]), int(rows[-1]) + 1, int(cols[0]), int(cols[-1]) + 1)
        self._rows: dict[int, np.ndarray] = {}

    @classmethod
    def from_reset_info(
        cls, info: dict[str, Any], params: TeacherParams | None = None
    ) -> OracleTeacher:
        """The teacher of the episode whose ``reset`` returned ``info`` (privileged env)."""
        return cls(info.get(PRIVILEGED_INFO_KEY), params)  # type: ignore[arg-type]

    # ------------------------------------------------------------------ labels
    def labels(
        self,
        obs: dict[str, np.ndarray],
        frontiers: Sequence[Any] | None = None,
    ) -> FrontierLabels:
        """Label each frontier at the state ``obs`` (its ``map`` and ``pose``).

        Args:
            obs: The env's observation at the decision point.
            frontiers: The frontiers the student chooses among, each a ``(K, 2)`` cell array
                or an object with ``.cells`` (a
                :class:`~semexplore_gym.core.frontiers.detection.GridFrontier`); default: every
                frontier reachable from the robot (free-cell convention, at least
                ``min_frontier_cells``).
        """
        grid = np.asarray(obs["map"])
        pose = np.asarray(obs["pose"], dtype=np.float64)
        if frontiers is None:
            frontiers = detect_frontiers(
                grid,
                self.geometry,
                pose[:2],
                min_frontier_cells=self.params.min_frontier_cells,
                cell_convention="free",
            )
        cells = tuple(
            np.asarray(getattr(f, "cells", f), dtype=np.int64).reshape(-1, 2) for f in frontiers
        )
        robot = self._robot_cell(pose)
        d_robot, _ = distance_field(self._geo_cost, robot)
        robot_row = d_robot[self.candidates_rc[:, 0], self.candidates_rc[:, 1]]
        unseen = grid.reshape(-1)[self.mask_flat] != FREE
        chosen = self._cover(unseen, robot_row)
        owner = self._owners(grid, cells)
        vp_owner = self._viewpoint_owners(chosen, unseen, owner)
        nodes = np.vstack([np.array([robot], dtype=np.int64), self.candidates_rc[chosen]])
        dist = self._node_distances(chosen, robot_row)
        order = open_tour_order(dist, self.params.tour.lkh_runs)
        tour = [i - 1 for i in order[1:]]
        length = float(sum(dist[a, b] for a, b in zip(order[:-1], order[1:], strict=False)))
        cost = np.array(
            [
                self._cost_to_go(f, cells[f], nodes, dist, vp_owner, d_robot)
                for f in range(len(cells))
            ]
        )
        if tour and vp_owner[tour[0]] >= 0:  # the tour itself heads for that frontier first
            f0 = int(vp_owner[tour[0]])
            cost[f0] = min(cost[f0], length)
        owned = owner.reshape(-1)[self.mask_flat[unseen]]
        return FrontierLabels(
            frontier_cells=cells,
            first=int(np.argmin(cost)) if tour and np.isfinite(cost).any() else -1,
            cost_to_go_m=cost,
            tour_length_m=length,
            tour_frontiers=np.array([vp_owner[i] for i in tour], dtype=np.int64),
            viewpoints_rc=self.candidates_rc[np.asarray(chosen, dtype=np.int64)[tour]]
            if tour
            else np.zeros((0, 2), dtype=np.int64),
            unseen_cells=np.bincount(owned[owned >= 0], minlength=len(cells))[: len(cells)],
        )

    def _robot_cell(self, pose: np.ndarray) -> tuple[int, int]:
        try:
            return nearest_allowed_cell(self.standing, self.geometry, pose[:2])
        except ValueError:  # off the standing mask (grazing a wall): the cell it is in
            r, c = (int(v) for v in self.geometry.world_to_grid(pose[0], pose[1]))
            return r, c

    def _row(self, i: int) -> np.ndarray:
        """Geodesic distances from viewpoint ``i`` to every viewpoint (cached)."""
        row = self._rows.get(i)
        if row is None:
            r0, r1, c0, c1 = self._box
            cand = self.candidates_rc
            d, _ = distance_field(
                self._geo_cost[r0:r1, c0:c1], (int(cand[i, 0]) - r0, int(cand[i, 1]) - c0)
            )
            row = d[cand[:, 0] - r0, cand[:, 1] - c0]
            self._rows[i] = row
        return row

    def _node_distances(self, chosen: list[int], robot_row: np.ndarray) -> np.ndarray:
        """Geodesic matrix of the robot (node 0) and the ``chosen`` viewpoints."""
        k = len(chosen)
        out = np.zeros((k + 1, k + 1))
        out[0, 1:] = out[1:, 0] = robot_row[chosen]
        for a, i in enumerate(chosen):
            out[a + 1, 1:] = self._row(i)[chosen]
        out = np.minimum(out, out.T)
        np.fill_diagonal(out, 0.0)
        return out

    def _cover(self, unseen: np.ndarray, robot_row: np.ndarray) -> list[int]:
        """Viewpoints that see the cover target of the reachable cells (seen ones count).

        The rule of :func:`~semexplore_gym.core.coverage_tour.tour.travel_aware_cover` (most
        unseen cells per ``detour_m`` + path from the nearest point chosen so far, the robot
        first), with the viewpoints' distances cached and only the viewpoints that see an
        unseen cell considered.
        """
        seen = ~unseen
        n = max(1, self.mask_flat.size)
        required = min(
            int(math.ceil(self.params.tour.coverage_target * n)),
            int((seen | self._coverable).sum()),
        )
        n_cov = int(seen.sum())
        if n_cov >= required:
            return []
        # Only viewpoints within sensor range of an unseen cell can see one.
        geo = self.geometry
        unseen_grid = np.zeros(geo.height * geo.width, dtype=bool)
        unseen_grid[self.mask_flat[unseen]] = True
        far = ndimage.distance_transform_edt(~unseen_grid.reshape(geo.shape)) * geo.resolution_m
        cand = self.candidates_rc
        live = np.flatnonzero(far[cand[:, 0], cand[:, 1]] <= self.facts.sensor.max_range_m + 0.1)
        indptr, indices = self.visible.indptr, self.visible.indices
        gain_ub = _row_gains(indptr, indices, live, unseen).astype(np.float64)
        keep = gain_ub > 0
        live, gain_ub = live[keep], gain_ub[keep]
        cov = seen.copy()
        dist = robot_row[live].astype(np.float64)
        detour = max(self.params.tour.detour_m, 1e-6)
        taken = np.zeros(live.size, dtype=bool)
        chosen: list[int] = []
        while n_cov < required:
            bound = np.where(taken | ~np.isfinite(dist), -1.0, gain_ub / (dist + detour))
            best, best_val, best_gain = -1, 0.0, 0
            for i in np.argsort(-bound, kind="stable"):
                if bound[i] <= best_val:
                    break
                g = int(_row_gains(indptr, indices, live[i : i + 1], ~cov)[0])
                gain_ub[i] = g
                if g / (dist[i] + detour) > best_val:
                    best, best_val, best_gain = int(i), g / (dist[i] + detour), g
            if best < 0:
                break
            chosen.append(int(live[best]))
            taken[best] = True
            k = int(live[best])
            cov[indices[indptr[k] : indptr[k + 1]]] = True
            n_cov += best_gain
            np.minimum(dist, self._row(int(live[best]))[live], out=dist)
        return chosen

    def _owners(self, grid: np.ndarray, cells: tuple[np.ndarray, ...]) -> np.ndarray:
        """Per map cell, the frontier nearest along true free space (-1: none reaches it)."""
        h, w = grid.shape
        owner = np.full(h * w, -1, dtype=np.int64)
        if not cells or not any(c.size for c in cells):
            return owner.reshape(h, w)
        src = np.vstack([c for c in cells if c.size])
        label = np.concatenate([np.full(len(c), f, dtype=np.int64) for f, c in enumerate(cells)])
        cost = np.where(self.true_free, self.geometry.resolution_m, np.inf)
        dist, parent = distance_field(cost, src)
        reached = np.isfinite(dist.reshape(-1))
        par = parent.reshape(-1)
        root = np.where(par >= 0, par, np.arange(h * w, dtype=np.int64))
        while True:  # pointer jumping up to the source each cell was reached from
            nxt = root[root]
            if np.array_equal(nxt, root):
                break
            root = nxt
        src_flat = src[:, 0] * w + src[:, 1]
        # a cell that is the source of two frontiers keeps the first
        first_label = {int(k): int(f) for k, f in zip(src_flat[::-1], label[::-1], strict=True)}
        lut = np.full(h * w, -1, dtype=np.int64)
        lut[list(first_label)] = list(first_label.values())
        owner[reached] = lut[root[reached]]
        return owner.reshape(h, w)

    def _viewpoint_owners(
        self, chosen: list[int], unseen: np.ndarray, owner: np.ndarray
    ) -> np.ndarray:
        """The frontier owning most of the unseen cells each chosen viewpoint sees."""
        cell_owner = owner.reshape(-1)[self.mask_flat]
        out = np.full(len(chosen), -1, dtype=np.int64)
        for k, i in enumerate(chosen):
            cols = self.visible.indices[self.visible.indptr[i] : self.visible.indptr[i + 1]]
            o = cell_owner[cols[unseen[cols]]]
            o = o[o >= 0]
            if o.size:
                out[k] = int(np.bincount(o).argmax())
        return out

    def _cost_to_go(
        self,
        f: int,
        cells: np.ndarray,
        nodes: np.ndarray,
        dist: np.ndarray,
        vp_owner: np.ndarray,
        d_robot: np.ndarray,
    ) -> float:
        """Tour length from the robot when frontier ``f`` is headed for first (``nodes``: the
        robot's cell, then the viewpoints; ``dist``: their geodesic matrix)."""
        mine = np.flatnonzero(vp_owner == f) + 1  # node indices in ``dist``
        if mine.size:
            # The best of the frontier's few viewpoints nearest the robot as the first stop.
            firsts = mine[np.argsort(dist[0, mine], kind="stable")[: self.params.first_stops]]
            return min(self._tour_via(int(i), dist) for i in firsts)
        # No viewpoint of its own: drive to the frontier, then tour every viewpoint from there.
        entry = self._entry_cell(cells, d_robot)
        if entry is None:
            return math.inf
        d_entry, _ = distance_field(self._geo_cost, entry)
        head = float(d_robot[entry])
        sub = dist.copy()
        sub[0, 1:] = sub[1:, 0] = d_entry[nodes[1:, 0], nodes[1:, 1]]
        if not math.isfinite(head):
            return math.inf
        if sub.shape[0] <= 1:
            return head
        order = open_tour_order(sub, self.params.pricing_lkh_runs)
        return head + float(sum(sub[a, b] for a, b in zip(order[:-1], order[1:], strict=False)))

    def _tour_via(self, first: int, dist: np.ndarray) -> float:
        """Robot -> node ``first`` -> an open LKH tour through every other viewpoint."""
        head = float(dist[0, first])
        rest = [i for i in range(1, dist.shape[0]) if i != first]
        if not math.isfinite(head) or not rest:
            return head
        sub = dist[np.ix_([first, *rest], [first, *rest])]
        order = open_tour_order(sub, self.params.pricing_lkh_runs)
        return head + float(sum(sub[a, b] for a, b in zip(order[:-1], order[1:], strict=False)))

    def _entry_cell(self, cells: np.ndarray, d: np.ndarray) -> tuple[int, int] | None:
        """The standing cell nearest the robot (path ``d``) within 0.3 m of the frontier."""
        if cells.size == 0:
            return None
        near = np.zeros_like(self.standing)
        r = max(1, int(round(0.3 / self.geometry.resolution_m)))
        h, w = near.shape
        for row, col in cells:
            near[max(0, row - r) : min(h, row + r + 1), max(0, col - r) : min(w, col + r + 1)] = (
                True
            )
        ok = near & self.standing & np.isfinite(d)
        if not ok.any():
            return None
        row, col = divmod(int(np.argmin(np.where(ok, d, np.inf))), w)
        return row, col


@njit(cache=True)
def _row_gains(indptr, indices, rows, flags):  # pragma: no cover - numba
    """Per row of ``rows``, how many of its CSR columns are set in ``flags``."""
    out = np.zeros(rows.size, dtype=np.int64)
    for k in range(rows.size):
        r = rows[k]
        n = 0
        for j in range(indptr[r], indptr[r + 1]):
            if flags[indices[j]]:
                n += 1
        out[k] = n
    return out
