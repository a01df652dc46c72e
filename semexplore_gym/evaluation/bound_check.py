"""The certified lower bound checked against missions: per world family the starts, the
missions, how many beat the bound (a bug if ever above zero), best known ÷ bound, the oracle's
T99 ÷ bound and the share of paired missions the oracle reached 99 % no later.

A *checked mission* is one mission of a benchmark folder with the bound of its start: the
records ``scripts/check_lower_bound.py`` builds (it computes the bounds) and writes with
``--missions-out FILE``; ``semexplore report FILE`` prints this module's table from such a file
(the docs build renders the oracle page's table from a shipped one).
"""

from __future__ import annotations

import csv
import math
from collections import defaultdict
from pathlib import Path
from typing import Any

import numpy as np

ORACLE = "oracle"
#: The columns of a checked-missions CSV (``folder``: the benchmark folder the mission ran in;
#: pairs for the oracle's wins are taken within one folder).
MISSION_COLUMNS: tuple[str, ...] = (
    "folder",
    "world",
    "seed",
    "random_start",
    "policy",
    "T99_s",
    "drive_to_99_m",
    "lower_bound_s",
    "lower_bound_m",
)


def _cell(x: float | None) -> str:
    return "" if x is None else repr(float(x))


def write_missions(path: Path, missions: list[dict[str, Any]]) -> None:
    """Write checked missions (records of :func:`mission_record`) as a CSV."""
    with path.open("w", newline="", encoding="utf-8") as fh:
        w = csv.writer(fh)
        w.writerow(MISSION_COLUMNS)
        for m in missions:
            world, seed, random_start = m["start"]
            w.writerow(
                [
                    m["folder"],
                    world,
                    seed,
                    str(bool(random_start)),
                    m["policy"],
                    _cell(m["T99_s"]),
                    _cell(m["drive_m"]),
                    repr(float(m["bound_s"])),
                    repr(float(m["bound_m"])),
                ]
            )


def _number(text: str, where: str) -> float | None:
    if text in ("", "None"):
        return None
    try:
        return float(text)
    except ValueError:
        raise ValueError(f"{where}: {text!r} is not a number") from None


def read_missions(path: Path) -> list[dict[str, Any]]:
    """The checked missions of a CSV written by :func:`write_missions`.

    Raises:
        ValueError: one line: a missing column, a cell that is not a number, no rows.
    """
    from semexplore_gym.evaluation.suites import world_family

    with path.open(newline="", encoding="utf-8", errors="replace") as fh:
        reader = csv.DictReader(fh)
        missing = [c for c in MISSION_COLUMNS if c not in (reader.fieldnames or [])]
        if missing:
            raise ValueError(f"{path} has no column{'s' * (len(missing) > 1)} {', '.join(missing)}")
        out = []
        for i, r in enumerate(reader, start=2):
            where = f"{path} line {i}"
            bound_s, bound_m = (
                _number(r["lower_bound_s"], where),
                _number(r["lower_bound_m"], where),
            )
            if bound_s is None or bound_m is None:
                raise ValueError(f"{where}: the bound is empty")
            out.append(
                {
                    "folder": r["folder"],
                    "start": (r["world"], int(r["seed"]), r["random_start"] == "True"),
                    "family": world_family(r["world"]),
                    "policy": r["policy"],
                    "T99_s": _number(r["T99_s"], where),
                    "drive_m": _number(r["drive_to_99_m"], where),
                    "bound_s": bound_s,
                    "bound_m": bound_m,
                }
            )
    if not out:
        raise ValueError(f"no checked missions in {path}")
    return out


def unique_missions(missions: list[dict[str, Any]]) -> tuple[list[dict[str, Any]], int]:
    """The missions with each (start, policy) once, the first folder's kept, and how many
    repeats were dropped: two folders that ran the same policy from the same start ran the same
    (deterministic) mission, which is one check of the bound, not two."""
    first: dict[tuple[Any, ...], str] = {}  # (start, policy) -> the folder that ran it first
    kept = []
    for m in missions:
        folder = first.setdefault((m["start"], m["policy"]), m["folder"])
        if folder == m["folder"]:
            kept.append(m)
    return kept, len(missions) - len(kept)


def _median(xs: list[float]) -> float | None:
    return round(float(np.median(xs)), 3) if xs else None


def _oracle_wins(ms: list[dict[str, Any]]) -> tuple[int, int]:
    """``(pairs where the oracle's T99 <= the other policy's, pairs)`` over every other policy
    that ran the same start in the same folder (a policy that never reached 99 % loses to one
    that did; pairs where neither did are left out)."""
    by_start: dict[tuple[Any, ...], dict[str, float | None]] = defaultdict(dict)
    for m in ms:
        by_start[(m["folder"], m["start"])][m["policy"]] = m["T99_s"]
    wins = pairs = 0
    for times in by_start.values():
        if ORACLE not in times:
            continue
        mine = times[ORACLE]
        for policy, t in times.items():
            if policy == ORACLE or (mine is None and t is None):
                continue
            pairs += 1
            wins += mine is not None and (t is None or mine <= t)
    return wins, pairs


