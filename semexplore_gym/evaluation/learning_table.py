"""The learning benchmark's table: per family, every policy against the expert and the oracle.

Written by ``semexplore benchmark --split NAME:PART`` into ``summary.md`` (section "Learning
benchmark") and printed. One row per (family, policy), the oracle and the expert first, the
baselines (nearest, FE) last:

* ``n``: missions; ``coverage``: median final coverage;
* ``T99 (s)``, ``mission time (s)``: medians (a mission that never reached 99 % has T99 = ∞);
* ``D99 (m)``: median distance driven until 99 % coverage (from each mission's trace and
  trajectory; the figure ARiADNE and its successors report on the DungeonMaps);
* ``÷ expert``, ``÷ oracle``: the median over (world, seed) pairs of the policy's figure over
  the expert's (the oracle's) on the same start;
* ``p W``: two-sided Wilcoxon signed-rank test on the pairs' log ratios to the expert (T99;
  mission time). A pair where one side never reached 99 % counts as a very large ratio (±log
  1e6: ranks only), a pair where neither did as a tie.

A second table, "Against the best baseline", pairs every other policy with the family's best
baseline: nearest or FE, whichever is faster on that family (the bar of the learning issue's
goal): the shorter median T99, then the shorter median mission time (a baseline that stops
early below 99 % is not the faster one), with the same ratios and tests.

:func:`paired_table_lines` is the learners' short table (``semexplore report --table paired``,
the user guide's comparison with today's expert): per family, each policy's T99 paired with a
reference policy's, with the self-stops and collisions the learning goals count.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from semexplore_gym.evaluation.run_writer import distance_to_coverage_m

#: The expert every row is compared with (``semexplore benchmark``'s reference policy).
EXPERT = "semantic"
ORACLE = "oracle"
#: Baselines, listed last.
BASELINES = ("nearest", "frontier")
SECTION_TITLE = "## Learning benchmark"
BEST_BASELINE_TITLE = "### Against the best baseline"
_BIG_LOG = math.log(1e6)


def _value(r: dict[str, Any], key: str) -> float:
    v = r.get(key)
    return math.inf if v is None or not math.isfinite(float(v)) else float(v)


def _paired(
    rows: list[dict[str, Any]], ref: dict[tuple[str, int], dict[str, Any]], key: str
) -> np.ndarray:
    """log(policy / reference) per (world, seed) pair (ties and one-sided infinities handled)."""
    out = []
    for r in rows:
        o = ref.get((r["world"], int(r["seed"])))
        if o is None:
            continue
        a, b = _value(r, key), _value(o, key)
        if math.isinf(a) and math.isinf(b):
            out.append(0.0)
        elif math.isinf(a) or b <= 0:
            out.append(_BIG_LOG)
        elif math.isinf(b) or a <= 0:
            out.append(-_BIG_LOG)
        else:
            out.append(math.log(a / b))
    return np.asarray(out, dtype=np.float64)


def _ratio_cell(logs: np.ndarray) -> str:
    if logs.size == 0:
        return "–"
    med = float(np.median(logs))
    return "∞" if med >= _BIG_LOG else f"{math.exp(med):.2f}"


def _p_cell(logs: np.ndarray) -> str:
    from scipy.stats import wilcoxon

    if logs.size < 2 or not np.any(logs != 0):
        return "–"
    return f"{wilcoxon(logs, alternative='two-sided').pvalue:.2g}"


def _median(rows: list[dict[str, Any]], key: str) -> float:
    v = np.asarray([_value(r, key) for r in rows], dtype=np.float64)
    return float(np.percentile(v, 50, method="lower")) if v.size else math.nan


def _median_cell(rows: list[dict[str, Any]], key: str) -> str:
    med = _median(rows, key)
    if math.isnan(med):
        return "–"
    return "∞" if math.isinf(med) else (f"{med:.3f}" if key == "coverage" else f"{med:.1f}")


def _order(policies: list[str]) -> list[str]:
    first = [p for p in (ORACLE, EXPERT) if p in policies]
    last = [p for p in BASELINES if p in policies]
    return first + [p for p in policies if p not in first + last] + last


def learning_table_lines(rows: list[dict[str, Any]], out_dir: Any = None) -> list[str]:
    """The "Learning benchmark" section (see the module docstring) for ``runs.csv`` rows
    (``out_dir``: the benchmark directory, for D99; without it D99 is left out)."""
    from semexplore_gym.evaluation.report import group_by_family

    if out_dir is not None:
        rows = [{**r, "D99_m": distance_to_coverage_m(out_dir, r)} for r in rows]

    lines = [
        SECTION_TITLE,
        "",
        f"Per family: medians, and per (world, seed) pair the median ratio to the expert "
        f"(`{EXPERT}`) and to the oracle on the same start (< 1: faster); p W = two-sided "
        "Wilcoxon signed-rank test on the log ratios to the expert.",
        "",
        "| family | policy | n | coverage | T99 (s) | mission time (s) | D99 (m) | T99 ÷ expert | "
        "time ÷ expert | T99 ÷ oracle | time ÷ oracle | p W T99 | p W time |",
        "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    families = group_by_family(rows)
    for family, by_policy in families.items():
        refs = {
            name: {(r["world"], int(r["seed"])): r for r in by_policy.get(name, [])}
            for name in (EXPERT, ORACLE)
        }
        for policy in _order(list(by_policy)):
            rs = by_policy[policy]
            cells = [str(len(rs)), _median_cell(rs, "coverage")]
            cells += [_median_cell(rs, "T99_s"), _median_cell(rs, "mission_time_s")]
            cells.append(
                _median_cell([r for r in rs if r.get("D99_m", 0) is not None], "D99_m")
                if out_dir is not None
                else "–"
            )
            logs = {
                (name, key): _paired(rs, refs[name], key)
                if refs[name] and policy != name
                else np.zeros(0)
                for name in (EXPERT, ORACLE)
                for key in ("T99_s", "mission_time_s")
            }
            cells += [_ratio_cell(logs[k]) for k in logs]
            cells += [_p_cell(logs[(EXPERT, "T99_s")]), _p_cell(logs[(EXPERT, "mission_time_s")])]
            lines.append(f"| {family} | {policy} | " + " | ".join(cells) + " |")
    lines.append("")
    return lines + _best_baseline_lines(families)


def best_baseline(by_policy: dict[str, list[dict[str, Any]]]) -> str | None:
    """The faster baseline (of :data:`BASELINES`) of those that ran: the shorter median T99,
    then the shorter median mission time."""
    medians = {
        b: (_median(by_policy[b], "T99_s"), _median(by_policy[b], "mission_time_s"))
        for b in BASELINES
        if b in by_policy
    }
    return min(medians, key=lambda b: medians[b]) if medians else None


def _best_baseline_lines(families: dict[str, dict[str, list[dict[str, Any]]]]) -> list[str]:
    """The "Against the best baseline" table for rows grouped by family, then policy: each
    policy paired with its family's best baseline (nothing when no family ran a baseline)."""
    head = [
        BEST_BASELINE_TITLE,
        "",
        "Per family, the faster baseline (shorter median T99, then mission time), and the "
        "median ratio of every other policy's figure to it over (world, seed) pairs (< 1: "
        "faster); p W = two-sided Wilcoxon signed-rank test on the log ratios.",
        "",
        "| family | policy | best baseline | pairs | T99 ÷ baseline | time ÷ baseline | "
        "p W T99 | p W time |",
        "|---|---|---|---:|---:|---:|---:|---:|",
    ]
    body = []
    for family, by_policy in families.items():
        base = best_baseline(by_policy)
        if base is None:
            continue
        ref = {(r["world"], int(r["seed"])): r for r in by_policy[base]}
        for policy in _order(list(by_policy)):
            if policy == base:
                continue
            t99, time_s = (_paired(by_policy[policy], ref, k) for k in ("T99_s", "mission_time_s"))
            cells = [base, str(t99.size), _ratio_cell(t99), _ratio_cell(time_s)]
            cells += [_p_cell(t99), _p_cell(time_s)]
            body.append(f"| {family} | {policy} | " + " | ".join(cells) + " |")
    return [*head, *body, ""] if body else []


