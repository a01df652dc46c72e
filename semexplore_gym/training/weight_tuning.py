"""Tune the semantic expert's planner weights with Optuna (TPE), and score weight sets.

The tuned parameters are the frontier cost weights ``w_v``, ``w_p``, ``w_I``
(``SemanticExpertParams.cost.w_v/w_p/w_i``) and, optionally, the potential field's ``f_g``,
``f_o``, ``f_l`` (``potential_field.f_g/f_o/f_l``). A weight set is a plain mapping of dotted
override keys to floats, e.g. ``{"cost.w_v": 4.0, "cost.w_p": 0.2, "cost.w_i": 0.1}``, ready for
``make_policy("semantic", **weights)``.

The objective of a weight set is the mean over missions (training worlds x seeds) of
:func:`mission_score` = ``mission_time_s + penalty_s * max(0, target_coverage - coverage)``:
faster is better, and a mission that stops (or times out) short of the coverage target pays for
every missing percent. Lower is better.

Every finished trial is appended to a JSONL file and, when ``storage_path`` is given, stored in
an Optuna SQLite study, so an interrupted tuning run loses at most the trial in flight and a
rerun with the same paths resumes (it runs only the missing trials).
"""

from __future__ import annotations

import json
import math
import os
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from semexplore_gym.config.extras import require_extra
from semexplore_gym.core.planning.graph_search import FrontierCostWeights
from semexplore_gym.core.planning.potential_field import PotentialFieldParams
from semexplore_gym.evaluation.harness import resolve_world
from semexplore_gym.evaluation.rollout import make_mission_env

_PAPER_COST = FrontierCostWeights()
_PAPER_POTENTIAL = PotentialFieldParams()
#: The paper's weights (Table I of Fredriksson et al.; the dataclass defaults), as dotted
#: overrides.
PAPER_WEIGHTS: dict[str, float] = {
    f"cost.{k}": float(getattr(_PAPER_COST, k)) for k in ("w_v", "w_p", "w_i")
}
#: The paper's potential-field parameters (the dataclass defaults), as dotted overrides.
PAPER_FIELD: dict[str, float] = {
    f"potential_field.{k}": float(getattr(_PAPER_POTENTIAL, k)) for k in ("f_g", "f_o", "f_l")
}

Objective = Callable[[dict[str, float]], float]


@dataclass(frozen=True)
class SearchSpace:
    """Ranges ``(low, high)`` of the tuned parameters; ``log`` ones are sampled log-uniformly.

    Attributes:
        ranges: Dotted override key -> ``(low, high)``.
        log_keys: Keys sampled on a log scale (their ``low`` must be > 0).
    """

    ranges: dict[str, tuple[float, float]] = field(
        default_factory=lambda: {
            "cost.w_v": (0.0, 10.0),
            "cost.w_p": (0.0, 1.0),
            "cost.w_i": (0.0, 1.0),
        }
    )
    log_keys: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        if not self.ranges:
            raise ValueError("SearchSpace.ranges is empty: nothing to tune")
        for key, bounds in self.ranges.items():
            if len(bounds) != 2:
                raise ValueError(f"range of {key!r} must be (low, high), got {bounds!r}")
            lo, hi = float(bounds[0]), float(bounds[1])
            if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi):
                raise ValueError(f"range of {key!r} must be finite with low < high, got {bounds!r}")
        for key in self.log_keys:
            if key not in self.ranges:
                raise ValueError(f"log key {key!r} is not in ranges {sorted(self.ranges)}")
            if self.ranges[key][0] <= 0.0:
                raise ValueError(f"log-scaled {key!r} needs low > 0, got {self.ranges[key]!r}")

    @classmethod
    def with_field(cls) -> SearchSpace:
        """Cost weights plus the potential field's ``f_g``, ``f_o``, ``f_l``."""
        base = cls().ranges
        return cls(
            ranges={
                **base,
                "potential_field.f_g": (5.0, 60.0),
                "potential_field.f_o": (0.01, 0.3),
                "potential_field.f_l": (1.0, 3.0),
            },
            log_keys=("potential_field.f_o",),
        )

    def contains(self, weights: Mapping[str, float]) -> bool:
        """True when every key of ``weights`` is tuned here and lies within its range."""
        return all(
            k in self.ranges and self.ranges[k][0] <= float(v) <= self.ranges[k][1]
            for k, v in weights.items()
        )


