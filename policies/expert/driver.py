"""The semantic expert as a low-level driver for macro-action agents.

:class:`ExpertDriver` is the scripted :class:`~semexplore_gym.policies.expert.expert.SemanticExpertPolicy`
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
the env-id entry points in :mod:`semexplore_gym.expert_driven_envs` join the two.

It uses only the expert's public plug-in points (see :mod:`semexplore_gym.policies.expert.expert`):
it overrides :meth:`~semexplore_gym.policies.expert.expert.SemanticExpertPolicy.choose_goal`,
:meth:`~semexplore_gym.policies.expert.expert.SemanticExpertPolicy.on_replan_due` and
:meth:`~semexplore_gym.policies.expert.expert.SemanticExpertPolicy.on_replanned`, and calls
:meth:`~semexplore_gym.policies.expert.expert.SemanticExpertPolicy.request_replan`. To drive to
a point rather than a frontier, use the expert's
:meth:`~semexplore_gym.policies.expert.expert.SemanticExpertPolicy.drive_to`.
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Any

import numpy as np
from semexplore_gym.policies.expert.expert import (
    PlanKind,
    Segmenter,
    SemanticExpertParams,
    SemanticExpertPolicy,
)
from semexplore_gym.policies.expert.recipes import OUTSIDE_CHOICE, ExpertRecipe, for_outside_choice

from semexplore_gym.core.planning.graph_search import FrontierCandidate

_GOAL_DONE_REASONS = ("goal_reached", "goal_vanished", "path_done")


class ExpertDriver(SemanticExpertPolicy):
    """The semantic expert driven by an outside goal choice or outside cost weights.

    Args:
        params: Expert parameters (default: the robust expert's).
        segmenter: See :class:`~semexplore_gym.policies.expert.expert.SemanticExpertPolicy`.
        recipe: Default :data:`~semexplore_gym.policies.expert.recipes.OUTSIDE_CHOICE`: the
            outside choice, not the grid's nearest frontier, decides, and the learned agents
            were trained and measured driving the map's paths. A recipe whose semantic source
            has the grid candidate or the grid route is refused (a ValueError naming it).

    Attributes:
        goal_finished: The commanded goal is done (reached, vanished, blacklisted or gone);
            the expert keeps driving with its own choice until the next command.
    """

    name = "semantic-driver"
    params: SemanticExpertParams

    recipe = OUTSIDE_CHOICE

    def __init__(
        self,
        params: SemanticExpertParams | None = None,
        segmenter: Segmenter | None = None,
        recipe: ExpertRecipe | None = None,
    ) -> None:
        # The agent chooses the frontier: the grid's nearest frontier must not overrule it.
        parts = for_outside_choice(recipe or OUTSIDE_CHOICE, "the expert driver")
        super().__init__(params, segmenter, recipe=parts)
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
        self.request_replan()

    def set_cost_weights(self, w_v: float, w_p: float, w_i: float) -> None:
        """Use these frontier cost weights from the next ``act`` on (a replan follows at once).

        Raises:
            ValueError: a negative or non-finite weight.
        """
        cost = replace(self.params.cost, w_v=float(w_v), w_p=float(w_p), w_i=float(w_i))
        self.params = replace(self.params, cost=cost)
        self.request_replan()

    # ------------------------------------------------------------------ expert hooks
    def choose_goal(self, candidates: list[FrontierCandidate]) -> FrontierCandidate:
        """The commanded frontier while it lasts, else the expert's own choice."""
        goal = self._goal
        if goal is None or self.goal_finished:
            return super().choose_goal(candidates)
        # Frontiers recede as they are mapped: the commanded one is the nearest candidate
        # within the commitment radius of its goal.
        r = self.params.commitment_radius_m
        dist = [math.dist(c.goal_xy_m, goal.goal_xy_m) for c in candidates]
        k = int(np.argmin(dist))
        if dist[k] <= r:
            return candidates[k]
        self.goal_finished = True
        return super().choose_goal(candidates)

    def on_replan_due(self, reason: str) -> None:
        """The commanded goal is finished once reached, mapped or its path used up."""
        if self._goal is not None and reason in _GOAL_DONE_REASONS:
            self.goal_finished = True

    def on_replanned(self, source: PlanKind | None) -> None:
        """The commanded frontier is finished once it is no longer among the candidates."""
        if self._goal is not None and source != PlanKind.SEMANTIC:
            self.goal_finished = True