def write_learning_table(out_dir: Any) -> list[str]:
    """Append (or replace) the section in ``out_dir/summary.md``; returns its lines."""
    from pathlib import Path

    from semexplore_gym.evaluation.run_row import read_runs

    out = Path(out_dir)
    lines = learning_table_lines(read_runs(out / "runs.csv"), out)
    summary = out / "summary.md"
    text = summary.read_text() if summary.exists() else ""
    if SECTION_TITLE in text:
        head, _, rest = text.partition(SECTION_TITLE)
        nxt = rest.find("\n## ")
        text = head.rstrip() + "\n" + (rest[nxt:] if nxt >= 0 else "")
    summary.write_text(text.rstrip() + "\n\n" + "\n".join(lines) + "\n")
    return lines


#: A mission counts as a self-stop at the coverage goal when it ended itself at or above this.
SELF_STOP_COVERAGE = 0.97


def _log_ratio_text(log: float) -> str:
    if math.isnan(log):
        return "–"
    return "∞" if log == math.inf else f"{math.exp(log):.2f}"


def _quantile(sorted_logs: list[float], q: float) -> float:
    """The ``q`` quantile, interpolated linearly between neighbours as numpy does; one that
    lies between a finite log ratio and a one-sided infinity is that infinity."""
    pos = q * (len(sorted_logs) - 1)
    lo, frac = int(pos), pos - int(pos)
    if frac == 0.0:
        return sorted_logs[lo]
    a, b = sorted_logs[lo], sorted_logs[lo + 1]
    if math.isinf(a) or math.isinf(b):
        return a + b  # the infinity (nan between -inf and +inf: no ratio)
    return a + frac * (b - a)


