"""Features and actions of the macro-action decision problems (pure numpy, no gymnasium).

At each decision a macro-action agent sees features of the top-``K`` frontier candidates of the
semantic topometric map (Algorithm 1, ranked by the frontier cost ``C``) plus a few global
features, and answers with a candidate index (frontier choice) or with three numbers mapped to
the cost weights (:func:`action_to_weights`). The env wrappers in
:mod:`semexplore_gym.wrappers.frontier_choice` and the policy that runs a trained macro agent,
:class:`semexplore_gym.policies.macro_agent.MacroAgentPolicy`, both build their vectors here, so a trained
model sees the same numbers in training and in a benchmark.

Observation (``(K * 8 + 4,)`` float32 in ``[-1, 1]``): ``K`` rows of candidate features, padded
with zeros, then the global features. Per candidate (cheapest first):

====  =====================================================  =========================
col   feature                                                scaling
====  =====================================================  =========================
0     valid (1 for a real candidate, 0 for padding)          -
1     ``d``: path length to the frontier                      ``min(d / dist_scale_m, 1)``
2     ``v``: heading angle to the path start                  ``v / pi``
3     ``p_l``: frontier to intersection path length           ``min(p_l / dist_scale_m, 1)``
4     ``O(I)``: openings of the intersection                  ``min(O / count_scale, 1)``
5     ``P_u(I)``: its pathways leading to a frontier          ``min(P_u / count_scale, 1)``
6     ``C``: the frontier cost                                ``tanh(C / cost_scale)``
7     opening width                                           ``min(w / width_scale_m, 1)``
====  =====================================================  =========================

Global features: known fraction of the map's cells, ``min(sim_time_s / time_scale_s, 1)``,
candidates shown / ``K``, ``min(all candidates / (4 K), 1)``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from semexplore_gym.core.grid import UNKNOWN
from semexplore_gym.core.planning.graph_search import FrontierCandidate, FrontierCostWeights
from semexplore_gym.core.validation import require_finite

N_CANDIDATE_FEATURES = 8
N_GLOBAL_FEATURES = 4


@dataclass(frozen=True)
class MacroParams:
    """Parameters shared by the macro-action wrappers.

    Attributes:
        n_candidates: ``K``, the candidates shown (and actions of :class:`FrontierChoice`).
        max_macro_time_s: Longest decision of :class:`FrontierChoice` (simulated s).
        decision_period_s: Length of a decision of :class:`PlannerWeights` (simulated s).
        area_reward_per_m2: Reward per m^2 of newly mapped free area.
        time_penalty_per_s: Penalty per simulated second.
        dist_scale_m: Scale of ``d`` and ``p_l`` features.
        count_scale: Scale of ``O`` and ``P_u`` features.
        cost_scale: Scale of the ``C`` feature (inside tanh).
        width_scale_m: Scale of the width feature.
        time_scale_s: Scale of the elapsed-time feature.
    """

    n_candidates: int = 8
    max_macro_time_s: float = 20.0
    decision_period_s: float = 10.0
    area_reward_per_m2: float = 1.0
    time_penalty_per_s: float = 0.05
    dist_scale_m: float = 20.0
    count_scale: float = 8.0
    cost_scale: float = 10.0
    width_scale_m: float = 2.0
    time_scale_s: float = 600.0

    def __post_init__(self) -> None:
        if int(self.n_candidates) < 1:
            raise ValueError(f"n_candidates must be >= 1, got {self.n_candidates!r}")
        require_finite(
            self,
            (
                "max_macro_time_s",
                "decision_period_s",
                "dist_scale_m",
                "count_scale",
                "cost_scale",
                "width_scale_m",
                "time_scale_s",
            ),
            positive=True,
        )
        require_finite(self, ("area_reward_per_m2", "time_penalty_per_s"), positive=False)


def candidate_features(
    candidates: list[FrontierCandidate], params: MacroParams
) -> tuple[np.ndarray, np.ndarray]:
    """``(K, 8)`` float32 features of the first ``K`` candidates and the ``(K,)`` bool mask."""
    k = params.n_candidates
    feats = np.zeros((k, N_CANDIDATE_FEATURES), dtype=np.float32)
    mask = np.zeros(k, dtype=bool)
    for i, c in enumerate(candidates[:k]):
        feats[i] = (
            1.0,
            min(c.d_m / params.dist_scale_m, 1.0),
            min(max(c.v_rad, 0.0) / math.pi, 1.0),
            min(c.p_l_m / params.dist_scale_m, 1.0) if math.isfinite(c.p_l_m) else 1.0,
            min(c.n_openings / params.count_scale, 1.0),
            min(c.n_frontier_pathways / params.count_scale, 1.0),
            math.tanh(c.cost / params.cost_scale),
            min(c.frontier.width_m / params.width_scale_m, 1.0),
        )
        mask[i] = True
    return feats, mask


def global_features(
    grid: np.ndarray, sim_time_s: float, n_shown: int, n_all: int, params: MacroParams
) -> np.ndarray:
    """``(4,)`` float32: known fraction of ``grid``, elapsed time, candidates shown and found."""
    return np.array(
        [
            1.0 - float(np.count_nonzero(grid == UNKNOWN)) / grid.size,
            min(float(sim_time_s) / params.time_scale_s, 1.0),
            n_shown / params.n_candidates,
            min(n_all / (4.0 * params.n_candidates), 1.0),
        ],
        dtype=np.float32,
    )


def observation_vector(
    candidates: list[FrontierCandidate], grid: np.ndarray, sim_time_s: float, params: MacroParams
) -> tuple[np.ndarray, list[FrontierCandidate]]:
    """The agent's observation for all scored ``candidates`` (cheapest first) of a map.

    Returns the ``(K * 8 + 4,)`` float32 vector and the first ``K`` candidates (the ones shown,
    which the actions of a frontier-choice agent index).
    """
    shown = candidates[: params.n_candidates]
    feats, _ = candidate_features(shown, params)
    glob = global_features(grid, sim_time_s, len(shown), len(candidates), params)
    return np.concatenate([feats.ravel(), glob]).astype(np.float32), shown


def action_mask(n_shown: int, params: MacroParams) -> np.ndarray:
    """``(K,)`` bool mask of a frontier-choice agent's valid actions: the candidates shown.

    Action 0 is always valid: with no candidate it means "the driver's own choice".
    """
    mask = np.zeros(params.n_candidates, dtype=bool)
    mask[: max(1, n_shown)] = True
    return mask


def observation_size(params: MacroParams) -> int:
    """Length of the observation vector for ``params``."""
    return params.n_candidates * N_CANDIDATE_FEATURES + N_GLOBAL_FEATURES


_PAPER = FrontierCostWeights()
#: Ranges ``(low, paper, high)`` of ``w_v``, ``w_p``, ``w_I`` for :func:`action_to_weights`
#: (the middle values are the paper's, the defaults of :class:`FrontierCostWeights`).
WEIGHT_RANGES: tuple[tuple[float, float, float], ...] = (
    (0.0, _PAPER.w_v, 10.0),
    (0.0, _PAPER.w_p, 1.0),
    (0.0, _PAPER.w_i, 1.0),
)


def action_to_weights(action: np.ndarray) -> tuple[float, float, float]:
    """Map an action in ``[-1, 1]^3`` to ``(w_v, w_p, w_I)``, piecewise linearly per weight.

    ``-1`` gives the range's low end, ``0`` the paper's weight (4, 0.2, 0.1), ``+1`` the high end
    (:data:`WEIGHT_RANGES`: ``w_v`` in [0, 10], ``w_p`` in [0, 1], ``w_I`` in [0, 1]). Values
    outside ``[-1, 1]`` are clipped; NaN raises ``ValueError``.
    """
    a = np.asarray(action, dtype=np.float64).reshape(-1)
    if a.shape != (3,):
        raise ValueError(f"weights action must have 3 values, got shape {np.shape(action)}")
    if not np.isfinite(a).all():
        raise ValueError(f"weights action must be finite, got {a.tolist()}")
    a = np.clip(a, -1.0, 1.0)
    out = []
    for x, (lo, mid, hi) in zip(a, WEIGHT_RANGES, strict=True):
        out.append(float(mid + x * (mid - lo)) if x < 0 else float(mid + x * (hi - mid)))
    return out[0], out[1], out[2]
