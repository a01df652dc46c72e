"""The team benchmark's report: ``summary.md`` and ``team_speedup.png`` from ``runs.csv``.

``summary.md`` has one table per world family: medians per (policy, robots), the lowest
coverage, the median of each seed's T99 ratio to one robot's (same policy, world and seed)
and, per team size, a paired Wilcoxon test of each policy's T99 against ``independent``'s
and of every other pair of policies.
With the team oracle in the runs (``team_oracle``), each table adds per row the one-robot
oracle's T99 over the row's (``T_oracle(1) / T99``: the oracle's own rows give its speed-up
``T_oracle(1) / T_oracle(k)``), the regret (T99 over the team oracle's with as many robots,
same world and start) and T99 over the team lower bound (``lower_bound_s``), medians over seeds.
``team_speedup.png`` draws that ratio against the team size, per family and policy (median
and quartiles), with the perfect division 1/N for reference.
"""

from __future__ import annotations

import csv
import math
from pathlib import Path

import numpy as np

#: The baseline every team policy is tested against.
BASELINE = "team_independent"
#: The team oracle's name in ``runs.csv``.
ORACLE = "team_oracle"
_ORACLE_HEADER = (" T_oracle(1) / T99 | regret | T99 / bound |", "---|---|---|")


def _float(v: str) -> float:
    return float(v) if v not in ("", "None") else math.nan


def _median(values: list[float]) -> float:
    arr = np.array([v for v in values if math.isfinite(v)])
    return float(np.median(arr)) if arr.size else math.nan


def _fmt(v: float, digits: int = 1) -> str:
    return "-" if not math.isfinite(v) else f"{v:.{digits}f}"


def read_team_runs(out: str | Path) -> list[dict[str, str]]:
    """The rows of ``out/runs.csv``."""
    with (Path(out) / "runs.csv").open(newline="") as f:
        return list(csv.DictReader(f))


def family(world: str) -> str:
    """A world spelling's family: ``maze`` for ``maze:seed=3,size_m=10``."""
    return world.split(":")[0]


def speedup_ratios(rows: list[dict[str, str]]) -> dict[tuple[str, str, int], list[float]]:
    """Per (family, policy, robots): each mission's T99 ÷ the same policy's one-robot T99 on
    the same world and seed (NaN where either never reached 0.99 or one robot was not run)."""
    one = {
        (r["world"], r["policy"], int(r["seed"])): _float(r["T99_s"])
        for r in rows
        if int(r["n_robots"]) == 1
    }
    out: dict[tuple[str, str, int], list[float]] = {}
    for r in rows:
        base = one.get((r["world"], r["policy"], int(r["seed"])), math.nan)
        ratio = _float(r["T99_s"]) / base if base > 0 else math.nan
        out.setdefault((family(r["world"]), r["policy"], int(r["n_robots"])), []).append(ratio)
    return out


def oracle_ratios(rows: list[dict[str, str]]) -> dict[tuple[str, str, int], list[list[float]]]:
    """Per (family, policy, robots), per mission: the one-robot oracle's T99 over this T99,
    this T99 over the team oracle's with as many robots (regret) and this T99 over the team
    lower bound (NaN where a term is missing)."""
    oracle = {
        (r["world"], int(r["seed"]), int(r["n_robots"])): _float(r["T99_s"])
        for r in rows
        if r["policy"] == ORACLE
    }
    out: dict[tuple[str, str, int], list[list[float]]] = {}
    for r in rows:
        t99, n = _float(r["T99_s"]), int(r["n_robots"])
        one = oracle.get((r["world"], int(r["seed"]), 1), math.nan)
        same = oracle.get((r["world"], int(r["seed"]), n), math.nan)
        bound = _float(r.get("lower_bound_s") or "")
        cell = out.setdefault((family(r["world"]), r["policy"], n), [[], [], []])
        cell[0].append(one / t99 if t99 > 0 else math.nan)
        cell[1].append(t99 / same if same > 0 else math.nan)
        cell[2].append(t99 / bound if bound > 0 else math.nan)
    return out


def _oracle_cells(values: list[list[float]] | None) -> str:
    if values is None:
        return " - | - | - |"
    return "".join(f" {_fmt(_median(v), 2)} |" for v in values)


def _table_row(rs: list[dict[str, str]], ratios: list[float], pol: str, n: int) -> str:
    per_robot_max = [max(float(v) for v in r["path_per_robot_m"].split(";")) for r in rs]
    coverage = [_float(r["coverage"]) for r in rs]
    return (
        f"| {pol} | {n} | {len(rs)} | {_fmt(_median([_float(r['T90_s']) for r in rs]))} "
        f"| {_fmt(_median([_float(r['T99_s']) for r in rs]))} "
        f"| {_fmt(_median([_float(r['mission_time_s']) for r in rs]))} "
        f"| {_fmt(_median(ratios), 2)} "
        f"| {_fmt(_median([_float(r['path_total_m']) for r in rs]))} "
        f"| {_fmt(_median(per_robot_max))} "
        f"| {_fmt(_median([_float(r['overlap_ratio']) for r in rs]), 2)} "
        f"| {sum(int(r['robot_collisions']) for r in rs)} "
        f"| {_fmt(min(coverage), 3)} "
        f"| {sum(r['self_stopped'] == 'True' for r in rs)}/{len(rs)} |"
    )


def write_team_summary(out: str | Path) -> Path:
    """``out/summary.md`` from ``out/runs.csv`` (module docstring)."""
    out_dir = Path(out)
    path = out_dir / "summary.md"
    path.write_text("\n".join(team_summary_lines(read_team_runs(out_dir))) + "\n")
    return path


