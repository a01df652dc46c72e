"""``semexplore compare-weights``: paper vs tuned planner weights, with a semantic-term ablation.

1. Tune the frontier cost weights w_v, w_p, w_I of the paper (config keys ``cost.w_v``,
   ``cost.w_p``, ``cost.w_i``; ``--tune-field``: also ``potential_field.f_g/f_o/f_l``) with Optuna
   TPE on the training worlds x training seeds (objective: mean of
   ``mission_time_s + penalty_s * max(0, target_coverage - coverage)``). The study is kept in
   ``OUT/tuning/study.sqlite`` and every trial in ``OUT/tuning/trials.jsonl``.
2. Run every weight set on the test worlds x test seeds through the benchmark harness
   (``OUT/test/runs.csv``, resumable): ``semantic[paper]``, ``semantic[tuned]`` (labels) and the
   ablations of the paper weights, spelled as policy specs that ``explore --policy`` and
   ``benchmark --policies`` run as they are: ``semantic[cost.w_p=0]``, ``semantic[cost.w_i=0]``
   (w_I = 0), ``semantic[cost.w_p=0;cost.w_i=0]`` (the expert's defaults are the paper's weights).
   ``--agents`` adds learned agents (any policy spec, e.g. a ``SemanticExploreWeights-v0`` PPO
   model that chooses the weights at every decision: ``sb3:runs/pw/model.zip[learned]``) on the
   same test worlds and seeds.
3. Write ``OUT/compare.md`` and ``OUT/compare.csv`` (median mission time, coverage, score,
   Mann-Whitney U p-value of each set's mission times against the paper's) and
   ``OUT/mission_times.png`` (box plot per weight set). ``OUT/weights.json`` has every set.

Test seeds start at ``--test-seed0`` (default 1000) so ``seed=*`` procedural test worlds are
disjoint from the training ones. ``--test-suite mazes,offices,caves`` tests on benchmark suites
instead (``configs/suites``): each world with its suite's time limit, runs and start seeds, as
``semexplore benchmark --suite`` runs them (so the paper row repeats that run's ``semantic``
missions). ``OUT/test/summary.md`` compares every set with the paper's per family, paired by
(world, seed).

The default budget (20 trials on 2 training seeds per world, 5 test seeds, 300 s missions) is a
demo that runs in minutes: weights tuned on so few, often cut-short missions can well be slower
than the paper's. The comparison in the docs (docs/learning.md, "Hand-tuned vs learned
weights": tuned and paper weights within 1 % of each other) is reproduced by
``--train-worlds 'maze:seed=*,size_m=6' --test-worlds 'maze:seed=*,size_m=6' --trials 16
--runs 10 --max-time-s 600``. Example::

    semexplore compare-weights --train-worlds 'maze:seed=*,size_m=4' \\
        --test-worlds 'maze:seed=*,size_m=4' --trials 20 --runs 5 --max-time-s 120 --out runs/cw
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import shlex
import sys
from dataclasses import replace
from pathlib import Path
from typing import Any

from semexplore_gym.cli import describe
from semexplore_gym.cli._flags import add_renamed_flag
from semexplore_gym.cli._output import add_json_flag, print_result
from semexplore_gym.core.validation import short_repr
from semexplore_gym.evaluation.errors import ParameterError

#: Defaults of --runs, --test-seed0 and --max-time-s with --test-worlds.
DEFAULT_TEST_RUNS = 5
DEFAULT_TEST_SEED0 = 1000
DEFAULT_MAX_TIME_S = 300.0
#: First test seed with --test-suite: the one ``semexplore benchmark --suite`` starts from.
SUITE_SEED0 = 0

PAPER = "semantic[paper]"
TUNED = "semantic[tuned]"
ABLATE_P = "semantic[cost.w_p=0]"
ABLATE_I = "semantic[cost.w_i=0]"
ABLATE_BOTH = "semantic[cost.w_p=0;cost.w_i=0]"


def validate_args(args: argparse.Namespace) -> None:
    """Check every number and the output path before anything is loaded or tuned.

    Raises:
        ValueError: naming the argument and its value.
    """
    checks = (
        ("--max-time-s", args.max_time_s, args.max_time_s is None or 0 < args.max_time_s <= 1e7),
        (
            "--train-max-time-s",
            args.train_max_time_s,
            args.train_max_time_s is None or 0 < args.train_max_time_s <= 1e7,
        ),
        ("--target-coverage", args.target_coverage, 0.0 < args.target_coverage <= 1.0),
        ("--penalty-s", args.penalty_s, math.isfinite(args.penalty_s) and args.penalty_s >= 0),
        ("--trials", args.trials, 1 <= args.trials <= 100_000),
        ("--runs", args.runs, args.runs is None or 1 <= args.runs <= 100_000),
        ("--train-runs", args.train_runs, 1 <= args.train_runs <= 100_000),
        ("--workers", args.workers, 1 <= args.workers <= 256),
        ("--train-seed0", args.train_seed0, 0 <= args.train_seed0 <= 2**31),
        ("--test-seed0", args.test_seed0, args.test_seed0 is None or 0 <= args.test_seed0 <= 2**31),
        ("--seed", args.seed, 0 <= args.seed <= 2**32 - 1),
    )
    for flag, value, ok in checks:
        if not ok:
            raise ValueError(f"{flag}: {value!r} is out of range (see --help)")
    out = Path(args.out)
    if out.exists() and not out.is_dir():
        raise ValueError(f"--out {short_repr(args.out)} is an existing file; give a directory")


def split_worlds(text: str) -> list[str]:
    from semexplore_gym.cli.world_lists import split_worlds as split

    return split(text)


def weight_sets(tuned: dict[str, float]) -> dict[str, dict[str, float]]:
    """Label -> dotted overrides: paper, tuned and the ablations of the paper's semantic terms."""
    from semexplore_gym.training.weight_tuning import PAPER_WEIGHTS

    return {
        PAPER: dict(PAPER_WEIGHTS),
        TUNED: {**PAPER_WEIGHTS, **tuned},
        # Policy specs, not only labels: each bracket sets what its overrides set.
        ABLATE_P: {**PAPER_WEIGHTS, "cost.w_p": 0.0},
        ABLATE_I: {**PAPER_WEIGHTS, "cost.w_i": 0.0},
        ABLATE_BOTH: {**PAPER_WEIGHTS, "cost.w_p": 0.0, "cost.w_i": 0.0},
    }


