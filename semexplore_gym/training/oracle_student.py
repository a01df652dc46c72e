"""Train the frontier student from the oracle's labels (DAgger; no torch).

The student (:class:`~semexplore_gym.policies.frontier_student.FrontierStudentPolicy`) chooses
among every reachable frontier by a linear score of their features. Training is DAgger with a
privileged teacher ("learning by cheating"):

1. **Roll out** the current student on training worlds (the ``train`` parts of the learning
   splits, :mod:`semexplore_gym.evaluation.splits`; random starts) in a privileged env. Round 0's
   student is the nearest-frontier chooser.
2. **Label** its own decisions (each choice of a new goal; without ``keep_goal``, at most one
   every ``label_period_s`` simulated seconds): the
   :class:`~semexplore_gym.training.teacher_labels.OracleTeacher` prices every option by the
   oracle's tour length when it goes there first (``cost_to_go_m``). With probability ``beta``
   of the round the teacher's choice is driven instead of the student's (its own generator).
3. **Fit** the score to the aggregated labels: a listwise softmax over each decision's options,
   trained by cross-entropy against ``softmax(-(cost_to_go - min) / temperature_m)`` with an L2
   penalty (:func:`fit_student_model`, scipy's L-BFGS).

Every episode's labels are written as they come (``samples/round<R>_ep<E>.npz``) and its
summary appended to ``episodes.jsonl``: rerun the same command and finished episodes are read
back, not rerun. Each round's model is ``model_round<R>.yaml``; the last one is also
``model.yaml`` (a :class:`~semexplore_gym.policies.frontier_student.FrontierStudentParams` layer,
what ``frontier-student[params=...]`` and ``pretrained:`` read). Per round, the log gives the
choice regret of the model that drove on the round's own labels (metres of oracle tour lost by
its choices against the teacher's), next to the nearest frontier's on the same decisions.
"""

from __future__ import annotations

import json
import math
import re
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from scipy import optimize

from semexplore_gym.core.coverage_tour import PRIVILEGED_INFO_KEY
from semexplore_gym.core.features.frontier_option_features import OPTION_FEATURE_NAMES

__all__ = [
    "EpisodeJob",
    "LabelledDecisions",
    "OracleStudentTrainConfig",
    "choice_regret",
    "collect_episode",
    "fit_student_model",
    "load_oracle_student_config",
    "train_oracle_student",
]


@dataclass(frozen=True)
class OracleStudentTrainConfig:
    """Settings of :func:`train_oracle_student` (``configs/agents/oracle_student.yml``).

    Attributes:
        seed: Seed of the episode draws and of each episode's generator.
        splits: Learning splits whose ``train`` part is drawn from (never another part).
        max_size_m: Only training worlds with ``size_m`` at most this (DungeonMaps: 28 m).
        rounds: DAgger rounds (round 0 drives the nearest frontier).
        episodes_per_round: Episodes per round.
        beta: Per round, the chance that a labelled decision drives the teacher's choice
            (the last value repeats).
        keep_goal: The student's ``keep_goal`` (written into the model): it chooses only when
            its goal is reached, mapped or unreachable, and each such choice is labelled.
        label_period_s: Without ``keep_goal``: at most one label per this many simulated seconds.
        max_time_s: Simulated time limit of an episode.
        temperature_m: Soft target's temperature (metres of cost-to-go).
        l2: L2 penalty on the weights (standardised features).
        switch_margin: The student's switch margin (written into the model).
        first_stops: The teacher's ``first_stops`` (see :class:`TeacherParams`).
        workers: Episodes in parallel (processes).
        wall_budget_s: No new round starts after this much wall time.
    """

    seed: int = 0
    splits: tuple[str, ...] = ("mazes", "offices")
    max_size_m: float = 16.0
    rounds: int = 4
    episodes_per_round: int = 16
    beta: tuple[float, ...] = (0.0,)
    keep_goal: bool = True
    label_period_s: float = 6.0
    max_time_s: float = 1500.0
    temperature_m: float = 2.0
    l2: float = 1e-3
    switch_margin: float = 0.5
    first_stops: int = 2
    workers: int = 2
    wall_budget_s: float = 6600.0

    def __post_init__(self) -> None:
        for name in ("rounds", "episodes_per_round", "workers", "first_stops"):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, int) or v < 1:
                raise ValueError(f"{name} must be an integer >= 1, got {v!r}")
        for name in ("max_size_m", "label_period_s", "max_time_s", "temperature_m"):
            v = getattr(self, name)
            if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
                raise ValueError(f"{name} must be a finite number > 0, got {v!r}")
        if not self.beta or not all(0.0 <= float(b) <= 1.0 for b in self.beta):
            raise ValueError(f"beta must be one or more numbers in [0, 1], got {self.beta!r}")
        if not self.splits:
            raise ValueError("splits is empty: name at least one learning split")


