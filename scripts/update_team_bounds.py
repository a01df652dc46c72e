"""Compute the team lower bound of every mission of a team benchmark's ``runs.csv`` again, with
today's bound, and write it into the file's ``lower_bound_s`` column.

    python scripts/update_team_bounds.py docs/results/teams/runs.csv
    python scripts/update_team_bounds.py runs/team_ceiling --out runs/team_ceiling/rebound.csv

The bound (``semexplore_gym.evaluation.team_bound``, privileged: it reads the true world)
depends on the world and the robots' starts only, so it can be computed after the missions:
per (world, seed, team size) the env is built as ``semexplore benchmark --robots`` builds it
and reset with the mission's seed, which draws the same starts. The other columns are kept as
they are; a row whose world has no bound gets an empty cell. Give ``--fixed-start`` and
``--env-set`` as the benchmark run had them (its ``manifest.json``); the run must have used the
default env config. Prints one line per (world, seed, team size): the old and the new bound.
"""

from __future__ import annotations

import argparse
import csv
import sys
from pathlib import Path

#: The columns a team ``runs.csv`` needs here.
NEEDED = ("world", "seed", "n_robots")


def mission_bound_s(
    world: str, seed: int, n_robots: int, *, fixed_start: bool, env_overrides: list[str]
) -> float | None:
    """The team lower bound (s) of the benchmark's mission of ``world``, ``seed`` and team
    size ``n_robots``; None where the world has none."""
    from semexplore_gym.envs.multi_robot import make_multi
    from semexplore_gym.evaluation.team_benchmark import MISSION_OVERRIDES
    from semexplore_gym.evaluation.team_bound import team_lower_bound_s

    start = f"episode.random_start={'false' if fixed_start else 'true'}"
    overrides = [*MISSION_OVERRIDES, start, *env_overrides]
    env = make_multi(world=world, overrides=overrides, n_robots=n_robots)
    try:
        env.reset(seed=seed)
        return team_lower_bound_s(env, (world, seed))
    finally:
        env.close()


def read_team_runs(path: Path) -> tuple[list[str], list[dict[str, str]]]:
    """The header and rows of a team ``runs.csv`` (or of a run folder's)."""
    source = path / "runs.csv" if path.is_dir() else path
    if not source.is_file():
        raise ValueError(f"{source} does not exist (give a team runs.csv or its run folder)")
    with source.open(newline="", encoding="utf-8") as f:
        reader = csv.DictReader(f)
        header = list(reader.fieldnames or [])
        rows = list(reader)
    missing = [c for c in NEEDED if c not in header]
    if missing:
        raise ValueError(f"{source} is no team runs.csv: no column {', '.join(missing)}")
    if not rows:
        raise ValueError(f"{source} has no missions")
    for line, row in enumerate(rows, start=2):
        for column in ("seed", "n_robots"):
            try:
                int(row[column])
            except (TypeError, ValueError):
                raise ValueError(
                    f"{source} line {line}: {column} is {row[column]!r}, not a whole number"
                ) from None
    return header, rows


def new_bounds(
    rows: list[dict[str, str]], fixed_start: bool, env_overrides: list[str]
) -> dict[tuple[str, int, int], str]:
    """Per (world, seed, team size) of ``rows``, today's bound as its ``runs.csv`` cell (empty
    where none), world by world; prints each with the old one."""
    old: dict[tuple[str, int, int], set[str]] = {}
    for r in rows:
        key = (r["world"], int(r["seed"]), int(r["n_robots"]))
        old.setdefault(key, set()).add(r.get("lower_bound_s") or "-")
    bounds = {}
    for world, seed, n in sorted(old, key=lambda c: (c[0], c[2], c[1])):
        bound = mission_bound_s(
            world, seed, n, fixed_start=fixed_start, env_overrides=env_overrides
        )
        new = bounds[(world, seed, n)] = "" if bound is None else f"{round(bound, 3)}"
        was = "/".join(sorted(old[(world, seed, n)]))
        print(f"{world} seed {seed}, {n} robots: {was} -> {new or '-'}", flush=True)
    return bounds


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("runs", help="a team benchmark's runs.csv or run folder")
    p.add_argument("--out", default=None, help="write here instead of rewriting the file")
    p.add_argument("--fixed-start", action="store_true", help="the run used --fixed-start")
    p.add_argument(
        "--env-set", action="append", default=[], metavar="SECTION.KEY=VALUE",
        help="an env override the run had (repeatable)",
    )  # fmt: skip
    args = p.parse_args(argv)
    try:
        header, rows = read_team_runs(Path(args.runs))
        bounds = new_bounds(rows, args.fixed_start, args.env_set)
    except ValueError as e:  # a bad file, world or --env-set
        print(f"error: {e}", file=sys.stderr)
        return 2
    source = Path(args.runs) / "runs.csv" if Path(args.runs).is_dir() else Path(args.runs)
    out = Path(args.out) if args.out else source
    columns = header if "lower_bound_s" in header else [*header, "lower_bound_s"]
    with out.open("w", newline="", encoding="utf-8") as f:
        w = csv.DictWriter(f, fieldnames=columns, lineterminator="\n")
        w.writeheader()
        for r in rows:
            key = (r["world"], int(r["seed"]), int(r["n_robots"]))
            w.writerow({**r, "lower_bound_s": bounds[key]})
    print(f"wrote {out} ({len(rows)} rows, {len(bounds)} bounds)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
