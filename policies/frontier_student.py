"""The frontier student: the semantic expert's navigation, a learned choice among every frontier.

At each replan the student lists every frontier a clearance-aware grid search reaches from the
robot (``PlanContext.grid_frontier_options``: the grid fallback's filters and the goal memory's
drops), scores each by a linear function of its
features (:mod:`~semexplore_gym.core.features.frontier_option_features`: path cost, the unknown
area round it, its isolation from the other frontiers, whether it is the current goal, ...)
and drives to the best over that option's grid path. It keeps that goal until it is
reached, mapped or no longer reachable (``keep_goal``), and only then chooses again. Algorithm 1
is not asked; everything else is the expert's: retries and views of goals reached without
clearing them, the path follower, the collision guard, the blacklists, the pocket escape, the
narrow tier and the stop rule (when no frontier is reachable, the expert's later sources run as
usual). A choice that would adopt again a goal it left without the map growing since (the
goal memory's shuttle test) is passed to those sources too: at a narrow passage a goal can
drop out of the options each time the robot nears it, and choosing again would send the robot
back and forth between two such goals for the rest of the mission.

The weights are learned from the oracle (:mod:`semexplore_gym.training.oracle_student`): at
states the student itself reaches, the privileged teacher prices every option by the length of
its best tour through the rest of the building when it goes there first, and the student is
fitted to prefer the cheap ones. The student reads only its observation. With the default
model (every weight 0 except ``-1`` on ``path_m``) it drives to the nearest frontier::

    from semexplore_gym.policies.registry import make_policy
    policy = make_policy("pretrained:oracle_student")
    policy = make_policy("frontier-student")  # nearest-frontier weights
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from semexplore_gym.policies.expert.expert import Segmenter, SemanticExpertPolicy
from semexplore_gym.policies.expert.params import SemanticExpertParams
from semexplore_gym.policies.expert.plan import Plan, PlanKind
from semexplore_gym.policies.expert.plan_context import PlanContext, PlanSource
from semexplore_gym.policies.expert.recipes import OUTSIDE_CHOICE

from semexplore_gym.core.features.frontier_option_features import (
    OPTION_FEATURE_NAMES,
    frontier_option_features,
)
from semexplore_gym.core.frontiers.options import FrontierOptions

__all__ = [
    "FrontierStudentModel",
    "FrontierStudentParams",
    "FrontierStudentPolicy",
    "OptionChooser",
    "StudentDecision",
]


@dataclass(frozen=True)
class FrontierStudentModel:
    """A linear score over standardised option features (higher: better).

    ``score = sum_k weights[k] * (phi_k - mean[k]) / scale[k]``, columns in
    :data:`~semexplore_gym.core.features.frontier_option_features.OPTION_FEATURE_NAMES` order.
    Default: ``-path_m``, the nearest frontier.
    """

    weights: tuple[float, ...] = tuple(-1.0 if n == "path_m" else 0.0 for n in OPTION_FEATURE_NAMES)
    mean: tuple[float, ...] = (0.0,) * len(OPTION_FEATURE_NAMES)
    scale: tuple[float, ...] = (1.0,) * len(OPTION_FEATURE_NAMES)

    def __post_init__(self) -> None:
        k = len(OPTION_FEATURE_NAMES)
        for name in ("weights", "mean", "scale"):
            v = np.asarray(getattr(self, name), dtype=np.float64)
            if v.shape != (k,) or not np.isfinite(v).all():
                raise ValueError(
                    f"model.{name} must be {k} finite numbers (one per feature: "
                    f"{', '.join(OPTION_FEATURE_NAMES)}), got {getattr(self, name)!r}"
                )
        if min(self.scale) <= 0:
            raise ValueError(f"model.scale must be > 0, got {self.scale!r}")

    def scores(self, features: np.ndarray) -> np.ndarray:
        """``(F,)`` scores of ``(F, K)`` features."""
        z = (features - np.asarray(self.mean)) / np.asarray(self.scale)
        return z @ np.asarray(self.weights)


@dataclass(frozen=True)
class FrontierStudentParams:
    """Parameters of :class:`FrontierStudentPolicy`.

    Attributes:
        expert: The semantic expert's parameters (navigation, memory, stop rule; its
            frontier choice is not used while the student has options; the expert is made
            from the outside-choice recipe, :data:`~semexplore_gym.policies.expert.recipes.
            OUTSIDE_CHOICE`).
        model: The learned score.
        keep_goal: Keep the current goal while it is still one of the options (reached,
            mapped or unreachable goals end it); the choice is made only then. False: choose
            at every replan, with ``switch_margin``.
        switch_margin: Without ``keep_goal``, the current goal is kept while its score is
            within this of the best.
    """

    expert: SemanticExpertParams = field(default_factory=SemanticExpertParams)
    model: FrontierStudentModel = field(default_factory=FrontierStudentModel)
    keep_goal: bool = True
    switch_margin: float = 0.5

    def __post_init__(self) -> None:
        if not (np.isfinite(self.switch_margin) and self.switch_margin >= 0):
            raise ValueError(
                f"switch_margin must be a finite number >= 0, got {self.switch_margin!r}"
            )


@dataclass(frozen=True)
class StudentDecision:
    """One choice of the student, as training code sees it (``OptionChooser``).

    Attributes:
        grid: The map the student decided on.
        pose: ``(x_m, y_m, yaw_rad)`` of the robot.
        time_s: Simulated time of the decision.
        options: The reachable frontiers.
        features: ``(F, K)`` their features.
        scores: ``(F,)`` the model's scores.
        choice: The option the student picks (commitment applied).
    """

    grid: np.ndarray
    pose: tuple[float, float, float]
    time_s: float
    options: FrontierOptions
    features: np.ndarray
    scores: np.ndarray
    choice: int


#: Training code's hook: sees each decision, returns the option to drive to (None: the student's).
OptionChooser = Callable[[StudentDecision], "int | None"]


class StudentFrontier(PlanSource):
    """The student's pick among every reachable frontier (passes when none is reachable)."""

    name = "student"

    def __init__(self, decide: Callable[[PlanContext], Plan | None]) -> None:
        self._decide = decide

    def propose(self, ctx: PlanContext) -> Plan | None:
        return self._decide(ctx)


