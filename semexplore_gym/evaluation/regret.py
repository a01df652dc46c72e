"""Regret against the oracle: each mission's times and path over the oracle's on the same start.

A post-processing step over a benchmark's ``runs.csv`` (``semexplore benchmark --oracle``, on
by default for suites): the oracle (:mod:`semexplore_gym.policies.oracle`, privileged: it knows
the building) ran on every (world, seed) as one more policy; every other mission is paired with
the oracle's mission of the same (world, seed), the same start pose.

* ``regret.csv``: per mission ``world, policy, seed``, the oracle's ``oracle_T90_s``,
  ``oracle_T99_s``, ``oracle_mission_time_s``, ``oracle_path_length_m``, and the ratios
  ``T90_ratio``, ``T99_ratio``, ``mission_time_ratio``, ``path_ratio`` (policy ÷ oracle). A
  policy that never reached the level gets ``inf``; a pair whose oracle never did gets no ratio.
  (A file of its own next to ``runs.csv``: that file's columns are fixed so a run can resume.)
* ``summary.md`` gains "Regret against the oracle": per family and over all worlds, per
  policy, the median ratio [IQR] and how often the oracle's T99 was at most the policy's.
* ``regret_ladder.png``: per family, each policy's median T99 ratio with its IQR (log scale,
  the oracle at 1).
"""

from __future__ import annotations

import csv
import math
import os
from pathlib import Path
from typing import Any

import numpy as np

#: The oracle's policy spec in a benchmark.
ORACLE_SPEC = "oracle"
#: ``(ratio column, runs.csv column)``.
RATIOS: tuple[tuple[str, str], ...] = (
    ("T90_ratio", "T90_s"),
    ("T99_ratio", "T99_s"),
    ("mission_time_ratio", "mission_time_s"),
    ("path_ratio", "path_length_m"),
)
REGRET_COLUMNS: tuple[str, ...] = (
    "world",
    "policy",
    "seed",
    "oracle_T90_s",
    "oracle_T99_s",
    "oracle_mission_time_s",
    "oracle_path_length_m",
    *(r for r, _ in RATIOS),
)
SECTION_TITLE = "## Regret against the oracle"


def _ratio(value: Any, reference: Any) -> float | None:
    if reference is None or not (isinstance(reference, (int, float)) and reference > 0):
        return None
    if value is None or not math.isfinite(float(value)):
        return math.inf
    return float(value) / float(reference)


def regret_rows(rows: list[dict[str, Any]], oracle: str = ORACLE_SPEC) -> list[dict[str, Any]]:
    """One row per non-oracle mission that has an oracle mission on the same (world, seed)."""
    ref = {(r["world"], r["seed"]): r for r in rows if r["policy"] == oracle}
    out = []
    for r in rows:
        o = ref.get((r["world"], r["seed"]))
        if r["policy"] == oracle or o is None:
            continue
        row = {"world": r["world"], "policy": r["policy"], "seed": r["seed"]}
        for key in ("T90_s", "T99_s", "mission_time_s", "path_length_m"):
            row[f"oracle_{key}"] = o.get(key)
        for name, key in RATIOS:
            row[name] = _ratio(r.get(key), o.get(key))
        out.append(row)
    return out


def median_iqr(values: list[float | None]) -> str:
    """``median [q1–q3]`` of the values that are not None (``∞`` for an infinite one)."""
    v = np.asarray([x for x in values if x is not None], dtype=np.float64)
    if v.size == 0:
        return "–"
    q1, med, q3 = np.percentile(v, [25, 50, 75], method="lower")

    def f(x: float) -> str:
        return "∞" if not math.isfinite(x) else f"{x:.2f}"

    return f"{f(med)} [{f(q1)}–{f(q3)}]"


def _table(by_policy: dict[str, list[dict[str, Any]]]) -> list[str]:
    lines = [
        "| policy | pairs | T90 ÷ oracle | T99 ÷ oracle | mission time ÷ oracle | path ÷ oracle | "
        "oracle T99 ≤ policy's |",
        "|---|---|---|---|---|---|---|",
    ]
    for policy, rs in by_policy.items():
        t99 = [r["T99_ratio"] for r in rs if r["T99_ratio"] is not None]
        beat = sum(1 for x in t99 if x >= 1.0)
        cells = [median_iqr([r[name] for r in rs if r[name] is not None]) for name, _ in RATIOS]
        lines.append(f"| {policy} | {len(rs)} | " + " | ".join(cells) + f" | {beat}/{len(t99)} |")
    return lines


def _oracle_health(rows: list[dict[str, Any]], oracle: str) -> str:
    o = [r for r in rows if r["policy"] == oracle]
    ok = sum(
        1
        for r in o
        if r.get("coverage") is not None and r["coverage"] >= 0.99 and not r.get("collisions")
    )
    stopped = sum(1 for r in o if r.get("self_stopped"))
    return (
        f"Oracle missions: {len(o)}; self-stopped {stopped}; coverage ≥ 0.99 with 0 collisions "
        f"{ok}."
    )