def load_oracle_student_config(path: str | None, overrides: list[str]) -> OracleStudentTrainConfig:
    """Config from YAML ``path`` (or defaults) with ``key=value`` overrides applied."""
    from semexplore_gym.config import build_params

    return build_params(OracleStudentTrainConfig, path, overrides=overrides)


@dataclass(frozen=True)
class EpisodeJob:
    """One training episode (picklable, for a worker process)."""

    world: str
    seed: int
    round: int
    episode: int
    params: dict[str, Any]
    beta: float
    label_period_s: float
    max_time_s: float
    first_stops: int


@dataclass
class LabelledDecisions:
    """The teacher's labels of one episode's decisions.

    Attributes:
        features: Per decision, ``(F, K)`` option features.
        cost_to_go_m: Per decision, ``(F,)`` the teacher's cost-to-go of each option.
        choice: Per decision, the student's own choice.
    """

    features: list[np.ndarray] = field(default_factory=list)
    cost_to_go_m: list[np.ndarray] = field(default_factory=list)
    choice: list[int] = field(default_factory=list)

    def __len__(self) -> int:
        return len(self.features)

    def extend(self, other: LabelledDecisions) -> None:
        self.features += other.features
        self.cost_to_go_m += other.cost_to_go_m
        self.choice += other.choice

    def save(self, path: Path) -> None:
        sizes = np.array([len(c) for c in self.cost_to_go_m], dtype=np.int64)
        k = len(OPTION_FEATURE_NAMES)
        np.savez_compressed(
            path,
            sizes=sizes,
            features=np.vstack(self.features) if self.features else np.zeros((0, k)),
            cost_to_go_m=np.concatenate(self.cost_to_go_m) if self.features else np.zeros(0),
            choice=np.asarray(self.choice, dtype=np.int64),
        )

    @classmethod
    def load(cls, path: Path) -> LabelledDecisions:
        with np.load(path) as z:
            cuts = np.cumsum(z["sizes"])[:-1]
            return cls(
                list(np.split(z["features"], cuts)),
                list(np.split(z["cost_to_go_m"], cuts)),
                [int(c) for c in z["choice"]],
            )


