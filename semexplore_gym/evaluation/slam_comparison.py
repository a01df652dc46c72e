"""Perfect map against SLAM: the same missions paired, per world family and policy.

The rows are a benchmark's ``runs.csv`` rows, usually of two runs read as one: a run on the
perfect map (``--env-config default``; its ``ate_m`` cells are empty) and the same command with
``--env-config slam`` (``ate_m`` set). A perfect-map mission and a SLAM mission of the same
(world, policy, seed) make a pair; a mission without its twin is left out. Two tables
(``semexplore report PERFECT SLAM --table slam-vs-perfect``):

- per family and policy: pairs; self-stops at true coverage >= :data:`GOOD_COVERAGE` on each
  map; the median true coverage at the end on each map; collisions; the median SLAM / perfect mission-time ratio with the Wilcoxon signed-rank p
  on the log ratios; the SLAM figures (median ATE, median odometry ATE / ATE, map error, loop
  closures); false stops; the median SLAM / perfect wall-time ratio;
- per family and map: the reference policy's mission time over each other policy's on the same
  (world, seed), median with the Wilcoxon p.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np

Key = tuple[str, str, int]
Row = dict[str, Any]
Family = Callable[[str], str]

#: A self-stop at this true coverage or more counts as a finished mission.
GOOD_COVERAGE = 0.97


def split_missions(rows: list[Row]) -> tuple[dict[Key, Row], dict[Key, Row]]:
    """The perfect-map missions (empty ``ate_m``) and the SLAM missions (``ate_m`` set), each
    by (world, policy, seed).

    Raises:
        ValueError: the same (world, policy, seed) twice on one map.
    """
    perfect: dict[Key, Row] = {}
    slam: dict[Key, Row] = {}
    for r in rows:
        key = (r["world"], r["policy"], int(r["seed"]))
        on = slam if r.get("ate_m") is not None else perfect
        if key in on:
            where = "SLAM" if on is slam else "perfect-map"
            raise ValueError(
                f"two {where} missions of world {key[0]}, policy {key[1]}, seed {key[2]} "
                "(give each run once)"
            )
        on[key] = r
    return perfect, slam


def median_p(ratios: list[float]) -> str:
    """``median (p = ...)`` of positive ratios, p the two-sided Wilcoxon signed-rank test on
    their logs (``–`` for p with fewer than 2 ratios or all ratios 1; ``–`` without ratios)."""
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


def _finished(r: Row) -> bool:
    return bool(r["self_stopped"]) and float(r["coverage"]) >= GOOD_COVERAGE


def _ratios(a: list[Row], b: list[Row], key: str) -> list[float]:
    """``b[i][key] / a[i][key]`` where both are numbers and the divisor is positive."""
    return [
        float(s[key]) / float(p[key])
        for p, s in zip(a, b, strict=True)
        if p.get(key) and s.get(key) is not None
    ]


def _pair_cells(a: list[Row], b: list[Row]) -> list[str]:
    """The cells of one (family, policy) row: perfect-map missions ``a``, their SLAM twins ``b``."""
    n = len(a)
    odom = [
        float(s["odom_ate_m"]) / float(s["ate_m"])
        for s in b
        if s.get("odom_ate_m") is not None and s.get("ate_m")
    ]
    return [
        str(n),
        f"{sum(map(_finished, a))}/{n} / {sum(map(_finished, b))}/{n}",
        _median([r["coverage"] for r in a], "{:.3f}")
        + " / "
        + _median([r["coverage"] for r in b], "{:.3f}"),
        f"{sum(int(r['collisions']) for r in a)} / {sum(int(r['collisions']) for r in b)}",
        median_p(_ratios(a, b, "mission_time_s")),
        _median([s.get("ate_m") for s in b], "{:.3f}"),
        _median(odom, "{:.1f}"),
        _median([s.get("map_error") for s in b], "{:.3f}"),
        _median([s.get("loop_closures") for s in b], "{:.0f}"),
        f"{sum(1 for s in b if s.get('slam_false_stop'))}/{n}",
        _median(_ratios(a, b, "wall_time_s"), "{:.2f}×"),
    ]


def paired_table(perfect: dict[Key, Row], slam: dict[Key, Row], family: Family) -> list[str]:
    """The per family and policy table (see the module docstring), families and policies in
    the perfect-map rows' order; ``family`` maps a world to its family."""
    lines = [
        "| family | policy | pairs | self-stops ≥ 0.97 perfect / SLAM | coverage perfect / SLAM "
        "| collisions perfect / SLAM | SLAM ÷ perfect time | ATE (m) | odometry ÷ SLAM ATE | map error | loop "
        "closures | false stops | SLAM ÷ perfect wall time |",
        "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    groups: dict[tuple[str, str], list[Key]] = {}
    for key in perfect:
        if key in slam:
            groups.setdefault((family(key[0]), key[1]), []).append(key)
    for fam, policy in _by_family(groups):
        keys = groups[(fam, policy)]
        cells = _pair_cells([perfect[k] for k in keys], [slam[k] for k in keys])
        lines.append(f"| {fam} | {policy} | " + " | ".join(cells) + " |")
    return lines


def _by_family(groups: dict[tuple[str, str], Any]) -> list[tuple[str, str]]:
    """The (family, x) keys of ``groups``, families in first-seen order, then first-seen x."""
    first = {f: i for i, f in reversed(list(enumerate(f for f, _ in groups)))}
    return sorted(groups, key=lambda g: first[g[0]])


def reference_ratio_table(
    maps: dict[str, dict[Key, Row]], reference: str, family: Family
) -> list[str]:
    """Per family and map: the reference's mission time over each other policy's on the same
    (world, seed), ``median (p = ...), n = pairs``; no lines when no such pair exists."""
    others = list(dict.fromkeys(k[1] for rows in maps.values() for k in rows if k[1] != reference))
    table: dict[tuple[str, str], dict[str, list[float]]] = {}
    for name, rows in maps.items():
        for (world, policy, seed), r in rows.items():
            if policy != reference:
                continue
            for other in others:
                o = rows.get((world, other, seed))
                if o is not None and o["mission_time_s"] and o["mission_time_s"] > 0:
                    ratios = table.setdefault((family(world), name), {})
                    ratios.setdefault(other, []).append(r["mission_time_s"] / o["mission_time_s"])
    if not table:
        return []
    lines = [
        "| family | map | " + " | ".join(f"{reference} ÷ {o}" for o in others) + " |",
        "|---|---|" + "---:|" * len(others),
    ]
    for fam, name in _by_family(table):
        ratios = table[(fam, name)]
        cells = [f"{median_p(ratios.get(o, []))}, n = {len(ratios.get(o, []))}" for o in others]
        lines.append(f"| {fam} | {name} | " + " | ".join(cells) + " |")
    return lines


def slam_vs_perfect_lines(rows: list[Row], reference: str) -> list[str]:
    """The two tables of the module docstring, each under a line that says how to read it.

    Raises:
        ValueError: no pair, or a (world, policy, seed) twice on one map.
    """
    from semexplore_gym.evaluation.suites import world_family

    perfect, slam = split_missions(rows)
    if not set(perfect) & set(slam):
        raise ValueError(
            f"no perfect-map mission has a SLAM twin ({len(perfect)} perfect-map missions with "
            f"ate_m empty, {len(slam)} SLAM missions with ate_m set; a pair shares world, "
            "policy and seed)"
        )
    lines = [
        "Each mission on the perfect map paired with the same (world, policy, seed) in the SLAM "
        f"mode. Self-stops: missions that stopped themselves at true coverage ≥ {GOOD_COVERAGE}; "
        "coverage: median true coverage at the mission's end; time ratios: median over the pairs of the SLAM mission's time divided by the "
        "perfect-map mission's, p = two-sided Wilcoxon signed-rank test on the log ratios; ATE, "
        "odometry ÷ SLAM ATE (per mission), map error and loop closures: medians over the SLAM "
        "missions; false stops: SLAM missions the policy ended short on a SLAM artefact.",
        "",
        *paired_table(perfect, slam, world_family),
    ]
    ratios = reference_ratio_table({"perfect": perfect, "SLAM": slam}, reference, world_family)
    if ratios:
        lines += [
            "",
            f"{reference}'s mission time divided by each other policy's on the same (world, "
            "seed) and map: median over the pairs (p as above), n pairs.",
            "",
            *ratios,
        ]
    return lines