def summary_lines(
    rows: list[dict[str, Any]], regret: list[dict[str, Any]], oracle: str = ORACLE_SPEC
) -> list[str]:
    """The "Regret against the oracle" section of ``summary.md``."""
    from semexplore_gym.evaluation.suites import world_family

    lines = [
        SECTION_TITLE,
        "",
        "Each mission over the oracle's on the same (world, seed): median [IQR] of the ratios "
        "(1 = as fast as full knowledge; ∞ = never reached the level). The oracle is privileged "
        "(it knows the building): its tour is an upper bound on the best possible, so the "
        "ratios understate the true regret.",
        "",
        _oracle_health(rows, oracle),
        "",
    ]
    families: dict[str, dict[str, list[dict[str, Any]]]] = {}
    for r in regret:
        families.setdefault(world_family(r["world"]), {}).setdefault(r["policy"], []).append(r)
    for fam, by_policy in families.items():
        lines += [f"### {fam}", "", *_table(by_policy), ""]
    if len(families) > 1:
        overall: dict[str, list[dict[str, Any]]] = {}
        for r in regret:
            overall.setdefault(r["policy"], []).append(r)
        lines += ["### all worlds", "", *_table(overall), ""]
    return lines


def write_regret(
    out_dir: str | os.PathLike, plots: bool = True, oracle: str = ORACLE_SPEC
) -> dict[str, Any]:
    """Write ``regret.csv``, the summary section and the ladder figure for ``out_dir``.

    Returns:
        ``{"pairs": n, "csv": path or None, "plot": path or None}``; nothing is written when
        the benchmark has no oracle missions.
    """
    from semexplore_gym.evaluation.harness import read_runs

    out = Path(out_dir)
    rows = read_runs(out / "runs.csv")
    regret = regret_rows(rows, oracle)
    if not any(r["policy"] == oracle for r in rows):
        return {"pairs": 0, "csv": None, "plot": None}
    csv_path = out / "regret.csv"
    with csv_path.open("w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(REGRET_COLUMNS))
        w.writeheader()
        for r in regret:
            w.writerow({k: ("" if r.get(k) is None else r[k]) for k in REGRET_COLUMNS})
    summary = out / "summary.md"
    text = summary.read_text() if summary.exists() else ""
    if SECTION_TITLE in text:
        text = text[: text.index(SECTION_TITLE)].rstrip() + "\n"
    summary.write_text(text + "\n" + "\n".join(summary_lines(rows, regret, oracle)) + "\n")
    plot = write_ladder(out, regret) if plots and regret else None
    return {"pairs": len(regret), "csv": str(csv_path), "plot": None if plot is None else str(plot)}


def _quartile_ranks(n: int) -> list[int]:
    """Indices of the lower quartile, median and upper quartile in a sorted sample of ``n``
    (numpy's "lower" method: actual samples, so an infinite ratio stays infinite)."""
    return [int(math.floor(q * (n - 1))) for q in (0.25, 0.5, 0.75)]


#: Families per row of the ladder figure.
LADDER_COLUMNS = 3


def write_ladder(out_dir: str | os.PathLike, regret: list[dict[str, Any]]) -> Path:
    """``regret_ladder.png``: per family, median T99 ÷ oracle with IQR per policy (log x)."""
    from semexplore_gym.evaluation.suites import world_family

    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        from matplotlib.ticker import FormatStrFormatter, NullFormatter
    except ImportError as e:  # pragma: no cover - the render extra is missing
        raise ImportError(
            "the regret ladder needs matplotlib: pip install 'semexplore-gym[render]'"
        ) from e
    families: dict[str, dict[str, list[float]]] = {}
    for r in regret:
        if r["T99_ratio"] is not None:
            families.setdefault(world_family(r["world"]), {}).setdefault(r["policy"], []).append(
                r["T99_ratio"]
            )
    n = max(1, len(families))
    cols = min(n, LADDER_COLUMNS)  # more families wrap onto further rows
    rows = math.ceil(n / cols)
    fig, axes = plt.subplots(
        rows,
        cols,
        figsize=(
            4.2 * cols,
            rows * (0.5 + 0.45 * max([len(v) + 1 for v in families.values()] or [2])) + 0.3,
        ),
        squeeze=False,
    )
    for ax in axes.flat[n:]:
        ax.set_axis_off()
    for ax, (fam, by_policy) in zip(axes.flat, families.items(), strict=False):
        # Never reaching 99 % is an infinite ratio: drawn at the right edge, marked "∞".
        finite = [x for v in by_policy.values() for x in v if math.isfinite(x)]
        cap = min(50.0, max([2.0, *finite]) * 1.1)
        names = ["oracle", *sorted(by_policy, key=lambda p: float(np.median(by_policy[p])))]
        for y, name in enumerate(names):
            v = np.asarray(by_policy.get(name, [1.0]), dtype=np.float64)
            q1, med, q3 = (min(float(q), cap) for q in np.sort(v)[_quartile_ranks(len(v))])
            ax.plot([q1, q3], [y, y], color="0.5", lw=3, solid_capstyle="butt")
            if med >= cap:
                ax.plot([cap], [y], ">", color="C3")
                ax.annotate("∞", (cap, y), xytext=(-14, 4), textcoords="offset points")
            else:
                ax.plot([med], [y], "o", color="k" if name == "oracle" else "C0")
        ax.set_yticks(range(len(names)), names)
        ax.set_xscale("log")
        ax.set_xlim(0.9, cap * 1.05)
        ax.xaxis.set_major_formatter(FormatStrFormatter("%g"))
        ax.xaxis.set_minor_formatter(NullFormatter())
        ax.set_xticks([t for t in (1, 1.5, 2, 3, 5, 10, 20, 50) if t <= cap])
        ax.axvline(1.0, color="0.7", lw=1, ls="--")
        ax.set_xlabel("T99 ÷ oracle's (median, IQR)")
        ax.set_title(fam)
    fig.tight_layout()
    path = Path(out_dir) / "regret_ladder.png"
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path