@dataclass(frozen=True)
class TuningResult:
    """Outcome of :func:`tune_weights`.

    Attributes:
        best_weights: The best trial's parameters (dotted keys).
        best_value: Its objective (lower is better).
        trials: ``(number, weights, value)`` of every completed trial, in order.
        wall_time_s: Wall time of this call (trials resumed from storage cost nothing).
    """

    best_weights: dict[str, float]
    best_value: float
    trials: list[tuple[int, dict[str, float], float]]
    wall_time_s: float


def mission_score(
    mission_time_s: float, coverage: float, target_coverage: float = 0.97, penalty_s: float = 600.0
) -> float:
    """``mission_time_s + penalty_s * max(0, target_coverage - coverage)`` (lower is better)."""
    if not (math.isfinite(mission_time_s) and mission_time_s >= 0.0):
        raise ValueError(f"mission_time_s must be a finite number >= 0, got {mission_time_s!r}")
    if not 0.0 <= target_coverage <= 1.0:
        raise ValueError(f"target_coverage must be in [0, 1], got {target_coverage!r}")
    if not (math.isfinite(penalty_s) and penalty_s >= 0.0):
        raise ValueError(f"penalty_s must be a finite number >= 0, got {penalty_s!r}")
    return float(mission_time_s + penalty_s * max(0.0, target_coverage - float(coverage)))


def evaluate_weights(
    weights: Mapping[str, float],
    worlds: Sequence[str],
    seeds: Sequence[int],
    max_time_s: float | None = None,
    env_config: Any = None,
    env_factory: Callable[[str], Any] | None = None,
) -> list[dict[str, Any]]:
    """Run the semantic expert with ``weights`` on every (world, seed); one summary dict each.

    Args:
        weights: Dotted overrides of ``SemanticExpertParams`` (see :data:`PAPER_WEIGHTS`).
        worlds: World spellings (``maze:seed=*,size_m=4`` takes each seed).
        seeds: Seeds for ``env.reset`` and the policy (and ``seed=*`` worlds).
        max_time_s: Simulated time limit per mission.
        env_config: Env config for ``gym.make`` (preset, path, mapping or None).
        env_factory: ``world -> env`` (default: :func:`make_mission_env` with ``env_config``).

    Returns:
        ``MissionResult.summary()`` dicts, world-major.
    """
    from semexplore_gym.evaluation.rollout import map_observation_for, run_mission
    from semexplore_gym.policies.expert.expert import SemanticExpertPolicy
    from semexplore_gym.policies.registry import make_policy

    if not worlds:
        raise ValueError("no worlds given")
    if not seeds:
        raise ValueError("no seeds given")
    env_kwargs = map_observation_for(SemanticExpertPolicy)
    make_env = env_factory or (lambda w: make_mission_env(w, env_config, **env_kwargs))
    out = []
    for world in worlds:
        for seed in seeds:
            env = make_env(resolve_world(world, int(seed)))
            try:
                policy = make_policy("semantic", **dict(weights))
                # The tuning objective is the time to the env's coverage goal.
                res = run_mission(
                    env,
                    policy,
                    seed=int(seed),
                    max_time_s=max_time_s,
                    progress=False,
                    ignore_terminated=False,
                )
            finally:
                env.close()
            out.append(res.summary())
    return out


def mission_objective(
    worlds: Sequence[str],
    seeds: Sequence[int],
    max_time_s: float | None = None,
    target_coverage: float = 0.97,
    penalty_s: float = 600.0,
    env_config: Any = None,
    fixed: Mapping[str, float] | None = None,
    env_factory: Callable[[str], Any] | None = None,
) -> Objective:
    """The tuning objective: mean :func:`mission_score` of the expert over worlds x seeds.

    ``fixed`` overrides are applied under the tuned ones (e.g. the paper's field parameters).
    """
    mission_score(0.0, 1.0, target_coverage, penalty_s)  # validates the arguments now

    def objective(weights: dict[str, float]) -> float:
        rows = evaluate_weights(
            {**dict(fixed or {}), **weights}, worlds, seeds, max_time_s, env_config, env_factory
        )
        scores = [
            mission_score(r["mission_time_s"], r["coverage"], target_coverage, penalty_s)
            for r in rows
        ]
        return float(sum(scores) / len(scores))

    return objective


@dataclass(frozen=True)
class StudySettings:
    """How :func:`tune_weights` keeps and samples its Optuna study.

    Attributes:
        seed: Seed of the TPE sampler (same seed and objective: same trials).
        storage_path: SQLite file of the study (None: in memory); a rerun resumes it.
        jsonl_path: One JSON line per finished trial is appended here.
        study_name: Name of the study in the storage.
        n_startup_trials: Random trials before TPE starts modelling.
    """

    seed: int = 0
    storage_path: str | os.PathLike | None = None
    jsonl_path: str | os.PathLike | None = None
    study_name: str = "semantic-weights"
    n_startup_trials: int = 5