def _current_option(
    options: FrontierOptions, goal_xy_m: tuple[float, float] | None, radius_m: float
) -> int | None:
    """The option whose goal lies within ``radius_m`` of ``goal_xy_m`` (the nearest), if any."""
    if goal_xy_m is None or len(options) == 0:
        return None
    gap = np.hypot(options.goal_xy_m[:, 0] - goal_xy_m[0], options.goal_xy_m[:, 1] - goal_xy_m[1])
    j = int(np.argmin(gap))
    return j if gap[j] <= radius_m else None


class FrontierStudentPolicy(SemanticExpertPolicy):
    """The expert's navigation with a learned frontier choice (see the module docstring).

    Args:
        params: The expert's parameters, the model and the switch margin.
        segmenter: The expert's segmenter (its topometric map still drives its look and view
            sources).
        chooser: Training code only: called at every choice (not while ``keep_goal`` keeps the
            goal), may override it.
    """

    name = "frontier-student"

    def __init__(
        self,
        params: FrontierStudentParams | None = None,
        segmenter: Segmenter | None = None,
        chooser: OptionChooser | None = None,
    ) -> None:
        self.student_params = params if params is not None else FrontierStudentParams()
        recipe = OUTSIDE_CHOICE.with_source(StudentFrontier(self._decide), before="semantic")
        super().__init__(self.student_params.expert, segmenter=segmenter, recipe=recipe)
        self.chooser = chooser
        self.decisions = 0
        self.shuttles_passed = 0

    def reset(
        self, obs: dict[str, np.ndarray], info: dict[str, Any], seed: int | None = None
    ) -> None:
        super().reset(obs, info, seed=seed)
        self.decisions = 0
        self.shuttles_passed = 0

    def _decide(self, ctx: PlanContext) -> Plan | None:
        options = ctx.grid_frontier_options()
        if len(options) == 0:
            return None
        prm = self.student_params
        current = ctx.current.goal_xy_m if ctx.current is not None else None
        kept = _current_option(options, current, ctx.params.commitment_radius_m)
        if prm.keep_goal and kept is not None:  # no choice to make
            choice = kept
        else:
            choice = self._choose(ctx, options, current, kept)
        goal = options.goal_xy_m[choice]
        if choice != kept and ctx.memory.would_shuttle(
            (float(goal[0]), float(goal[1])), self._known_cells
        ):
            # Back to a goal it left without the map growing since: a shuttle between goals
            # that drop out of the options as the robot nears them (a wall cell that flickers
            # at a narrow passage). Pass: the expert's own sources choose this time, with the
            # goal memory's retries and drops.
            self.shuttles_passed += 1
            return None
        return Plan(
            PlanKind.LEARNED,
            (float(goal[0]), float(goal[1])),
            ctx.resampled(options.path_m(choice)),
        )

    def _choose(
        self,
        ctx: PlanContext,
        options: FrontierOptions,
        current: tuple[float, float] | None,
        kept: int | None,
    ) -> int:
        """Score the options; the best (or ``kept``, the current goal's option, within the
        margin), or the training chooser's pick."""
        prm = self.student_params
        feats = frontier_option_features(
            ctx.grid, ctx.geometry, ctx.pose, options, current, ctx.params.commitment_radius_m
        )
        scores = prm.model.scores(feats)
        choice = int(np.argmax(scores))
        if kept is not None and scores[kept] >= scores[choice] - prm.switch_margin:
            choice = kept
        self.decisions += 1
        if self.chooser is not None:
            decision = StudentDecision(
                ctx.grid, ctx.pose, self.time_s, options, feats, scores, choice
            )
            override = self.chooser(decision)
            choice = choice if override is None else int(override)
        return choice

    def mission_metrics(self) -> dict[str, Any]:
        return {
            **super().mission_metrics(),
            "student_decisions": self.decisions,
            "student_shuttles_passed": self.shuttles_passed,
        }
