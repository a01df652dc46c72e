"""Robustness sweep: a policy on hundreds of procedural worlds of every family, random starts.

    python scripts/robustness_sweep.py --per-family 60 --workers 2 --out runs/sweep
    python scripts/robustness_sweep.py --per-family 60 --policies semantic,nearest --families cave,forest --out runs/sweep_pair

Worlds are drawn deterministically from the families below (sizes and parameters cycle, seeds
are ``--seed0 + i``), so the same command always sweeps the same worlds. Each world runs once per
policy from a random start pose (``episode.random_start``; the same start for every policy).
Missions go through the benchmark harness: ``OUT/runs.csv`` is written as missions finish and a
rerun resumes. Then ``OUT/sweep.md`` gets, per family and policy: missions, share that ended by
self-stop at coverage >= ``--ok-coverage``, share truncated, collisions, median mission time and
coverage, and a list of every failure with its stop reason. ``--gifs`` re-runs each failure of
the first policy with an animation in ``OUT/failures/``.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

import numpy as np

from semexplore_gym.evaluation.suites import world_family

#: Per family, the parameter sets that cycle over the sweep's worlds (sizes small to large).
FAMILIES: dict[str, list[str]] = {
    "maze": [
        "size_m=6",
        "size_m=8,braid=0.3",
        "size_m=10,corridor_width_m=0.8",
        "size_m=12,braid=0.5",
        "size_m=14,corridor_width_m=1.2",
    ],
    "office": [
        "size_m=10",
        "size_m=12,clutter=1",
        "size_m=14",
        "size_m=16,clutter=0.5",
        "size_m=20",
    ],
    "cave": [
        "size_m=8,min_passage_m=0.5",
        "size_m=10",
        "size_m=10,min_passage_m=0.45,feature_size_m=0.6",
        "size_m=12,min_passage_m=0.8",
        "size_m=15",
    ],
    "noisecave": [
        "size_m=8,threshold=0.4",
        "size_m=10,threshold=0.44",
        "size_m=12,threshold=0.48",
        "size_m=14,threshold=0.42",
        "size_m=16,threshold=0.46",
    ],
    "forest": [
        "size_m=6,density=10",
        "size_m=8",
        "size_m=8,density=15,min_gap_m=0.5",
        "size_m=10,density=6,trunk_radius_max_m=0.8",
        "size_m=12,density=10",
    ],
}

#: One time limit for every mission of the sweep (its largest worlds need ~900 s at 0.22 m/s).
DEFAULT_MAX_TIME_S = 1500.0


def sweep_worlds(families: list[str], per_family: int, seed0: int) -> list[str]:
    """The sweep's world spellings, ``per_family`` of each family, deterministic."""
    worlds = []
    for family in families:
        variants = FAMILIES[family]
        for i in range(per_family):
            worlds.append(f"{family}:seed={seed0 + i},{variants[i % len(variants)]}")
    return worlds


def _ok(row: dict[str, Any], ok_coverage: float) -> bool:
    return bool(row["self_stopped"]) and float(row["coverage"]) >= ok_coverage


def summarise(rows: list[dict[str, Any]], ok_coverage: float) -> str:
    """Markdown tables: per family and policy, then every failure."""
    lines = [
        f"| family | policy | missions | self-stopped at coverage >= {ok_coverage} | truncated "
        "| collisions | median mission time (s) | median coverage |",
        "|---|---|---:|---:|---:|---:|---:|---:|",
    ]
    keys = sorted({(world_family(r["world"]), r["policy"]) for r in rows})
    for family, policy in [*keys, ("all", None)]:
        sel = [
            r
            for r in rows
            if (family == "all" or world_family(r["world"]) == family)
            and (policy is None or r["policy"] == policy)
        ]
        if not sel:
            continue
        ok = sum(_ok(r, ok_coverage) for r in sel)
        trunc = sum(not r["self_stopped"] for r in sel)
        coll = sum(int(r["collisions"]) for r in sel)
        t = np.median([float(r["mission_time_s"]) for r in sel])
        c = np.median([float(r["coverage"]) for r in sel])
        label = policy if policy is not None else "all"
        lines.append(
            f"| {family} | {label} | {len(sel)} | {ok}/{len(sel)} ({100 * ok / len(sel):.1f} %) "
            f"| {trunc} | {coll} | {t:.1f} | {c:.3f} |"
        )
    failures = [r for r in rows if not _ok(r, ok_coverage) or int(r["collisions"]) > 0]
    lines += ["", f"Failures ({len(failures)}):", ""]
    for r in failures:
        lines.append(
            f"- `{r['world']}` {r['policy']} seed {r['seed']}: coverage {float(r['coverage']):.3f}, "
            f"{float(r['mission_time_s']):.0f} s, collisions {r['collisions']}, {r['stop_reason']}"
        )
    return "\n".join(lines) + "\n"