def tuned_is_paper(sets: dict[str, dict[str, float]]) -> bool:
    """True when no tuning trial beat the paper's weights: ``semantic[tuned]`` is the paper's
    set (trial 0 is the paper's, and ties keep it)."""
    tuned, paper = sets.get(TUNED, {}), sets.get(PAPER, {})
    return set(tuned) == set(paper) and all(math.isclose(tuned[k], paper[k]) for k in paper)


#: Said in ``compare.md`` and on stderr when :func:`tuned_is_paper`.
TUNED_IS_PAPER_NOTE = (
    f"No tuning trial beat the paper's weights: `{TUNED}` is the paper's set, so its row "
    "differs from the paper's only by chance (run more --trials to tune)."
)


def summarise(
    rows: list[dict[str, Any]], labels: list[str], target_coverage: float, penalty_s: float
) -> list[dict[str, Any]]:
    """One table row per label: medians, completion rate, score and p-values vs the paper.

    ``p_value_vs_paper`` compares mission times, ``p_value_score_vs_paper`` the scores
    (``mission_score``: time plus the missing-coverage penalty; informative when missions hit the
    time limit), both with a two-sided Mann-Whitney U test against ``semantic[paper]``.
    """
    import numpy as np
    from scipy.stats import mannwhitneyu

    from semexplore_gym.training.weight_tuning import mission_score

    def score(r: dict[str, Any]) -> float:
        return mission_score(
            float(r["mission_time_s"]), float(r["coverage"]), target_coverage, penalty_s
        )

    def p_value(a: np.ndarray, b: np.ndarray) -> float:
        if not len(a) or not len(b):
            return math.nan
        if np.ptp(np.concatenate([a, b])) == 0:
            return 1.0  # all values tied: scipy warns and returns nan
        return float(mannwhitneyu(a, b, alternative="two-sided").pvalue)

    by_label: dict[str, list[dict[str, Any]]] = {lab: [] for lab in labels}
    for r in rows:
        if r["policy"] in by_label:
            by_label[r["policy"]].append(r)
    paper_rows = by_label.get(PAPER, [])
    ref_times = np.array([float(r["mission_time_s"]) for r in paper_rows])
    ref_scores = np.array([score(r) for r in paper_rows])
    table = []
    for lab in labels:
        rs = by_label[lab]
        times = np.array([float(r["mission_time_s"]) for r in rs])
        cov = np.array([float(r["coverage"]) for r in rs])
        scores = np.array([score(r) for r in rs])
        nan = math.nan
        table.append(
            {
                "weights": lab,
                "n": len(rs),
                "median_mission_time_s": float(np.median(times)) if len(rs) else nan,
                "median_coverage": float(np.median(cov)) if len(rs) else nan,
                "mean_coverage": float(np.mean(cov)) if len(rs) else nan,
                "completed_fraction": float(np.mean(cov >= target_coverage)) if len(rs) else nan,
                "mean_score": float(np.mean(scores)) if len(rs) else nan,
                "p_value_vs_paper": nan if lab == PAPER else p_value(times, ref_times),
                "p_value_score_vs_paper": nan if lab == PAPER else p_value(scores, ref_scores),
            }
        )
    return table


