"""The semantic expert with a learned frontier value: ``C' = C + sum_k w_k * phi_k``.

Only the choice of frontier changes. At each replan the expert's candidates (Algorithm 1's
frontiers with their paper cost ``C``) are re-ranked by ``C'``, the paper's cost plus a linear
value over the features of :mod:`semexplore_gym.core.features.frontier_features` (path length in
metres, unknown area round the goal, isolation from the other frontiers, ...); the expert's goal
commitment then works on ``C'``. Navigation, safety, retries, the grid fallback and the stop
rule are the expert's own. With every weight at 0 it is the expert, decision for decision.

The weights (and the expert's cost weights and switch margin) were fitted by black-box
optimisation over missions on training worlds (:mod:`semexplore_gym.training.frontier_value_search`);
a fitted set ships as ``pretrained:frontier_value`` (``policies/pretrained``)::

    from semexplore_gym.policies.registry import make_policy
    policy = make_policy("pretrained:frontier_value")
    policy = make_policy("frontier-value", **{"value.w_path_m": 0.1, "expert.switch_margin": 0.3})
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from semexplore_gym.policies.expert.expert import Segmenter, SemanticExpertPolicy
from semexplore_gym.policies.expert.params import SemanticExpertParams
from semexplore_gym.policies.expert.recipes import OUTSIDE_CHOICE

from semexplore_gym.core.features.frontier_features import FEATURE_NAMES, frontier_value_features
from semexplore_gym.core.planning.graph_search import FrontierCandidate
from semexplore_gym.core.validation import require_finite

__all__ = ["FrontierValueParams", "FrontierValuePolicy", "FrontierValueWeights"]


@dataclass(frozen=True)
class FrontierValueWeights:
    """Weights of the learned value (cost units of ``C`` per unit of each feature; 0: unused).

    Attributes:
        w_path_m: Per metre of path ``d``.
        w_unknown_frac: Per unit share of unknown cells round the goal.
        w_isolation_m: Per metre to the nearest other frontier.
        w_spread_m: Per metre to the centroid of the other frontiers.
        w_detour: Per unit of ``d / straight distance - 1``.
        unknown_radius_m: Radius of the disc ``unknown_frac`` looks at.
    """

    w_path_m: float = 0.0
    w_unknown_frac: float = 0.0
    w_isolation_m: float = 0.0
    w_spread_m: float = 0.0
    w_detour: float = 0.0
    unknown_radius_m: float = 1.5

    def __post_init__(self) -> None:
        for name in FEATURE_NAMES:
            w = getattr(self, f"w_{name}")
            if isinstance(w, bool) or not isinstance(w, (int, float)) or not math.isfinite(w):
                raise ValueError(f"w_{name} must be a finite number, got {w!r}")
        require_finite(self, ("unknown_radius_m",), positive=True)

    def vector(self) -> np.ndarray:
        """The weights in :data:`FEATURE_NAMES` order."""
        return np.array([getattr(self, f"w_{n}") for n in FEATURE_NAMES], dtype=np.float64)

    def is_zero(self) -> bool:
        return not bool(np.any(self.vector() != 0.0))


@dataclass(frozen=True)
class FrontierValueParams:
    """Parameters of :class:`FrontierValuePolicy`.

    Attributes:
        expert: The semantic expert's parameters (its cost weights and switch margin included;
            the expert is made from the outside-choice recipe, :data:`~semexplore_gym.policies.
            expert.recipes.OUTSIDE_CHOICE`: the learned ranking decides, driven as it was
            measured).
        value: The learned value's weights.
    """

    expert: SemanticExpertParams = field(default_factory=SemanticExpertParams)
    value: FrontierValueWeights = field(default_factory=FrontierValueWeights)


class FrontierValuePolicy(SemanticExpertPolicy):
    """The semantic expert choosing its frontier by ``C'`` (see the module docstring).

    Args:
        params: The expert's parameters and the value's weights (default: all 0, the expert).
    """

    name = "frontier-value"

    def __init__(
        self, params: FrontierValueParams | None = None, segmenter: Segmenter | None = None
    ) -> None:
        self.value_params = params if params is not None else FrontierValueParams()
        # The learned ranking chooses: the grid's nearest frontier must not overrule it.
        super().__init__(self.value_params.expert, segmenter=segmenter, recipe=OUTSIDE_CHOICE)
        self._obs: dict[str, np.ndarray] | None = None

    def act(self, obs: dict[str, np.ndarray], info: dict[str, Any]) -> np.ndarray:
        self._obs = obs
        return super().act(obs, info)

    def rescored(self, candidates: list[FrontierCandidate]) -> list[FrontierCandidate]:
        """``candidates`` with ``cost`` replaced by ``C'``, cheapest first (stable)."""
        value = self.value_params.value
        if value.is_zero() or self._obs is None or not candidates:
            return list(candidates)
        pose = self._obs["pose"]
        feats = frontier_value_features(
            np.asarray(self._obs["map"]),
            self.geometry,
            (float(pose[0]), float(pose[1])),
            [c.goal_xy_m for c in candidates],
            [c.d_m for c in candidates],
            unknown_radius_m=value.unknown_radius_m,
        )
        extra = feats @ value.vector()
        out = [
            dataclasses.replace(c, cost=float(c.cost + e))
            for c, e in zip(candidates, extra, strict=True)
        ]
        order = sorted(range(len(out)), key=lambda i: out[i].cost)
        return [out[i] for i in order]

    def rank_frontiers(self, candidates: list[FrontierCandidate]) -> list[FrontierCandidate]:
        """The candidates ranked by ``C'`` (the expert's goal commitment then works on it)."""
        return self.rescored(candidates)
