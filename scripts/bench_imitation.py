"""Learned agents vs the expert at the expert's own mission time, on held-out worlds.

For every held-out world the scripted expert runs until it stops itself (or ``--expert-max-time-s``);
its mission time ``T_e`` and final coverage are the reference. Each ``--models`` zip then runs on
the same world from the same start (same seed) for ``T_e`` seconds of simulated time, and its
coverage is compared with the expert's::

    python scripts/bench_imitation.py --models runs/bc/model.zip runs/dagger/model.zip \
        --worlds 'maze:size_m=5,seed=*' --seeds 100-104 --out /tmp/il/bench.csv

Missions run through :func:`semexplore_gym.evaluation.harness.run_task` (the benchmark
harness's runner: missions end when the policy stops, not at the env's coverage goal). A CSV
row is appended and flushed per mission, and rows already in ``--out`` are reused, so an
interrupted benchmark resumes where it stopped. The markdown table goes to stdout.
"""

from __future__ import annotations

import argparse
import csv
import math
import sys
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from scipy import stats

CSV_COLUMNS: tuple[str, ...] = (
    "world",
    "seed",
    "policy",
    "expert_time_s",
    "expert_coverage",
    "coverage",
    "ratio",
    "mission_time_s",
    "collisions",
    "wall_time_s",
)

#: ``run(world, policy_spec, seed, max_time_s) -> harness row`` (injectable for tests).
MissionRunner = Callable[[str, str, int, float | None], dict[str, Any]]


def _harness_runner(world: str, policy: str, seed: int, max_time_s: float | None) -> dict[str, Any]:
    from semexplore_gym.evaluation.harness import Task, run_task

    return run_task(Task(world, policy, seed, max_time_s=max_time_s))["row"]


def parse_seed_range(text: str) -> list[int]:
    """``"100-104"`` -> [100, ..., 104]; ``"1,5,7"`` -> [1, 5, 7]."""
    seeds: list[int] = []
    try:
        for part in text.split(","):
            if "-" in part.strip()[1:]:
                lo, hi = part.strip().split("-", 1)
                seeds.extend(range(int(lo), int(hi) + 1))
            elif part.strip():
                seeds.append(int(part))
    except ValueError as e:
        raise ValueError(f"bad seed list {text!r}: use e.g. '100-104' or '1,5,7'") from e
    if not seeds:
        raise ValueError(f"bad seed list {text!r}: no seeds")
    return seeds


def _read_done(path: Path) -> dict[tuple[str, int, str], dict[str, Any]]:
    if not path.is_file():
        return {}
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    done = {}
    for r in rows:
        rec: dict[str, Any] = dict(r)
        rec["seed"] = int(r["seed"])
        for k in ("expert_time_s", "expert_coverage", "coverage", "ratio", "mission_time_s"):
            rec[k] = float(r[k])
        done[(r["world"], rec["seed"], r["policy"])] = rec
    return done


def run_imitation_benchmark(
    worlds: Sequence[str],
    seeds: Sequence[int],
    models: Sequence[str],
    out_csv: str | Path,
    expert: str = "semantic",
    expert_max_time_s: float = 600.0,
    runner: MissionRunner | None = None,
    log: Callable[[str], None] | None = None,
) -> list[dict[str, Any]]:
    """Run the expert, then each model for the expert's mission time; one CSV row per mission.

    Args:
        worlds: World specs; ``seed=*`` is replaced by each seed.
        seeds: Seeds of the worlds and of the start poses (shared by expert and models).
        models: Model zips (run as policy ``sb3:<zip>``) or any other policy spec.
        out_csv: CSV file; existing rows are reused (resume), new ones appended and flushed.
        expert: Policy spec of the reference expert.
        expert_max_time_s: Time limit of the expert's missions.
        runner: Mission runner (default: the benchmark harness's ``run_task``).
        log: Called with a line per finished mission.

    Returns:
        All rows (reused and new), expert rows first per world.
    """
    if not models:
        raise ValueError("need at least one model to compare with the expert")
    if not expert_max_time_s > 0:
        raise ValueError(f"expert_max_time_s must be positive, got {expert_max_time_s!r}")
    run = runner or _harness_runner
    path = Path(out_csv)
    path.parent.mkdir(parents=True, exist_ok=True)
    done = _read_done(path)
    new_file = not path.is_file() or path.stat().st_size == 0
    rows: list[dict[str, Any]] = []
    with open(path, "a", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=CSV_COLUMNS)
        if new_file:
            writer.writeheader()

        def mission(world: str, seed: int, spec: str, limit_s: float, ref: Any) -> dict[str, Any]:
            key = (world, seed, spec)
            if key in done:
                return done[key]
            r = run(world.replace("seed=*", f"seed={seed}"), spec, seed, limit_s)
            t_e, cov_e = (r["mission_time_s"], r["coverage"]) if ref is None else ref
            rec = {
                "world": world,
                "seed": seed,
                "policy": spec,
                "expert_time_s": float(t_e),
                "expert_coverage": float(cov_e),
                "coverage": float(r["coverage"]),
                "ratio": float(r["coverage"]) / float(cov_e) if cov_e > 0 else math.nan,
                "mission_time_s": float(r["mission_time_s"]),
                "collisions": int(r["collisions"]),
                "wall_time_s": round(float(r["wall_time_s"]), 3),
            }
            writer.writerow(rec)
            f.flush()
            if log is not None:
                log(f"{world} seed={seed} {spec}: coverage {rec['coverage']:.3f} at {t_e:.1f} s")
            return rec

        for world in worlds:
            for seed in seeds:
                e = mission(world, seed, expert, expert_max_time_s, None)
                rows.append(e)
                for m in models:
                    spec = m if ":" in m and not m.endswith(".zip") else f"sb3:{m}"
                    rows.append(
                        mission(
                            world,
                            seed,
                            spec,
                            e["expert_time_s"],
                            (e["expert_time_s"], e["expert_coverage"]),
                        )
                    )
    return rows