def _ratio_iqr_cell(logs: np.ndarray) -> str:
    """``median [q1–q3]`` of the ratios whose logs are given (the quantiles of the logs; a
    one-sided pair counts as an infinite log ratio, not as the test's stand-in)."""
    if logs.size == 0:
        return "–"
    exact = sorted(math.copysign(math.inf, x) if abs(x) >= _BIG_LOG else float(x) for x in logs)
    q1, med, q3 = (_log_ratio_text(_quantile(exact, q)) for q in (0.25, 0.5, 0.75))
    return f"{med} [{q1}–{q3}]"


def _t99_cell(rows: list[dict[str, Any]]) -> str:
    """The median T99 (the mean of the middle two of an even count; ∞ for no 99 %)."""
    med = float(np.median([_value(r, "T99_s") for r in rows]))
    return "∞" if math.isinf(med) else f"{med:.1f}"


def _collisions_cell(rows: list[dict[str, Any]]) -> str:
    counts = [int(r["collisions"]) for r in rows if r.get("collisions") is not None]
    return str(sum(counts)) if counts else "–"


def gap_closed(
    rows: list[dict[str, Any]],
    ref: dict[tuple[str, int], dict[str, Any]],
    best_t99_s: dict[tuple[str, int], float],
) -> tuple[float | None, int]:
    """The share of the reference's gap to the best known that ``rows``' policy closes:
    ``sum(T_ref - T) / sum(T_ref - T_best)`` over the (world, seed) pairs where all three reached
    99 % (1: as fast as the best known; 0: as the reference; below 0: slower). A sum, not a median
    of per-start shares: a start where the reference is already at the best known has no gap to
    divide by. ``(None, n)`` when the reference has no gap on those pairs."""
    gain = gap = 0.0
    n = 0
    for r in rows:
        key = (r["world"], int(r["seed"]))
        o, best = ref.get(key), best_t99_s.get(key)
        if o is None or best is None:
            continue
        t, t_ref = _value(r, "T99_s"), _value(o, "T99_s")
        if not (math.isfinite(t) and math.isfinite(t_ref) and math.isfinite(best)):
            continue
        gain += t_ref - t
        gap += t_ref - best
        n += 1
    return (gain / gap if gap > 0 else None), n


def _over_bound_cell(rows: list[dict[str, Any]], bound_s: dict[tuple[str, int], float]) -> str:
    """Median of the missions' T99 over their start's bound (∞ short of 99 %), and how many."""
    ratios = [
        _value(r, "T99_s") / bound_s[(r["world"], int(r["seed"]))]
        for r in rows
        if (r["world"], int(r["seed"])) in bound_s
    ]
    if not ratios:
        return "–"
    med = float(np.median(ratios))
    return f"{med:.2f} ({len(ratios)})" if math.isfinite(med) else f"∞ ({len(ratios)})"