def _gif_failures(out: Path, rows: list[dict[str, Any]], policy: str, ok_coverage: float) -> None:
    import gymnasium as gym
    from semexplore_gym.policies.registry import make_policy

    import semexplore_gym  # noqa: F401
    from semexplore_gym.evaluation.rollout import GifOptions, run_mission

    gif_dir = out / "failures"
    gif_dir.mkdir(exist_ok=True)
    for r in rows:
        if r["policy"] != policy or _ok(r, ok_coverage):
            continue
        name = f"{r['world']}__{r['seed']}".replace(":", "_").replace(",", "_").replace("=", "")
        path = gif_dir / f"{name}.gif"
        if path.exists():
            continue
        env = gym.make(
            "SemanticExplore-v0",
            world=r["world"],
            config={"episode": {"random_start": True}},
            render_mode="rgb_array",
        )
        try:
            run_mission(
                env, make_policy(policy), seed=int(r["seed"]), progress=False,
                gif=GifOptions(path, every_s=8.0), ignore_terminated=True,
            )  # fmt: skip
        finally:
            env.close()
        print(f"failure animation -> {path}", file=sys.stderr)


def parse_args(argv: list[str] | None = None) -> argparse.Namespace:
    """The command line, checked (families, counts) before anything is loaded or run."""
    ap = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    ap.add_argument(
        "--families",
        default=",".join(FAMILIES),
        help="comma-separated families (default: %(default)s)",
    )
    ap.add_argument(
        "--per-family", type=int, default=75, help="worlds per family (default: %(default)s)"
    )
    ap.add_argument(
        "--policies", default="semantic", help="comma-separated policy specs (default: %(default)s)"
    )
    ap.add_argument(
        "--seed0", type=int, default=1000, help="seed of the first world (default: %(default)s)"
    )
    ap.add_argument(
        "--max-time-s",
        type=float,
        default=DEFAULT_MAX_TIME_S,
        help="mission time limit (default: %(default)s s)",
    )
    ap.add_argument(
        "--ok-coverage",
        type=float,
        default=0.97,
        help="coverage a mission must reach (default: %(default)s)",
    )
    ap.add_argument(
        "--workers", type=int, default=1, help="missions in parallel (default: %(default)s)"
    )
    ap.add_argument("--gifs", action="store_true", help="animate every failure of the first policy")
    ap.add_argument("--no-progress", action="store_true", help="no progress bar")
    ap.add_argument("--out", required=True, help="output directory; rerunning resumes")
    args = ap.parse_args(argv)  # fmt: skip

    families = [f.strip() for f in args.families.split(",") if f.strip()]
    unknown = [f for f in families if f not in FAMILIES]
    if unknown or not families:
        ap.error(f"--families: unknown {unknown!r}; choose from {', '.join(FAMILIES)}")
    if not 1 <= args.per_family <= 10_000:
        ap.error(f"--per-family must be in [1, 10000], got {args.per_family}")
    if not 0.0 < args.ok_coverage <= 1.0:
        ap.error(f"--ok-coverage must be in (0, 1], got {args.ok_coverage}")
    args.families = families
    return args


def main(argv: list[str] | None = None) -> int:
    from semexplore_gym.policies.specs import split_specs

    from semexplore_gym.envs.env_config import load_env_config
    from semexplore_gym.evaluation.harness import Task, read_runs, run_benchmark

    args = parse_args(argv)
    families = args.families
    policies = split_specs(args.policies)  # a comma inside [...] stays with its spec

    worlds = sweep_worlds(families, args.per_family, args.seed0)
    limit_s = args.max_time_s or DEFAULT_MAX_TIME_S
    env_config = load_env_config(
        None, ["episode.random_start=true", f"episode.max_time_s={limit_s:g}"]
    )
    # One mission per world and policy: the world's own seed also seeds the start pose.
    tasks = [
        Task(w, p, int(w.split("seed=")[1].split(",")[0]), limit_s, env_config)
        for w in worlds
        for p in policies
    ]
    out = Path(args.out)
    res = run_benchmark(tasks, out, workers=args.workers, progress=not args.no_progress)
    rows = [r for r in read_runs(out / "runs.csv") if r["world"] in set(worlds)]
    text = summarise(rows, args.ok_coverage)
    (out / "sweep.md").write_text(text)
    print(text)
    if args.gifs:
        _gif_failures(out, rows, policies[0], args.ok_coverage)
    return 1 if res["failed"] else 0


if __name__ == "__main__":
    sys.exit(main())