def collect_episode(job: EpisodeJob) -> tuple[LabelledDecisions, dict[str, Any]]:
    """Run the student on ``job.world`` in a privileged env; label its decisions.

    The true world goes to the teacher only; the student sees its observation.
    """
    from semexplore_gym.envs.env_config import load_env_config
    from semexplore_gym.evaluation.rollout import make_mission_env
    from semexplore_gym.policies.frontier_student import FrontierStudentPolicy, StudentDecision
    from semexplore_gym.policies.registry import make_policy
    from semexplore_gym.training.teacher_labels import OracleTeacher, TeacherParams
    from semexplore_gym.training.workers import DAGGER_STREAM, episode_rng

    rng = episode_rng(job.seed, job.round * 100_000 + job.episode, DAGGER_STREAM)
    cfg = load_env_config(
        None, ["episode.random_start=true", f"episode.max_time_s={job.max_time_s!r}"]
    )
    env = make_mission_env(job.world, cfg, privileged=True, disable_env_checker=True)
    data = LabelledDecisions()
    next_label_s = [0.0]
    teacher: list[OracleTeacher] = []
    current = OPTION_FEATURE_NAMES.index("current")
    keep_goal = bool(job.params.get("keep_goal", True))

    def chooser(d: StudentDecision) -> int | None:
        # A decision: a new goal is chosen (or, without keep_goal, one per label period).
        new_goal = not d.features[:, current].any()
        due = new_goal or (not keep_goal and d.time_s >= next_label_s[0])
        if not due or len(d.options) < 2:
            return None
        next_label_s[0] = d.time_s + job.label_period_s
        lab = teacher[0].labels(
            {"map": d.grid, "pose": np.asarray(d.pose)}, d.options.frontier_cells
        )
        if lab.first < 0 or not np.isfinite(lab.cost_to_go_m).any():
            return None
        data.features.append(d.features.copy())
        data.cost_to_go_m.append(lab.cost_to_go_m.astype(np.float64))
        data.choice.append(d.choice)
        return lab.first if rng.random() < job.beta else None

    policy = make_policy("frontier-student", params=job.params)
    assert isinstance(policy, FrontierStudentPolicy)
    policy.chooser = chooser
    t0 = time.perf_counter()
    try:
        obs, info = env.reset(seed=job.seed)
        teacher.append(
            OracleTeacher.from_reset_info(info, TeacherParams(first_stops=job.first_stops))
        )
        info = {k: v for k, v in info.items() if k != PRIVILEGED_INFO_KEY}  # the student's view
        policy.reset(obs, info, seed=job.seed)
        truncated = False
        while not policy.done and not truncated:
            obs, _, _, truncated, info = env.step(policy.act(obs, info))
        coverage = float(info.get("coverage", float("nan")))
    finally:
        env.close()
    summary = {
        "round": job.round,
        "episode": job.episode,
        "world": job.world,
        "seed": job.seed,
        "mission_time_s": round(policy.time_s, 2),
        "coverage": round(coverage, 4),
        "labels": len(data),
        "wall_s": round(time.perf_counter() - t0, 1),
    }
    return data, summary


def _soft_targets(cost_to_go_m: np.ndarray, temperature_m: float) -> np.ndarray:
    c = np.where(np.isfinite(cost_to_go_m), cost_to_go_m, np.inf)
    z = -(c - c.min()) / temperature_m
    q = np.exp(z)
    return q / q.sum()


def fit_student_model(
    data: LabelledDecisions, temperature_m: float = 2.0, l2: float = 1e-3
) -> dict[str, list[float]]:
    """The ``model`` section (weights, mean, scale) fitted to ``data`` (see the module)."""
    keep = [i for i, c in enumerate(data.cost_to_go_m) if len(c) >= 2 and np.isfinite(c).any()]
    if not keep:
        raise ValueError("no labelled decision with two or more options: nothing to fit")
    feats = [data.features[i] for i in keep]
    x = np.vstack(feats)
    mean = x.mean(axis=0)
    scale = x.std(axis=0)
    scale = np.where(scale > 1e-9, scale, 1.0)
    z = (x - mean) / scale
    q = np.concatenate([_soft_targets(data.cost_to_go_m[i], temperature_m) for i in keep])
    starts = np.cumsum([0] + [len(f) for f in feats[:-1]])
    group = np.repeat(np.arange(len(feats)), [len(f) for f in feats])
    n = len(feats)

    def loss(w: np.ndarray) -> tuple[float, np.ndarray]:
        s = z @ w
        m = np.maximum.reduceat(s, starts)
        e = np.exp(s - m[group])
        tot = np.add.reduceat(e, starts)
        p = e / tot[group]
        logp = s - m[group] - np.log(tot[group])
        val = -float(np.sum(q * logp)) / n + l2 * float(w @ w)
        grad = z.T @ (p - q) / n + 2.0 * l2 * w
        return val, grad

    w0 = np.zeros(z.shape[1])
    w0[OPTION_FEATURE_NAMES.index("path_m")] = -1.0
    res = optimize.minimize(loss, w0, jac=True, method="L-BFGS-B")
    return {
        "weights": [round(float(v), 6) for v in res.x],
        "mean": [round(float(v), 6) for v in mean],
        "scale": [round(float(v), 6) for v in scale],
    }