def family_report(missions: list[dict[str, Any]]) -> dict[str, dict[str, Any]]:
    """Per world family (and ``all``): starts, missions, violations, the medians and the
    oracle's wins (see the module docstring)."""
    fams: dict[str, list[dict[str, Any]]] = defaultdict(list)
    for m in missions:
        fams[m["family"]].append(m)
    fams = {**dict(sorted(fams.items())), "all": list(missions)}
    out = {}
    for fam, ms in fams.items():
        best: dict[tuple[Any, ...], float] = {}
        bound: dict[tuple[Any, ...], float] = {}
        for m in ms:
            bound[m["start"]] = m["bound_s"]
            if m["T99_s"] is not None:
                best[m["start"]] = min(best.get(m["start"], math.inf), m["T99_s"])
        ok = [k for k in best if 0 < bound[k] < math.inf]
        oracle = [
            math.inf if m["T99_s"] is None else m["T99_s"] / m["bound_s"]
            for m in ms
            if m["policy"] == ORACLE and 0 < m["bound_s"] < math.inf
        ]
        wins, pairs = _oracle_wins(ms)
        out[fam] = {
            "starts": len(bound),
            "missions": len(ms),
            "with_T99": sum(m["T99_s"] is not None for m in ms),
            "T99_below_bound": sum(
                m["T99_s"] is not None and m["T99_s"] < m["bound_s"] for m in ms
            ),
            "with_drive": sum(m["drive_m"] is not None for m in ms),
            "drive_below_bound": sum(
                m["drive_m"] is not None and m["drive_m"] < m["bound_m"] for m in ms
            ),
            "median_best_known_over_bound": _median([best[k] / bound[k] for k in ok]),
            "median_oracle_over_bound": _median(oracle),
            "oracle_missions": len(oracle),
            "oracle_wins": wins,
            "oracle_pairs": pairs,
        }
    return out


def _fmt(x: float | None) -> str:
    return "-" if x is None else f"{x:.2f}"


def report_lines(missions: list[dict[str, Any]]) -> list[str]:
    """Violations (must be none), the per-family table, the oracle's wins per folder (a suite or
    a run: pairs are taken within one) and median T99 / bound per policy."""
    fams = family_report(missions)
    total = fams["all"]
    lines = [
        f"missions: {total['missions']}; with T99: {total['with_T99']}, "
        f"T99 below the bound: {total['T99_below_bound']}; "
        f"with a drive to 99 % on file: {total['with_drive']}, "
        f"drive below the bound: {total['drive_below_bound']}",
        "",
        "| family | starts | missions | below the bound | best known ÷ bound | "
        "oracle ÷ bound (its missions) | oracle T99 ≤ other's |",
        "|---|---|---|---|---|---|---|",
    ]
    for fam, f in fams.items():
        share = f"{f['oracle_wins']}/{f['oracle_pairs']}" if f["oracle_pairs"] else "-"
        if f["oracle_pairs"]:
            share += f" ({100.0 * f['oracle_wins'] / f['oracle_pairs']:.0f} %)"
        lines.append(
            f"| {fam} | {f['starts']} | {f['missions']} | "
            f"{f['T99_below_bound'] + f['drive_below_bound']} | "
            f"{_fmt(f['median_best_known_over_bound'])} | "
            f"{_fmt(f['median_oracle_over_bound'])} ({f['oracle_missions']}) | {share} |"
        )
    by_folder: dict[str, list[dict[str, Any]]] = defaultdict(list)
    for m in missions:
        by_folder[m["folder"]].append(m)
    folder_wins = [(name, *_oracle_wins(ms)) for name, ms in by_folder.items()]
    if any(pairs for _, _, pairs in folder_wins):
        lines += ["", "| folder | oracle T99 ≤ other's |", "|---|---|"]
        for name, wins, pairs in folder_wins:
            if pairs:
                lines.append(f"| {name} | {wins}/{pairs} ({100.0 * wins / pairs:.0f} %) |")
    ratios: dict[tuple[str, str], list[float]] = defaultdict(list)
    for m in missions:
        if m["T99_s"] is not None and 0 < m["bound_s"] < math.inf:
            ratios[(m["policy"], m["family"])].append(m["T99_s"] / m["bound_s"])
    lines += ["", "| policy | family | n | median T99 / bound | min |", "|---|---|---|---|---|"]
    for (policy, fam), xs in sorted(ratios.items()):
        lines.append(
            f"| {policy} | {fam} | {len(xs)} | {float(np.median(xs)):.2f} | {min(xs):.2f} |"
        )
    return lines
