"""Perfect map against SLAM: the same missions paired, per world family and policy.

Reads the ``runs.csv`` of benchmarks run on the perfect map (``--env-config default``) and of
the same command with ``--env-config slam``, pairs the missions by (world, policy, seed) and
prints markdown tables:

- per family and policy: missions paired; self-stops at true coverage >= 0.97 on each map;
  collisions; the median SLAM / perfect mission-time ratio with the Wilcoxon signed-rank p on
  the log ratios; the SLAM figures (median ATE, median odometry ATE / ATE, map error, loop
  closures); false stops and lost missions; the median SLAM / perfect wall-time ratio;
- per family and map: the semantic expert's mission time over frontier's and nearest's on the
  same (world, seed), median with the Wilcoxon p.

    python scripts/compare_slam.py runs/perfect runs/slam
    python scripts/compare_slam.py runs/a-perfect,runs/b-perfect runs/a-slam,runs/b-slam
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path
from typing import Any

import numpy as np

from semexplore_gym.evaluation.run_row import read_runs
from semexplore_gym.evaluation.suites import world_family

Key = tuple[str, str, int]
#: A self-stop at this true coverage or more counts as a finished mission.
GOOD_COVERAGE = 0.97


def load(dirs: str) -> dict[Key, dict[str, Any]]:
    """The missions of the comma-separated benchmark directories ``dirs`` by (world, policy,
    seed); a directory without ``runs.csv`` is an error."""
    rows: dict[Key, dict[str, Any]] = {}
    for d in (p for p in dirs.split(",") if p):
        path = Path(d) / "runs.csv"
        if not path.is_file():
            raise ValueError(f"no runs.csv in {d!r}")
        for r in read_runs(path):
            rows[(r["world"], r["policy"], int(r["seed"]))] = r
    return rows


def median_p(ratios: list[float]) -> str:
    """``median (p = ...)`` of positive ratios, p the two-sided Wilcoxon signed-rank test on
    their logs (``–`` for p with fewer than 2 pairs or all ratios 1)."""
    v = np.array([r for r in ratios if r > 0 and math.isfinite(r)], dtype=np.float64)
    if v.size == 0:
        return "–"
    logs = np.log(v)
    p = "–"
    if v.size >= 2 and np.any(logs != 0):
        from scipy.stats import wilcoxon

        p = f"{wilcoxon(logs, alternative='two-sided').pvalue:.2g}"
    return f"{float(np.median(v)):.2f} (p = {p})"


def _median(values: list[Any], fmt: str) -> str:
    v = [float(x) for x in values if x is not None and math.isfinite(float(x))]
    return fmt.format(float(np.median(v))) if v else "–"


def _finished(r: dict[str, Any]) -> bool:
    return bool(r["self_stopped"]) and float(r["coverage"]) >= GOOD_COVERAGE


def slam_rows(perfect: dict[Key, dict], slam: dict[Key, dict]) -> list[str]:
    """The per family and policy table (see the module docstring)."""
    lines = [
        "| family | policy | pairs | self-stops ≥ 0.97 perfect / SLAM | collisions perfect / "
        "SLAM | SLAM ÷ perfect time | ATE (m) | odometry ÷ SLAM ATE | map error | loop "
        "closures | false stops | lost | SLAM ÷ perfect wall time |",
        "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    groups: dict[tuple[str, str], list[Key]] = {}
    for key in sorted(set(perfect) & set(slam)):
        groups.setdefault((world_family(key[0]), key[1]), []).append(key)
    for (fam, policy), keys in groups.items():
        a, b = [perfect[k] for k in keys], [slam[k] for k in keys]
        n = len(keys)
        ratio = [s["mission_time_s"] / p["mission_time_s"] for p, s in zip(a, b, strict=True)]
        wall = [s["wall_time_s"] / p["wall_time_s"] for p, s in zip(a, b, strict=True)]
        odom = [
            s["odom_ate_m"] / s["ate_m"]
            for s in b
            if s.get("odom_ate_m") is not None and s.get("ate_m")
        ]
        cells = [
            f"{sum(map(_finished, a))}/{n} / {sum(map(_finished, b))}/{n}",
            f"{sum(int(r['collisions']) for r in a)} / {sum(int(r['collisions']) for r in b)}",
            median_p(ratio),
            _median([s.get("ate_m") for s in b], "{:.3f}"),
            _median(odom, "{:.1f}"),
            _median([s.get("map_error") for s in b], "{:.3f}"),
            _median([s.get("loop_closures") for s in b], "{:.0f}"),
            f"{sum(1 for s in b if s.get('slam_false_stop'))}/{n}",
            f"{sum(1 for s in b if s.get('slam_lost') or (s.get('slam_lost_events') or 0))}/{n}",
            _median(wall, "{:.2f}×"),
        ]
        lines.append(f"| {fam} | {policy} | {n} | " + " | ".join(cells) + " |")
    return lines


def expert_ratio_rows(maps: dict[str, dict[Key, dict]], expert: str = "semantic") -> list[str]:
    """The expert's mission time over each baseline's, per family and map."""
    lines = [
        "| family | map | PM ÷ FE | PM ÷ nearest |",
        "|---|---|---:|---:|",
    ]
    for name, rows in maps.items():
        by_family: dict[str, dict[str, list[float]]] = {}
        for (world, policy, seed), r in rows.items():
            if policy != expert:
                continue
            for base in ("frontier", "nearest"):
                other = rows.get((world, base, seed))
                if other is not None and other["mission_time_s"] > 0:
                    ratios = by_family.setdefault(world_family(world), {})
                    ratios.setdefault(base, []).append(
                        r["mission_time_s"] / other["mission_time_s"]
                    )
        for fam, ratios in sorted(by_family.items()):
            cells = [
                f"{median_p(ratios.get(b, []))}, n = {len(ratios.get(b, []))}"
                for b in ("frontier", "nearest")
            ]
            lines.append(f"| {fam} | {name} | " + " | ".join(cells) + " |")
    return lines


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("perfect", help="comma-separated benchmark directories on the perfect map")
    ap.add_argument("slam", help="the same benchmarks with --env-config slam")
    args = ap.parse_args(argv)
    try:
        perfect, slam = load(args.perfect), load(args.slam)
    except ValueError as e:
        print(f"compare_slam: error: {e}", file=sys.stderr)
        return 2
    print("\n".join(slam_rows(perfect, slam)))
    print()
    print("\n".join(expert_ratio_rows({"perfect": perfect, "SLAM": slam})))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