def markdown_table(rows: Sequence[dict[str, Any]], expert: str = "semantic") -> str:
    """Per-world table (T_e, expert coverage, coverage and ratio per model) plus mean rows."""
    policies = list(dict.fromkeys(r["policy"] for r in rows if r["policy"] != expert))
    worlds = list(dict.fromkeys((r["world"], r["seed"]) for r in rows if r["policy"] == expert))
    by = {(r["world"], r["seed"], r["policy"]): r for r in rows}
    head = ["world", "seed", "T_e (s)", "expert cov."]
    for p in policies:
        head += [f"{p} cov.", f"{p} ratio"]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for w, s in worlds:
        e = by[(w, s, expert)]
        cells = [w, str(s), f"{e['expert_time_s']:.1f}", f"{e['expert_coverage']:.3f}"]
        for p in policies:
            r = by.get((w, s, p))
            cells += [f"{r['coverage']:.3f}", f"{r['ratio']:.2f}"] if r else ["–", "–"]
        lines.append("| " + " | ".join(cells) + " |")
    means = ["mean", "", "", ""]
    for i, p in enumerate(policies):
        rs = [by[(w, s, p)] for w, s in worlds if (w, s, p) in by]
        if i == 0:
            es = [by[(w, s, expert)] for w, s in worlds]
            means[2] = f"{sum(r['expert_time_s'] for r in es) / len(es):.1f}"
            means[3] = f"{sum(r['expert_coverage'] for r in es) / len(es):.3f}"
        means += (
            [
                f"{sum(r['coverage'] for r in rs) / len(rs):.3f}",
                f"{sum(r['ratio'] for r in rs) / len(rs):.2f}",
            ]
            if rs
            else ["–", "–"]
        )
    lines.append("| " + " | ".join(f"**{c}**" if c else "" for c in means) + " |")
    return "\n".join(lines)


def mean_ratios(rows: Sequence[dict[str, Any]], expert: str = "semantic") -> dict[str, float]:
    """Mean coverage ratio (learner / expert at the expert's mission time) per policy."""
    acc: dict[str, list[float]] = {}
    for r in rows:
        if r["policy"] != expert:
            acc.setdefault(r["policy"], []).append(float(r["ratio"]))
    return {p: sum(v) / len(v) for p, v in acc.items()}


def summary_lines(rows: Sequence[dict[str, Any]], expert: str = "semantic") -> list[str]:
    """Per model: mean, median and share of worlds at >= 0.8 of the expert's coverage; per pair
    of models, the paired comparison of their ratios over the worlds both ran (median
    difference, wins, Wilcoxon signed-rank p)."""
    by: dict[str, dict[tuple[str, int], float]] = {}
    for r in rows:
        if r["policy"] != expert:
            by.setdefault(r["policy"], {})[(r["world"], int(r["seed"]))] = float(r["ratio"])
    lines = []
    for policy, ratios in by.items():
        v = np.array(list(ratios.values()))
        lines.append(
            f"{policy}: mean ratio {v.mean():.3f}, median {np.median(v):.3f}, "
            f">= 0.8 on {int((v >= 0.8).sum())}/{len(v)} worlds"
        )
    names = list(by)
    for i, a in enumerate(names):
        for b in names[i + 1 :]:
            keys = sorted(set(by[a]) & set(by[b]))
            if len(keys) < 2:
                continue
            d = np.array([by[a][k] - by[b][k] for k in keys])
            try:
                p = float(stats.wilcoxon(d).pvalue) if np.any(d != 0) else 1.0
            except ValueError:
                p = 1.0
            lines.append(
                f"{a} - {b}: median difference {np.median(d):+.3f} over {len(keys)} worlds, "
                f"{a} ahead on {int((d > 0).sum())}, behind on {int((d < 0).sum())}, "
                f"Wilcoxon p = {p:.3g}"
            )
    return lines


def main(argv: Sequence[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--models", nargs="+", required=True, help="model zips (or policy specs)")
    p.add_argument(
        "--worlds",
        nargs="+",
        default=["maze:size_m=5,seed=*"],
        help="held-out world specs; 'seed=*' takes each seed (default: %(default)s)",
    )
    p.add_argument(
        "--seeds", default="100-104", help="held-out seeds, e.g. 100-104 (default: %(default)s)"
    )
    p.add_argument("--expert", default="semantic", help="reference expert policy spec")
    p.add_argument(
        "--expert-max-time-s", type=float, default=600.0, help="expert mission time limit"
    )
    p.add_argument("--out", default="bench_imitation.csv", help="CSV of all missions (resumable)")
    p.add_argument("--torch-threads", type=int, default=1, help="torch.set_num_threads value")
    args = p.parse_args(argv)
    try:
        seeds = parse_seed_range(args.seeds)
    except ValueError as e:
        p.error(str(e))
    try:
        import torch

        torch.set_num_threads(args.torch_threads)
    except ImportError:
        pass
    rows = run_imitation_benchmark(
        args.worlds,
        seeds,
        args.models,
        args.out,
        expert=args.expert,
        expert_max_time_s=args.expert_max_time_s,
        log=lambda line: print(line, file=sys.stderr, flush=True),
    )
    print(markdown_table(rows, args.expert))
    print()
    for policy, ratio in mean_ratios(rows, args.expert).items():
        print(f"mean ratio {policy}: {ratio:.3f}")
    for line in summary_lines(rows, args.expert):
        print(line)
    return 0


if __name__ == "__main__":
    sys.exit(main())