def _check_enqueued(enqueue: Sequence[Mapping[str, float]], space: SearchSpace) -> None:
    for w in enqueue:
        unknown = sorted(set(w) - set(space.ranges))
        if unknown:
            raise ValueError(
                f"enqueued weights {unknown} are not in the search space {sorted(space.ranges)}"
            )


def _finished_trials(study: Any, complete: Any) -> list[tuple[int, dict[str, float], float]]:
    """``(number, weights, value)`` of every completed trial of ``study``."""
    return [
        (t.number, {k: float(v) for k, v in t.params.items()}, float(t.value))
        for t in study.trials
        if t.state == complete and t.value is not None
    ]


def _open_study(optuna: Any, settings: StudySettings) -> Any:
    """The study of ``settings``: created, or loaded from its storage to resume."""
    storage = None
    if settings.storage_path is not None:
        Path(settings.storage_path).parent.mkdir(parents=True, exist_ok=True)
        storage = f"sqlite:///{Path(settings.storage_path).resolve()}"
    sampler = optuna.samplers.TPESampler(
        seed=settings.seed, n_startup_trials=settings.n_startup_trials
    )
    return optuna.create_study(
        study_name=settings.study_name,
        storage=storage,
        sampler=sampler,
        direction="minimize",
        load_if_exists=True,
    )


def tune_weights(
    objective: Objective,
    n_trials: int,
    space: SearchSpace | None = None,
    study_settings: StudySettings | None = None,
    enqueue: Sequence[Mapping[str, float]] = (),
    on_trial: Callable[[int, dict[str, float], float], None] | None = None,
) -> TuningResult:
    """Minimise ``objective`` over ``space`` with Optuna's seeded TPE sampler.

    Args:
        objective: Weight set -> value (lower is better), e.g. from :func:`mission_objective`.
        n_trials: Total completed trials wanted (trials already in the storage count).
        space: The search space (default: ``w_v``, ``w_p``, ``w_I``).
        study_settings: Seed, storage, trial log and name of the study (None: defaults).
        enqueue: Weight sets tried first (e.g. the paper's, or a deliberately bad start); keys
            missing from a set are sampled.
        on_trial: Called after each trial as ``on_trial(number, weights, value)``.

    Returns:
        The :class:`TuningResult`.
    """
    settings = study_settings if study_settings is not None else StudySettings()
    require_extra("rl", "weight tuning (Optuna)", "optuna")
    import optuna

    if n_trials < 1:
        raise ValueError(f"n_trials must be >= 1, got {n_trials!r}")
    space = space or SearchSpace()
    _check_enqueued(enqueue, space)
    optuna.logging.set_verbosity(optuna.logging.WARNING)
    study = _open_study(optuna, settings)
    complete = optuna.trial.TrialState.COMPLETE
    n_done = sum(t.state == complete for t in study.trials)
    if n_done == 0:
        for w in enqueue:
            study.enqueue_trial({k: float(v) for k, v in w.items()})
    jsonl = Path(settings.jsonl_path) if settings.jsonl_path is not None else None
    if jsonl is not None:
        jsonl.parent.mkdir(parents=True, exist_ok=True)

    def run_trial(trial: Any) -> float:
        weights = {
            key: trial.suggest_float(key, lo, hi, log=key in space.log_keys)
            for key, (lo, hi) in space.ranges.items()
        }
        t0 = time.perf_counter()
        value = float(objective(weights))
        if not math.isfinite(value):
            raise ValueError(f"objective returned {value!r} for weights {weights}")
        if jsonl is not None:
            with jsonl.open("a") as f:
                record = {
                    "trial": trial.number,
                    "weights": weights,
                    "value": value,
                    "wall_time_s": round(time.perf_counter() - t0, 3),
                }
                f.write(json.dumps(record) + "\n")
        if on_trial is not None:
            on_trial(trial.number, weights, value)
        return value

    t_start = time.perf_counter()
    remaining = max(0, n_trials - n_done)
    if remaining:
        study.optimize(run_trial, n_trials=remaining)
    trials = _finished_trials(study, complete)
    _, best_weights, best_value = min(trials, key=lambda t: t[2])
    return TuningResult(
        best_weights=best_weights,
        best_value=best_value,
        trials=trials,
        wall_time_s=time.perf_counter() - t_start,
    )
