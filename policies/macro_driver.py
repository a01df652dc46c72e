"""The semantic expert as a low-level driver for macro-action agents.

:class:`ExpertDriver` is the scripted :class:`~policies.semantic_expert.SemanticExpertPolicy`
with two outside hooks, so that a learning agent makes the high-level choice and the expert's
navigation stack (potential field, entry detours, local-minimum escape, stuck recovery,
blacklisting, grid fallback) does the driving:

* :meth:`ExpertDriver.command_goal` makes the expert pursue one given frontier candidate instead of
  its own ``argmin C``; :attr:`ExpertDriver.goal_finished` turns True once that frontier is
  reached, has vanished (mapped), was blacklisted, or is no longer among the candidates.
* :meth:`ExpertDriver.set_cost_weights` changes ``w_v``, ``w_p``, ``w_I`` and replans at once.

:meth:`ExpertDriver.frontier_candidates` runs the pose identification and Algorithm 1 on an
observation and returns the scored candidates (cheapest first), without changing the plan.

The wrappers in :mod:`semexplore_gym.wrappers.frontier_choice` use this class through their
``FrontierDriver`` protocol; they never import it (wrappers sit below policies in the layering),
the env-id entry points in :mod:`semexplore_gym.macro_envs` join the two.

The hooks override the expert's goal-commitment and replan-reason steps (``_commit``,
``_replan_reason``); a change of those internals must keep this class working (its tests cover it).
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Any

import numpy as np

from policies.semantic_expert import Segmenter, SemanticExpertParams, SemanticExpertPolicy
from semexplore_gym.core.planning.graph_search import (
    FrontierCandidate,
    FrontierCostWeights,
    search_frontier_paths,
)

_GOAL_DONE_REASONS = ("goal_reached", "goal_vanished", "path_done")


class ExpertDriver(SemanticExpertPolicy):
    """The semantic expert driven by an outside goal choice or outside cost weights.

    Args:
        params: Expert parameters (default: the paper's).
        segmenter: See :class:`~policies.semantic_expert.SemanticExpertPolicy`.

    Attributes:
        goal_finished: The commanded goal is done (reached, vanished, blacklisted or gone);
            the expert keeps driving with its own choice until the next command.
    """

    name = "semantic-driver"

    def __init__(
        self, params: SemanticExpertParams | None = None, segmenter: Segmenter | None = None
    ) -> None:
        super().__init__(params, segmenter)
        self._goal: FrontierCandidate | None = None
        self.goal_finished = False

    def reset(
        self, obs: dict[str, np.ndarray], info: dict[str, Any], seed: int | None = None
    ) -> None:
        super().reset(obs, info, seed=seed)
        self._goal = None
        self.goal_finished = False

    # ------------------------------------------------------------------ hooks
    def command_goal(self, candidate: FrontierCandidate | None) -> None:
        """Pursue ``candidate`` (None: the expert's own choice) from the next ``act`` on."""
        self._goal = candidate
        self.goal_finished = False
        self._next_replan_s = self._time_s  # replan at the next step

    def set_cost_weights(self, w_v: float, w_p: float, w_i: float) -> None:
        """Use these frontier cost weights from the next ``act`` on (a replan follows at once).

        Raises:
            ValueError: a negative or non-finite weight.
        """
        cost = replace(self.params.cost, w_v=float(w_v), w_p=float(w_p), w_i=float(w_i))
        self.params = replace(self.params, cost=cost)
        self._next_replan_s = self._time_s

    def frontier_candidates(
        self, obs: dict[str, np.ndarray], weights: FrontierCostWeights | None = None
    ) -> list[FrontierCandidate]:
        """Scored, non-blacklisted frontier candidates of ``obs`` (cheapest ``C`` first).

        Args:
            obs: The env observation (``map``, ``pose``).
            weights: Cost weights to score with (default: the driver's current ones).
        """
        if self._segmenter is None:
            raise ValueError("frontier_candidates needs reset() first")
        prm = self.params
        grid = obs["map"]
        x_m, y_m, yaw_rad = (float(v) for v in obs["pose"][:3])
        tmap = self._segmenter(
            grid, self.geometry, self.clearance_m, params=prm.segmentation, previous=self.tmap
        )
        cands, _ = search_frontier_paths(
            tmap,
            (x_m, y_m),
            yaw_rad,
            weights or prm.cost,
            prune_by=prm.prune_by,
            min_frontier_width_m=prm.min_frontier_width_m,
        )
        return [c for c in cands if not self._is_blacklisted(c.goal_xy_m)]

    # ------------------------------------------------------------------ overrides
    def _commit(self, cands: list[FrontierCandidate]) -> FrontierCandidate:
        goal = self._goal
        if goal is None or self.goal_finished:
            return super()._commit(cands)
        # Frontiers recede as they are mapped: the commanded one is the nearest candidate
        # within the commitment radius of its goal.
        r = self.params.commitment_radius_m
        dist = [math.dist(c.goal_xy_m, goal.goal_xy_m) for c in cands]
        k = int(np.argmin(dist))
        if dist[k] <= r:
            return cands[k]
        self.goal_finished = True
        return super()._commit(cands)

    def _replan_reason(self, grid: np.ndarray, pose: tuple[float, float, float]) -> str:
        reason = super()._replan_reason(grid, pose)
        if self._goal is not None and reason in _GOAL_DONE_REASONS:
            self.goal_finished = True
        return reason

    def _replan(self, grid: np.ndarray, pose: tuple[float, float, float], stats: Any) -> None:
        super()._replan(grid, pose, stats)
        plan = self._plan
        if self._goal is not None and (plan is None or plan.source != "semantic"):
            self.goal_finished = True  # the commanded frontier is no longer among the candidates