def choice_regret(
    data: LabelledDecisions, scores: Callable[[np.ndarray], np.ndarray]
) -> dict[str, float]:
    """Mean metres of oracle tour lost by choosing ``argmax scores`` against the teacher's
    choice, and the share of decisions where both agree."""
    lost, agree = [], []
    for f, c in zip(data.features, data.cost_to_go_m, strict=True):
        if len(c) < 2 or not np.isfinite(c).any():
            continue
        pick = int(np.argmax(scores(f)))
        best = float(np.nanmin(np.where(np.isfinite(c), c, np.nan)))
        lost.append((c[pick] if np.isfinite(c[pick]) else np.nanmax(c[np.isfinite(c)])) - best)
        agree.append(float(c[pick] <= best + 1e-9))
    if not lost:
        return {"regret_m": float("nan"), "agree": float("nan"), "n": 0}
    return {"regret_m": float(np.mean(lost)), "agree": float(np.mean(agree)), "n": len(lost)}


_SIZE = re.compile(r"size_m=([0-9.]+)")


def training_worlds(cfg: OracleStudentTrainConfig) -> list[str]:
    """The ``train`` parts of ``cfg.splits``, worlds up to ``max_size_m`` (DungeonMaps: 28 m)."""
    from semexplore_gym.evaluation.splits import load_split

    out = []
    for name in cfg.splits:
        for world in load_split(name).parts["train"]:
            m = _SIZE.search(world)
            size = float(m.group(1)) if m else 28.0
            if size <= cfg.max_size_m:
                out.append(world)
    if not out:
        raise ValueError(f"no training world of splits {list(cfg.splits)} is <= {cfg.max_size_m} m")
    return out


def _nearest_scores(f: np.ndarray) -> np.ndarray:
    return -f[:, OPTION_FEATURE_NAMES.index("path_m")]


def _params_layer(
    cfg: OracleStudentTrainConfig, model: dict[str, list[float]] | None
) -> dict[str, Any]:
    layer: dict[str, Any] = {"keep_goal": cfg.keep_goal, "switch_margin": cfg.switch_margin}
    if model is not None:
        layer["model"] = model
    return layer


def train_oracle_student(
    cfg: OracleStudentTrainConfig,
    out_dir: str | Path,
    log: Callable[[str], None] = print,
    run_jobs: Callable[[Sequence[EpisodeJob]], Any] | None = None,
) -> dict[str, Any]:
    """DAgger rounds (see the module); writes into ``out_dir`` and returns the final metrics.

    Args:
        cfg: The settings.
        out_dir: Run directory (resumed when it holds earlier episodes).
        log: Where progress lines go.
        run_jobs: Runs episodes, yielding ``(job, (data, summary))`` as each finishes (default:
            ``cfg.workers`` processes).
    """
    out = Path(out_dir)
    (out / "samples").mkdir(parents=True, exist_ok=True)
    worlds = training_worlds(cfg)
    rng = np.random.default_rng(cfg.seed)
    t0 = time.perf_counter()
    model: dict[str, list[float]] | None = None
    everything = LabelledDecisions()
    history: list[dict[str, Any]] = []
    runner = run_jobs or _process_jobs(cfg.workers)
    for r in range(cfg.rounds):
        if r > 0 and time.perf_counter() - t0 > cfg.wall_budget_s:
            log(f"round {r}: wall budget of {cfg.wall_budget_s:.0f} s spent, stopping")
            break
        picks = rng.integers(0, len(worlds), size=cfg.episodes_per_round)
        seeds = rng.integers(0, 2**31 - 1, size=cfg.episodes_per_round)
        beta = float(cfg.beta[min(r, len(cfg.beta) - 1)])
        jobs = [
            EpisodeJob(
                worlds[int(w)],
                int(s),
                r,
                e,
                _params_layer(cfg, model),
                beta,
                cfg.label_period_s,
                cfg.max_time_s,
                cfg.first_stops,
            )
            for e, (w, s) in enumerate(zip(picks, seeds, strict=True))
        ]
        fresh = _round_data(jobs, out, runner, log)
        everything.extend(fresh)
        drove = _model_scores(model)
        row: dict[str, Any] = {
            "round": r,
            "labels": len(fresh),
            "student": choice_regret(fresh, drove),
            "nearest": choice_regret(fresh, _nearest_scores),
            "wall_s": round(time.perf_counter() - t0, 1),
        }
        model = fit_student_model(everything, cfg.temperature_m, cfg.l2)
        row["fit_on_all"] = choice_regret(everything, _model_scores(model))
        history.append(row)
        (out / "rounds.jsonl").write_text("".join(json.dumps(h) + "\n" for h in history))
        _write_model(out / f"model_round{r}.yaml", cfg, model, row)
        log(
            f"round {r}: {len(fresh)} labels, regret of the driving model "
            f"{row['student']['regret_m']:.2f} m (nearest {row['nearest']['regret_m']:.2f} m), "
            f"agreement {row['student']['agree']:.2f}; {row['wall_s']:.0f} s"
        )
    assert model is not None
    _write_model(out / "model.yaml", cfg, model, history[-1])
    return {"rounds": len(history), "labels": len(everything), "last": history[-1]}