def write_table(
    out: Path,
    table: list[dict[str, Any]],
    sets: dict[str, dict[str, float]],
    agents: list[str] | None = None,
) -> tuple[Path, Path]:
    """``compare.csv`` and ``compare.md`` from :func:`summarise` rows (``agents``: their specs)."""
    cols = list(table[0])
    csv_path = out / "compare.csv"
    with csv_path.open("w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=cols)
        w.writeheader()
        w.writerows(table)

    def fmt(v: Any) -> str:
        if isinstance(v, float):
            return "-" if math.isnan(v) else f"{v:.4g}"
        return str(v)

    lines = [
        "| " + " | ".join(cols) + " |",
        "|" + "---|" * len(cols),
        *("| " + " | ".join(fmt(r[c]) for c in cols) + " |" for r in table),
        "",
        "Weights:",
        "",
        *(
            f"- `{lab}`: " + ", ".join(f"{k}={v:.4g}" for k, v in ws.items())
            for lab, ws in sets.items()
        ),
        *(f"- `{spec}`: learned agent (policy spec)" for spec in agents or []),
        "",
        "Per family, each set against the paper's paired by (world, seed): `test/summary.md`.",
        "",
    ]
    if tuned_is_paper(sets):
        lines[-1:-1] = ["", TUNED_IS_PAPER_NOTE]
    md_path = out / "compare.md"
    md_path.write_text("\n".join(lines))
    return csv_path, md_path


def write_boxplot(out: Path, rows: list[dict[str, Any]], labels: list[str]) -> Path:
    """Box plot of mission times per weight set (``mission_times.png``)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    data = [[float(r["mission_time_s"]) for r in rows if r["policy"] == lab] for lab in labels]
    fig, ax = plt.subplots(figsize=(1.8 * len(labels) + 2, 4))
    ax.boxplot(data, showmeans=True)
    ax.set_xticks(range(1, len(labels) + 1))
    ax.set_xticklabels([lab.removeprefix("semantic") for lab in labels], rotation=20, ha="right")
    ax.set_ylabel("mission time (simulated s)")
    ax.set_title("Mission time per weight set (test worlds)")
    ax.grid(axis="y", alpha=0.3)
    fig.tight_layout()
    path = out / "mission_times.png"
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path


def add_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    p = sub.add_parser(
        "compare-weights",
        help="tune the planner weights with Optuna and compare them with the paper's (and ablations)",
        description=describe(__doc__),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument(
        "--train-worlds",
        required=True,
        help="comma-separated training worlds ('maze:seed=*,size_m=4')",
    )
    test = p.add_mutually_exclusive_group(required=True)
    test.add_argument("--test-worlds", help="comma-separated test worlds")
    test.add_argument(
        "--test-suite",
        help="comma-separated benchmark suites to test on instead (configs/suites: mazes, "
        "offices, caves, ...; or suite YAML paths), with each suite's worlds, time limits and "
        "start seeds",
    )
    p.add_argument("--out", required=True, help="output directory; rerunning resumes")
    p.add_argument("--trials", type=int, default=20, help="Optuna trials (default: %(default)s)")
    p.add_argument(
        "--train-runs", type=int, default=2, help="seeds per training world (default: %(default)s)"
    )
    p.add_argument(
        "--runs",
        type=int,
        default=None,
        help=f"seeds per test world (default: {DEFAULT_TEST_RUNS}; with --test-suite the suite's runs)",
    )
    p.add_argument(
        "--train-seed0", type=int, default=0, help="first training seed (default: %(default)s)"
    )
    p.add_argument(
        "--test-seed0",
        type=int,
        default=None,
        help=f"first test seed (default: {DEFAULT_TEST_SEED0}; with --test-suite {SUITE_SEED0}, "
        "the seeds semexplore benchmark --suite uses)",
    )
    p.add_argument(
        "--max-time-s",
        type=float,
        default=None,
        help=f"simulated time limit per mission (default: {DEFAULT_MAX_TIME_S:g}; with "
        "--test-suite it replaces the suites' own limits only when given)",
    )
    p.add_argument(
        "--train-max-time-s",
        type=float,
        default=None,
        help="time limit of the tuning missions (default: --max-time-s, or "
        f"{DEFAULT_MAX_TIME_S:g})",
    )
    _add_scoring_and_run_arguments(p)
    return p


def _add_scoring_and_run_arguments(p: argparse.ArgumentParser) -> None:
    """The score, agent, seed, config and parallelism options of ``compare-weights``."""
    p.add_argument(
        "--target-coverage",
        type=float,
        default=0.97,
        help="coverage below this is penalised (default: %(default)s)",
    )
    p.add_argument(
        "--penalty-s",
        type=float,
        default=600.0,
        help="seconds per unit of missing coverage (default: %(default)s)",
    )
    p.add_argument(
        "--tune-field", action="store_true", help="also tune the potential field's f_g, f_o, f_l"
    )
    p.add_argument(
        "--agents",
        default="",
        help="comma-separated policy specs compared on the test worlds too, e.g. "
        "'sb3:runs/pw/model.zip[learned weights]'. sb3:MODEL.zip and py: specs run code from "
        "the named file: use only files from trusted sources",
    )
    p.add_argument("--seed", type=int, default=0, help="TPE sampler seed (default: %(default)s)")
    p.add_argument("--env-config", default=None, help="env config: preset name or YAML path")
    p.add_argument("--no-progress", action="store_true", help="no progress bars")
    add_json_flag(p, "the tuned weights and the report paths")
    add_renamed_flag(p, "--config", "use --env-config (env config preset or YAML)")
    p.add_argument(
        "--workers",
        type=int,
        default=1,
        help="test missions in parallel processes (default: %(default)s)",
    )


def _checked_worlds(flag: str, text: str, seed: int) -> list[str]:
    """The worlds ``flag`` lists, each once and each buildable (``seed=*`` with ``seed``)."""
    from semexplore_gym.cli.world_lists import check_worlds, refuse_repeats, split_worlds

    worlds = split_worlds(text)
    if not worlds:
        raise ValueError(f"{flag} must name at least one world")
    refuse_repeats(flag, worlds)
    try:
        check_worlds(worlds, seed)
    except (ValueError, FileNotFoundError) as e:
        raise ValueError(f"{flag}: {e}") from None
    return worlds


def _check_run_args(
    args: argparse.Namespace,
) -> tuple[list[str], list[int], list[Any], list[str], list[dict[str, Any]]]:
    """Everything is checked before the tuning starts: a typo must not cost an Optuna run.

    Returns:
        ``(train_worlds, train_seeds, test_tasks, agents, suites)``: the test tasks of every
        weight set and agent, without the weight sets' overrides (known after the tuning), and
        the name and version of each ``--test-suite`` (empty with ``--test-worlds``).
    """
    from semexplore_gym.evaluation.harness import expand_tasks, parse_seeds

    validate_args(args)
    train_seeds = parse_seeds(args.train_runs, args.train_seed0)
    train_worlds = _checked_worlds("--train-worlds", args.train_worlds, train_seeds[0])
    if args.env_config is not None:
        from semexplore_gym.envs.env_config import load_env_config

        load_env_config(args.env_config)
    from semexplore_gym.policies.specs import split_specs

    agents = split_specs(args.agents)
    if agents:
        from semexplore_gym.policies.registry import make_policy
        from semexplore_gym.policies.specs import strip_label

        for spec in agents:
            if strip_label(spec).partition(":")[0] == "semantic":
                raise ValueError(
                    f"--agents {spec!r}: weight sets of the expert are built in; give learned "
                    "or other agents here"
                )
            try:
                make_policy(spec)  # a bad path or spec fails now, not after the tuning
            except (ValueError, FileNotFoundError) as e:
                raise ValueError(f"--agents {spec!r}: {e}") from None
    labels = [*weight_sets({}), *agents]
    if args.test_suite is not None:
        from semexplore_gym.cli.world_lists import split_list
        from semexplore_gym.evaluation.suites import suite_tasks

        seed0 = SUITE_SEED0 if args.test_seed0 is None else args.test_seed0
        try:
            tasks, suites, test_worlds = suite_tasks(
                split_list(args.test_suite),
                labels,
                lambda runs: parse_seeds(args.runs or runs, seed0),
                max_time_s=args.max_time_s,
                env_config=args.env_config,
            )
        except ParameterError as e:
            raise e.for_flags({"names": "--test-suite", "runs": "--runs"}) from None
    else:
        suites = []
        seed0 = DEFAULT_TEST_SEED0 if args.test_seed0 is None else args.test_seed0
        test_seeds = parse_seeds(args.runs or DEFAULT_TEST_RUNS, seed0)
        test_worlds = _checked_worlds("--test-worlds", args.test_worlds, test_seeds[0])
        limit = DEFAULT_MAX_TIME_S if args.max_time_s is None else args.max_time_s
        tasks = expand_tasks(
            test_worlds, labels, test_seeds, max_time_s=limit, env_config=args.env_config
        )
    overlap = set(train_seeds) & {t.seed for t in tasks}
    if overlap and set(train_worlds) & set(test_worlds):
        raise ValueError(
            f"training and test (world, seed) pairs overlap on seeds {sorted(overlap)}; change --test-seed0"
        )
    return train_worlds, train_seeds, tasks, agents, suites


def _train_limit_s(args: argparse.Namespace) -> float:
    """The tuning missions' time limit: --train-max-time-s, else --max-time-s, else the default."""
    for value in (args.train_max_time_s, args.max_time_s):
        if value is not None:
            return float(value)
    return DEFAULT_MAX_TIME_S


def _run_test_missions(tasks: list[Any], out_dir: Path, args: argparse.Namespace) -> Any:
    """The test missions through the benchmark harness, its errors in flag names."""
    from semexplore_gym.evaluation.harness import run_benchmark

    try:
        return run_benchmark(tasks, out_dir, workers=args.workers, progress=not args.no_progress)
    except ParameterError as e:
        raise e.for_flags({"out_dir": "--out", "workers": "--workers"}) from None


def run(args: argparse.Namespace) -> int:
    from semexplore_gym.evaluation.harness import read_runs, write_manifest
    from semexplore_gym.evaluation.report import write_summary
    from semexplore_gym.training.weight_tuning import (
        PAPER_FIELD,
        PAPER_WEIGHTS,
        SearchSpace,
        StudySettings,
        mission_objective,
        tune_weights,
    )

    train_worlds, train_seeds, test_tasks, agents, suites = _check_run_args(args)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    write_manifest(
        out,
        {
            "command": " ".join(shlex.quote(a) for a in sys.argv),
            **{k: v for k, v in vars(args).items() if not k.startswith("_")},
        },
    )

    space = SearchSpace.with_field() if args.tune_field else SearchSpace()
    start = {**PAPER_WEIGHTS, **(PAPER_FIELD if args.tune_field else {})}
    objective = mission_objective(
        train_worlds,
        train_seeds,
        _train_limit_s(args),
        args.target_coverage,
        args.penalty_s,
        env_config=args.env_config,
    )

    def show(number: int, weights: dict[str, float], value: float) -> None:
        if not args.no_progress:
            ws = ", ".join(f"{k.split('.')[-1]}={v:.3g}" for k, v in weights.items())
            print(f"trial {number}: {value:.2f} ({ws})", file=sys.stderr)

    study = StudySettings(
        seed=args.seed,
        storage_path=out / "tuning" / "study.sqlite",
        jsonl_path=out / "tuning" / "trials.jsonl",
    )
    result = tune_weights(objective, args.trials, space, study, enqueue=[start], on_trial=show)
    sets = weight_sets(result.best_weights)
    (out / "weights.json").write_text(
        json.dumps({"sets": sets, "best_train_value": result.best_value}, indent=2)
    )

    tasks = [replace(t, policy_overrides=dict(sets.get(t.policy, {}))) for t in test_tasks]
    # OUT/test is a benchmark directory: its manifest names the suites for its summary.
    (out / "test").mkdir(exist_ok=True)
    write_manifest(out / "test", {"suites": suites or None, "weight_sets": sets})
    res = _run_test_missions(tasks, out / "test", args)
    rows = read_runs(out / "test" / "runs.csv")
    summary = write_summary(out / "test", reference=PAPER)
    labels = [*sets, *agents]
    table = summarise(rows, labels, args.target_coverage, args.penalty_s)
    csv_path, md_path = write_table(out, table, sets, agents)
    plot = write_boxplot(out, rows, labels)
    report = {
        "trials": len(result.trials),
        "best_train_value": result.best_value,
        "tuned": result.best_weights,
        "tuned_is_paper": tuned_is_paper(sets),
        "table": str(md_path),
        "csv": str(csv_path),
        "plot": str(plot),
        "per_family": str(summary),
        "failed": len(res["failed"]),
    }
    print_result(args, report, md_path.read_text())
    if tuned_is_paper(sets):
        print(TUNED_IS_PAPER_NOTE.replace("`", ""), file=sys.stderr)
    return 1 if res["failed"] else 0