def paired_table_lines(
    rows: list[dict[str, Any]],
    reference: str = EXPERT,
    best_t99_s: dict[tuple[str, int], float] | None = None,
    bound_s: dict[tuple[str, int], float] | None = None,
) -> list[str]:
    """Each policy's T99 against ``reference``'s on the same (world, seed), per family.

    One row per (family, policy), the reference first: missions, median T99, the median [IQR]
    over pairs of the policy's T99 over the reference's (a mission that never reached 99 %
    counts as ∞, as in the learning table), the Wilcoxon p of the pairs' log ratios, the pairs
    where the policy was faster, the missions it ended itself at coverage ≥
    :data:`SELF_STOP_COVERAGE`, and its collisions. With ``best_t99_s`` (the best-known T99 per
    (world, seed) of these missions' starts) a last column gives the share of the reference's gap
    to the best known the policy closes (:func:`gap_closed`); with ``bound_s`` (the certified
    lower bound per (world, seed), seconds) one more the median of its T99 over the bound of
    each mission's start (never below 1; ∞ for a mission short of 99 %). ``rows`` need the columns
    ``world``, ``policy``, ``seed``, ``self_stopped``, ``coverage``, ``T99_s`` and
    ``collisions``.
    """
    from semexplore_gym.evaluation.report import group_by_family

    best = best_t99_s or {}
    gap_col = bool(best) and any((r["world"], int(r["seed"])) in best for r in rows)
    bound = bound_s or {}
    bound_col = bool(bound) and any((r["world"], int(r["seed"])) in bound for r in rows)
    lines = [
        f"Per family, each policy paired with `{reference}` by (world, seed). T99 ÷ "
        f"{reference} = median [IQR] over the pairs of the policy's T99 over {reference}'s "
        "(< 1: faster; a mission that never reached 99 % counts as ∞); p W = two-sided "
        "Wilcoxon signed-rank test on the pairs' log ratios; faster = pairs where the policy "
        f"reached 99 % sooner; self-stops = missions it ended itself at coverage ≥ "
        f"{SELF_STOP_COVERAGE}."
        + (
            f" Gap closed = the share of {reference}'s gap to the best-known T99 of the same "
            f"starts that the policy closes, sum({reference} − policy) ÷ sum({reference} − best "
            "known) over the pairs where all three reached 99 % (1: the best known; 0: as "
            f"{reference}; n pairs)."
            if gap_col
            else ""
        )
        + (
            " T99 ÷ bound = the median over the policy's missions of its T99 over the certified "
            "lower bound of the mission's start (the best-known table's; ∞: short of 99 %; "
            "n missions)."
            if bound_col
            else ""
        ),
        "",
        f"| family | policy | n | T99 (s) | T99 ÷ {reference} [IQR] | p W | faster | "
        "self-stops | collisions |"
        + (" gap closed (n) |" if gap_col else "")
        + (" T99 ÷ bound (n) |" if bound_col else ""),
        "|---|---|---:|---:|---:|---:|---:|---:|---:|"
        + ("---:|" if gap_col else "")
        + ("---:|" if bound_col else ""),
    ]
    for family, by_policy in group_by_family(rows).items():
        ref = {(r["world"], int(r["seed"])): r for r in by_policy.get(reference, [])}
        order = [reference] if reference in by_policy else []
        for policy in order + [p for p in by_policy if p != reference]:
            rs = by_policy[policy]
            logs = _paired(rs, ref, "T99_s") if policy != reference else np.zeros(0)
            faster = f"{int(np.sum(logs < 0))}/{logs.size}" if logs.size else "–"
            stops = sum(
                1 for r in rs if r["self_stopped"] and (r["coverage"] or 0.0) >= SELF_STOP_COVERAGE
            )
            cells = [str(len(rs)), _t99_cell(rs), _ratio_iqr_cell(logs)]
            cells += [_p_cell(logs), faster, f"{stops}/{len(rs)}", _collisions_cell(rs)]
            if gap_col:
                share, n = gap_closed(rs, ref, best) if policy != reference else (None, 0)
                cells.append("–" if share is None else f"{share:.2f} ({n})")
            if bound_col:
                cells.append(_over_bound_cell(rs, bound))
            lines.append(f"| {family} | {policy} | " + " | ".join(cells) + " |")
    lines.append("")
    return lines
