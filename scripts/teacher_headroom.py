"""How much faster the frontier student could be: the oracle's own choices, driven.

Runs the frontier student's training episodes twice on the same worlds and starts (the ``train``
parts of the learning splits, drawn as round 0 of ``semexplore train --algo oracle_student``
draws them): once choosing by the student's model (``--student``, default the nearest frontier)
and once driving the privileged teacher's choice at every labelled decision (``beta = 1``), with
the expert's navigation either way. The ratio of their mission times is the headroom of a
student that imitated the teacher perfectly, at that decision rule. Prints the paired table
(median ratio, wins, two-sided Wilcoxon signed-rank p); one CSV row per mission, written as it
finishes (rerun the command to resume).

Usage::

    python scripts/teacher_headroom.py --out runs/headroom.csv [--episodes 40] [--workers 2]
        [--student runs/oracle_student/model.yaml] [--train-set keep_goal=false ...]
"""

from __future__ import annotations

import argparse
import csv
import sys
from pathlib import Path

import numpy as np

FIELDS = ("episode", "world", "seed", "beta", "mission_time_s", "coverage", "labels", "wall_s")


def main(argv: list[str] | None = None) -> int:
    from concurrent.futures import ProcessPoolExecutor, as_completed

    from scipy.stats import wilcoxon

    from semexplore_gym.config.loading import load_yaml_file
    from semexplore_gym.training.oracle_student import (
        EpisodeJob,
        collect_episode,
        load_oracle_student_config,
        training_worlds,
    )

    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", required=True, help="CSV file (resumed when it exists)")
    ap.add_argument("--episodes", type=int, default=40, help="missions per arm (default: 40)")
    ap.add_argument("--workers", type=int, default=2, help="processes (default: 2)")
    ap.add_argument("--student", default=None, help="model.yaml of a trained student")
    ap.add_argument("--train-config", default=None, help="oracle_student config YAML")
    ap.add_argument("--train-set", action="append", default=[], metavar="KEY=VALUE")
    args = ap.parse_args(argv)
    from semexplore_gym.core.coverage_tour.tour import require_solver

    try:
        require_solver()  # the teacher's tours
    except ImportError as e:
        ap.error(str(e))
    if args.episodes < 1 or args.workers < 1:
        ap.error(f"--episodes and --workers must be >= 1, got {args.episodes}, {args.workers}")
    cfg = load_oracle_student_config(args.train_config, args.train_set)
    params = {"keep_goal": cfg.keep_goal, "switch_margin": cfg.switch_margin}
    if args.student:
        params = dict(load_yaml_file(args.student, "student model") or {})
    worlds = training_worlds(cfg)
    rng = np.random.default_rng(cfg.seed)
    picks = rng.integers(0, len(worlds), size=args.episodes)
    seeds = rng.integers(0, 2**31 - 1, size=args.episodes)
    jobs = [
        EpisodeJob(
            worlds[int(w)],
            int(s),
            0,
            e,
            params,
            beta,
            cfg.label_period_s,
            cfg.max_time_s,
            cfg.first_stops,
        )
        for e, (w, s) in enumerate(zip(picks, seeds, strict=True))
        for beta in (0.0, 1.0)
    ]
    out = Path(args.out)
    done: dict[tuple[int, float], dict[str, str]] = {}
    if out.is_file():
        with out.open() as fh:
            done = {(int(r["episode"]), float(r["beta"])): r for r in csv.DictReader(fh)}
    else:
        out.parent.mkdir(parents=True, exist_ok=True)
        out.write_text(",".join(FIELDS) + "\n")
    todo = [j for j in jobs if (j.episode, j.beta) not in done]
    with ProcessPoolExecutor(max_workers=args.workers) as pool:
        futures = {pool.submit(collect_episode, j): j for j in todo}
        for n, fut in enumerate(as_completed(futures), 1):
            job = futures[fut]
            _, s = fut.result()
            row = {**{k: s[k] for k in FIELDS if k in s}, "episode": job.episode, "beta": job.beta}
            with out.open("a", newline="") as fh:
                csv.DictWriter(fh, FIELDS).writerow(row)
            done[(job.episode, job.beta)] = {k: str(v) for k, v in row.items()}
            print(
                f"{n}/{len(todo)} {job.world} beta={job.beta}: {s['mission_time_s']:.0f} s",
                file=sys.stderr,
                flush=True,
            )
    t0 = np.array([float(done[(e, 0.0)]["mission_time_s"]) for e in range(args.episodes)])
    t1 = np.array([float(done[(e, 1.0)]["mission_time_s"]) for e in range(args.episodes)])
    c0 = np.array([float(done[(e, 0.0)]["coverage"]) for e in range(args.episodes)])
    c1 = np.array([float(done[(e, 1.0)]["coverage"]) for e in range(args.episodes)])
    ratio = t1 / t0
    differs = np.log(ratio)[ratio != 1.0]
    p = float(wilcoxon(differs).pvalue) if len(differs) >= 2 else float("nan")
    print("| arm | n | median mission time (s) | median coverage |")
    print("|---|---:|---:|---:|")
    print(f"| student | {len(t0)} | {np.median(t0):.1f} | {np.median(c0):.3f} |")
    print(f"| teacher's choices | {len(t1)} | {np.median(t1):.1f} | {np.median(c1):.3f} |")
    print(
        f"\nteacher / student mission time: median paired ratio {np.median(ratio):.2f}, "
        f"teacher faster {int((ratio < 1).sum())}/{len(ratio)}, p W = {p:.2g}"
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