def team_summary_lines(rows: list[dict[str, str]]) -> list[str]:
    """The lines of the team benchmark's ``summary.md`` for the ``runs.csv`` rows ``rows``:
    per family a table per (policy, team size) and the paired T99 tests."""
    ratios = speedup_ratios(rows)
    with_oracle = any(r["policy"] == ORACLE for r in rows)
    against = oracle_ratios(rows) if with_oracle else {}
    extra = _ORACLE_HEADER if with_oracle else ("", "")
    lines = ["# Team benchmark", ""]
    for fam in sorted({family(r["world"]) for r in rows}):
        fam_rows = [r for r in rows if family(r["world"]) == fam]
        lines += [
            f"## {fam}",
            "",
            "| policy | robots | n | T90 s | T99 s | mission s | T99 / 1 robot | path total m "
            "| path max m | overlap | robot coll. | coverage min | self-stopped |" + extra[0],
            "|---|---|---|---|---|---|---|---|---|---|---|---|---|" + extra[1],
        ]
        for pol, n in sorted({(r["policy"], int(r["n_robots"])) for r in fam_rows}):
            rs = [r for r in fam_rows if r["policy"] == pol and int(r["n_robots"]) == n]
            line = _table_row(rs, ratios[(fam, pol, n)], pol, n)
            if with_oracle:
                line += _oracle_cells(against.get((fam, pol, n)))
            lines.append(line)
        lines += ["", *paired_tests(fam_rows), ""]
    return lines


def paired_tests(rows: list[dict[str, str]]) -> list[str]:
    """Per team size, each policy's T99 against :data:`BASELINE`'s on the same seeds, then
    every other pair of policies (two-sided Wilcoxon signed-rank; pairs of missions where
    either never reached 0.99 are counted and left out)."""
    by: dict[tuple[str, int], dict[tuple[str, int], float]] = {}
    for r in rows:
        cell = by.setdefault((r["policy"], int(r["n_robots"])), {})
        cell[(r["world"], int(r["seed"]))] = _float(r["T99_s"])
    policies = sorted({pol for pol, _ in by})
    others = [pol for pol in policies if pol != BASELINE]
    pairs = [(pol, BASELINE) for pol in others if BASELINE in policies]
    pairs += [(x, y) for i, x in enumerate(others) for y in others[i + 1 :]]
    sizes = sorted({n for _, n in by})
    return [
        _paired_line(x, y, n, by[(x, n)], by[(y, n)])
        for x, y in pairs
        for n in sizes
        if (x, n) in by and (y, n) in by
    ]


def _paired_line(
    x: str, y: str, n: int, vals: dict[tuple[str, int], float], base: dict[tuple[str, int], float]
) -> str:
    """One line of :func:`paired_tests`: ``x``'s T99 against ``y``'s with ``n`` robots."""
    from scipy.stats import wilcoxon

    common = [k for k in vals if k in base]
    keys = [k for k in common if math.isfinite(vals[k]) and math.isfinite(base[k])]
    unreached = f" ({len(common) - len(keys)} left out: no T99)" if len(keys) < len(common) else ""
    robots = "robot" if n == 1 else "robots"
    if len(keys) < 5:
        return f"- {x} vs {y}, {n} {robots}: {len(keys)} pairs, too few{unreached}"
    a = np.array([vals[k] for k in keys])
    b = np.array([base[k] for k in keys])
    p = float(wilcoxon(a, b).pvalue) if np.any(a != b) else 1.0
    return (
        f"- {x} vs {y}, {n} {robots}: median T99 ratio "
        f"{np.median(a / b):.2f} over {len(keys)} pairs, Wilcoxon p = {p:.3g}{unreached}"
    )


def write_team_plot(out: str | Path) -> Path | None:
    """``out/team_speedup.png``: per family, T99 ÷ one robot's against the team size (median
    and quartiles per policy) and 1/N; None when no run has more than one team size."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out_dir = Path(out)
    ratios = speedup_ratios(read_team_runs(out_dir))
    sizes = sorted({n for _, _, n in ratios})
    if len(sizes) < 2:
        return None
    families = sorted({fam for fam, _, _ in ratios})
    policies = sorted({pol for _, pol, _ in ratios})
    fig, axes = plt.subplots(1, len(families), figsize=(4.5 * len(families), 4), squeeze=False)
    for ax, fam in zip(axes[0], families, strict=True):
        ns = np.array(sizes, dtype=float)
        ax.plot(ns, 1.0 / ns, "k--", lw=1, label="perfect division 1/N")
        for i, pol in enumerate(policies):
            xs, med, lo, hi = [], [], [], []
            for n in sizes:
                v = np.array([x for x in ratios.get((fam, pol, n), []) if math.isfinite(x)])
                if v.size:
                    q1, q2, q3 = np.percentile(v, [25, 50, 75])
                    xs.append(n + 0.06 * (i - (len(policies) - 1) / 2))
                    med.append(q2)
                    lo.append(q2 - q1)
                    hi.append(q3 - q2)
            label = pol.removeprefix("team_")
            ax.errorbar(xs, med, yerr=[lo, hi], marker="o", capsize=3, label=label)
        ax.set_xticks(sizes)
        ax.set_xlabel("robots")
        ax.set_ylabel("T99 ÷ one robot's (median, quartiles)")
        ax.set_title(fam)
        ax.set_ylim(bottom=0)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    fig.tight_layout()
    path = out_dir / "team_speedup.png"
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path