def _model_scores(model: dict[str, list[float]] | None) -> Callable[[np.ndarray], np.ndarray]:
    if model is None:
        return _nearest_scores
    from semexplore_gym.policies.frontier_student import FrontierStudentModel

    m = FrontierStudentModel(**{k: tuple(v) for k, v in model.items()})
    return m.scores


def _round_data(
    jobs: list[EpisodeJob],
    out: Path,
    runner: Callable[[Sequence[EpisodeJob]], Any],
    log: Callable[[str], None],
) -> LabelledDecisions:
    """The round's labels: finished episodes read back, the others run (and saved)."""
    got: dict[int, LabelledDecisions] = {}
    todo = []
    for job in jobs:
        path = out / "samples" / f"round{job.round}_ep{job.episode}.npz"
        if path.is_file():
            got[job.episode] = LabelledDecisions.load(path)
        else:
            todo.append(job)
    for job, (ep, summary) in runner(todo):
        ep.save(out / "samples" / f"round{job.round}_ep{job.episode}.npz")
        with (out / "episodes.jsonl").open("a") as fh:
            fh.write(json.dumps(summary) + "\n")
        log(
            f"  round {job.round} episode {job.episode}: {summary['world']} "
            f"{summary['labels']} labels, {summary['mission_time_s']:.0f} s simulated, "
            f"coverage {summary['coverage']:.3f}, {summary['wall_s']:.0f} s wall"
        )
        got[job.episode] = ep
    data = LabelledDecisions()  # in episode order, however they finished
    for e in sorted(got):
        data.extend(got[e])
    return data


def _process_jobs(workers: int) -> Callable[[Sequence[EpisodeJob]], Any]:
    def run(jobs: Sequence[EpisodeJob]) -> Any:
        import multiprocessing as mp
        from concurrent.futures import ProcessPoolExecutor, as_completed

        if not jobs:
            return
        ctx = mp.get_context("fork")
        with ProcessPoolExecutor(max_workers=min(workers, len(jobs)), mp_context=ctx) as pool:
            futures = {pool.submit(collect_episode, j): j for j in jobs}
            for fut in as_completed(futures):
                yield futures[fut], fut.result()

    return run


def _write_model(
    path: Path, cfg: OracleStudentTrainConfig, model: dict[str, list[float]], row: dict[str, Any]
) -> None:
    import yaml

    head = (
        "# Frontier student (semexplore_gym.policies.frontier_student.FrontierStudentParams layer),\n"
        f"# fitted by semexplore_gym.training.oracle_student on {row.get('round', 0) + 1} DAgger "
        "round(s) of oracle labels.\n"
        f"# features: {', '.join(OPTION_FEATURE_NAMES)}\n"
    )
    path.write_text(head + yaml.safe_dump(_params_layer(cfg, model), sort_keys=False))
