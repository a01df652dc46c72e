"""How does a change of the certified lower bound's parameters move it, world by world?

For each world, the bound of the start ``semexplore oracle WORLD --start-seed S`` uses (a random
start drawn by ``env.reset(seed=S)``), computed with today's parameters and with ``--set``
overrides of :class:`~semexplore_gym.core.coverage_tour.LowerBoundParams`, the two alternated
in one process for ``--rounds`` rounds (every value is a valid bound; they trade speed for
tightness). Prints per world the two bounds (m), their ratio and the median seconds of each;
the bounds are deterministic, the seconds follow the machine's load.

    python scripts/compare_bounds.py --world 'maze:seed=5,size_m=10' --set hop_depth=false
    python scripts/compare_bounds.py --world 'office:seed=1,size_m=20' --set branch_block_m=0.4 \\
        --rounds 2 --json
    python scripts/compare_bounds.py --world 'maze:seed=6,size_m=14' --base branch_block_m=0.1 \\
        --set branch_nested=true

``--base`` changes the first bound too (the second is the first with ``--set`` on top), to
compare two settings of which neither is today's.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import time
from typing import Any


def parse_sets(items: list[str], flag: str = "--set") -> dict[str, Any]:
    """``KEY=VALUE`` strings as bound parameters (values read as YAML, as every ``--*-set``
    flag reads them: ``false``, ``0.2``, ``[1.0, 1.4]``; lists become tuples)."""
    from semexplore_gym.config.builder import parse_override

    out: dict[str, Any] = {}
    for item in items:
        if "=" not in item or not item.partition("=")[0].strip():
            raise ValueError(f"{flag} wants KEY=VALUE, got {item!r}")
        keys, value = parse_override(item)
        out[".".join(keys)] = tuple(value) if isinstance(value, list) else value
    return out


def compare(
    world: str, seed: int, sets: dict[str, Any], rounds: int, base: dict[str, Any] | None = None
) -> dict[str, Any]:
    """Both bounds of ``world`` from the start of ``seed`` (today's parameters with ``base``,
    and with ``base`` and then ``sets``) and the seconds each took."""
    from semexplore_gym.cli.oracle import certified_bound

    start = ["episode.random_start=true"]
    metres: dict[str, float] = {}
    seconds: dict[str, list[float]] = {"default": [], "changed": []}
    for _ in range(rounds):
        for name, params in (("default", base or {}), ("changed", {**(base or {}), **sets})):
            t0 = time.perf_counter()
            bound = certified_bound(world, seed, env_overrides=start, params=params)
            seconds[name].append(time.perf_counter() - t0)
            metres[name] = bound.distance_m
    return {
        "world": world,
        "start_seed": seed,
        "default_m": round(metres["default"], 3),
        "changed_m": round(metres["changed"], 3),
        "ratio": round(metres["changed"] / metres["default"], 4) if metres["default"] else None,
        "default_s": round(statistics.median(seconds["default"]), 2),
        "changed_s": round(statistics.median(seconds["changed"]), 2),
    }


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--world", action="append", required=True, help="a world spec (repeatable)")
    ap.add_argument("--start-seed", type=int, default=0, help="the start's seed (default 0)")
    ap.add_argument(
        "--set", action="append", default=[], metavar="KEY=VALUE",
        help="a LowerBoundParams field for the changed bound (repeatable)",
    )  # fmt: skip
    ap.add_argument(
        "--base", action="append", default=[], metavar="KEY=VALUE",
        help="a LowerBoundParams field for both bounds (repeatable; default: today's)",
    )  # fmt: skip
    ap.add_argument("--rounds", type=int, default=1, help="alternated rounds (default 1)")
    ap.add_argument("--json", action="store_true", help="one JSON line per world")
    args = ap.parse_args(argv)
    if args.rounds < 1:
        print(f"error: --rounds must be at least 1, got {args.rounds}", file=sys.stderr)
        return 2
    try:
        sets = parse_sets(args.set)
        base = parse_sets(args.base, "--base")
        if not sets:
            raise ValueError("give at least one --set KEY=VALUE to compare with")
        if not args.json:
            print(
                "| world | default (m) | changed (m) | changed / default | s default | s changed |"
            )
            print("|---|---:|---:|---:|---:|---:|")
        for world in args.world:
            row = compare(world, args.start_seed, sets, args.rounds, base)
            if args.json:
                print(json.dumps(row), flush=True)
            else:
                cells = [row[k] for k in ("default_m", "changed_m", "ratio")]
                cells += [row["default_s"], row["changed_s"]]
                print(f"| {world} | " + " | ".join(str(c) for c in cells) + " |", flush=True)
    except (ValueError, FileNotFoundError) as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
