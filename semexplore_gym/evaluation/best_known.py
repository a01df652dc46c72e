"""Best known results per (world, start), as operations-research libraries keep best-known
solutions, and each mission's ratio to them and to the certified lower bound.

A table (``configs/best_known/best_known.csv``, shipped; one row per (world, seed, start)) holds
the shortest time to 99 % coverage (``T99_s``) any policy has reached from that start with the
default env config, the policy spec that reached it, the shortest distance driven to 99 %
(``D99_m``) and its policy, and the certified lower bounds on both (the bound of
:mod:`semexplore_gym.core.coverage_tour`, when it was computed; ``inf`` when it was computed
and no explorer can reach the goal, so a mission that did lies below it). ``seed`` is the benchmark's
seed, which draws the start pose; ``start`` is ``random`` (a suite's start poses) or ``fixed``
(``--fixed-start``).

After a benchmark whose missions the table covers (default env config), ``summary.md`` gains
"Against the best known": per family and policy the median T99 ÷ best known and T99 ÷ lower
bound, how many missions tied or beat the best known, and how many fell below the bound (a
bound is never violated: a count above zero is a bug, flagged loudly). ``best_known.csv`` in the
run folder is the shipped table updated with the run's missions; a mission that beats the best
known is listed with the command that reproduces it. ``scripts/update_best_known.py`` merges run
folders into the shipped table.
"""

from __future__ import annotations

import csv
import math
import os
import shlex
from pathlib import Path
from typing import Any

import numpy as np

from semexplore_gym.evaluation.regret import median_iqr

#: Columns of a best-known table, in order.
COLUMNS: tuple[str, ...] = (
    "world",
    "seed",
    "start",
    "T99_s",
    "T99_policy",
    "D99_m",
    "D99_policy",
    "lower_bound_s",
    "lower_bound_m",
)
SECTION_TITLE = "## Against the best known"
#: A mission beats the best known when its T99 is below it by more than this share.
BEAT_MARGIN = 0.005
#: ``semexplore explore``'s time limit when ``--max-time-s`` is not given.
EXPLORE_DEFAULT_LIMIT_S = 1200.0
_FLOAT_COLUMNS = ("T99_s", "D99_m", "lower_bound_s", "lower_bound_m")
#: Columns that may hold ``inf``: a bound computed as infinite (no explorer reaches the goal).
_BOUND_COLUMNS = ("lower_bound_s", "lower_bound_m")
_STARTS = ("random", "fixed")

Key = tuple[str, int, str]


def shipped_table_path() -> Path:
    """The shipped table (``configs/best_known/best_known.csv`` of the checkout or the wheel)."""
    from semexplore_gym.config.resources import configs_dir

    return configs_dir() / "best_known" / "best_known.csv"


def _float_or_none(text: str, where: str, column: str) -> float | None:
    if text in ("", "None"):
        return None
    try:
        value = float(text)
    except ValueError:
        raise ValueError(f"{where}: {column} is not a number: {text!r}") from None
    if column in _BOUND_COLUMNS and value == math.inf:
        return value  # computed, and infinite: kept, so the bound is not computed again
    if not math.isfinite(value) or value < 0:
        raise ValueError(f"{where}: {column} must be a finite number >= 0, got {text!r}")
    return value


def read_table(path: str | os.PathLike | None = None) -> dict[Key, dict[str, Any]]:
    """The table at ``path`` (default: the shipped one) keyed by ``(world, seed, start)``; an
    absent file is an empty table.

    Raises:
        ValueError: a row with a missing or malformed cell (naming the file and line).
    """
    p = Path(path) if path is not None else shipped_table_path()
    if not p.exists():
        return {}
    table: dict[Key, dict[str, Any]] = {}
    with p.open(newline="") as f:
        reader = csv.DictReader(f)
        missing = [c for c in COLUMNS if c not in (reader.fieldnames or [])]
        if missing:
            raise ValueError(f"{p}: not a best-known table (missing columns {missing})")
        for line, raw in enumerate(reader, start=2):
            where = f"{p} line {line}"
            try:
                seed = int(raw["seed"])
            except ValueError:
                raise ValueError(f"{where}: seed is not an integer: {raw['seed']!r}") from None
            if raw["start"] not in _STARTS:
                raise ValueError(f"{where}: start must be random or fixed, got {raw['start']!r}")
            row: dict[str, Any] = {k: raw[k] for k in COLUMNS}
            row["seed"] = seed
            for c in _FLOAT_COLUMNS:
                row[c] = _float_or_none(raw[c], where, c)
            table[(raw["world"], seed, raw["start"])] = row
    return table


def write_table(path: str | os.PathLike, table: dict[Key, dict[str, Any]]) -> Path:
    """Write ``table`` sorted by (world, start, seed); returns the path."""
    p = Path(path)
    p.parent.mkdir(parents=True, exist_ok=True)
    tmp = p.with_suffix(p.suffix + ".tmp")
    with tmp.open("w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(COLUMNS))
        w.writeheader()
        for key in sorted(table, key=lambda k: (k[0], k[2], k[1])):
            row = table[key]
            w.writerow({c: ("" if row.get(c) is None else row[c]) for c in COLUMNS})
    os.replace(tmp, p)
    return p


def run_start(out_dir: str | os.PathLike) -> str | None:
    """``random`` or ``fixed``: the start poses of the benchmark in ``out_dir``; None when its
    missions are not comparable with the table (an env config or override other than the
    default, a robot team, or no ``benchmark.json``)."""
    import json

    p = Path(out_dir) / "benchmark.json"
    if not p.exists():
        return None
    try:
        meta = json.loads(p.read_text())
    except (OSError, ValueError):
        return None
    # ``--env-config default`` names the default config itself (the ``default`` preset).
    if meta.get("config") not in (None, "default") or meta.get("robots"):
        return None  # another env config, or a team
    if meta.get("env_overrides", [None]):
        return None  # overrides, or unknown ones (an older manifest)
    # A suite's or split's own ``random_start: false`` (the DungeonMaps' start markers) fixes
    # the starts as ``--fixed-start`` does; the manifest records it per suite.
    suites = meta.get("suites") or []
    starts = {s.get("random_start") for s in suites if isinstance(s, dict)} - {None}
    if starts == {False}:
        return "fixed"
    if len(starts) > 1:
        return None  # random and fixed starts in one run
    return "fixed" if meta.get("fixed_start") else "random"


def _finite(v: Any) -> float | None:
    if v is None:
        return None
    try:
        x = float(v)
    except (TypeError, ValueError):
        return None
    return x if math.isfinite(x) else None


def merge_runs(
    table: dict[Key, dict[str, Any]], rows: list[dict[str, Any]], start: str
) -> tuple[dict[Key, dict[str, Any]], list[dict[str, Any]]]:
    """``table`` updated with the missions ``rows`` (read with ``D99_m`` set, as the summary
    reads them); returns ``(new table, missions that beat the old best known T99)``.

    A mission's T99 or D99 replaces the entry's when it is lower (ties keep the older entry).
    A key new to the table gets an entry from its best mission (its bounds stay empty).
    """
    new = {k: dict(v) for k, v in table.items()}
    rows = [{**r, "policy": versioned_spec(r)} for r in rows]
    beats: list[dict[str, Any]] = []
    for r in rows:
        key = (str(r["world"]), int(r["seed"]), start)
        t99, d99 = _finite(r.get("T99_s")), _finite(r.get("D99_m"))
        if t99 is None and d99 is None:
            continue
        old = table.get(key)
        if old is not None and t99 is not None and old["T99_s"] is not None:
            if t99 < old["T99_s"] * (1.0 - BEAT_MARGIN):
                beats.append({**r, "best_known_T99_s": old["T99_s"], "start": start})
        entry = new.setdefault(
            key,
            {"world": key[0], "seed": key[1], "start": start, **dict.fromkeys(COLUMNS[3:])},
        )
        if t99 is not None and (entry["T99_s"] is None or t99 < entry["T99_s"]):
            entry["T99_s"], entry["T99_policy"] = round(t99, 3), r["policy"]
        if d99 is not None and (entry["D99_m"] is None or d99 < entry["D99_m"]):
            entry["D99_m"], entry["D99_policy"] = round(d99, 3), r["policy"]
    return new, beats


def versioned_spec(row: dict[str, Any]) -> str:
    """The row's policy spec with the expert's version name for ``semantic`` (which moves on
    to each newer version): ``semantic[cost.w_v=2]`` that ran ``semantic-v3`` is
    ``semantic-v3[cost.w_v=2]``, which means the same in every later release."""
    spec, version = str(row["policy"]), row.get("policy_version")
    if version and (spec == "semantic" or spec.startswith("semantic[")):
        return str(version) + spec[len("semantic") :]
    return spec


def reproduce_command(row: dict[str, Any]) -> str:
    """The ``semexplore explore`` line that runs the mission of a runs.csv row again."""
    parts = [
        "semexplore",
        "explore",
        "--world",
        str(row["world"]),
        "--policy",
        str(row["policy"]),
        "--seed",
        str(int(row["seed"])),
    ]
    random = "false" if row.get("start") == "fixed" else "true"
    parts += ["--env-set", f"episode.random_start={random}"]
    limit = _finite(row.get("mission_time_s"))
    if limit is not None and limit > EXPLORE_DEFAULT_LIMIT_S:
        parts += ["--max-time-s", str(math.ceil(limit))]
    return " ".join(shlex.quote(p) for p in parts) + " --json"


def mission_ratios(
    rows: list[dict[str, Any]], table: dict[Key, dict[str, Any]], start: str
) -> list[dict[str, Any]]:
    """Per mission with a table entry: its ``T99 ÷ best known``, ``T99 ÷ lower bound`` and
    ``D99 ÷ distance bound`` (``inf`` when it never reached 99 %; None without a reference),
    and whether its T99 or D99 lies below the bound."""
    out = []
    for r in rows:
        e = table.get((str(r["world"]), int(r["seed"]), start))
        if e is None:
            continue
        t99, d99 = _finite(r.get("T99_s")), _finite(r.get("D99_m"))

        def ratio(v: float | None, ref: float | None) -> float | None:
            if ref is None or not 0 < ref < math.inf:
                return None
            return math.inf if v is None else v / ref

        out.append(
            {
                "world": r["world"],
                "policy": r["policy"],
                "seed": int(r["seed"]),
                "best_ratio": ratio(t99, e["T99_s"]),
                "bound_ratio": ratio(t99, e["lower_bound_s"]),
                "distance_bound_ratio": ratio(d99, e["lower_bound_m"]),
                "below_bound": (
                    t99 is not None and e["lower_bound_s"] is not None and t99 < e["lower_bound_s"]
                )
                or (
                    d99 is not None and e["lower_bound_m"] is not None and d99 < e["lower_bound_m"]
                ),
                "at_best": t99 is not None
                and e["T99_s"] is not None
                and t99 <= e["T99_s"] * (1.0 + BEAT_MARGIN),
            }
        )
    return out


def _policy_table(by_policy: dict[str, list[dict[str, Any]]]) -> list[str]:
    lines = [
        "| policy | missions | T99 ÷ best known | at the best known | T99 ÷ lower bound | "
        "D99 ÷ distance bound | below the bound |",
        "|---|---|---|---|---|---|---|",
    ]
    for policy, rs in by_policy.items():

        def col(name: str, rs: list[dict[str, Any]] = rs) -> str:
            return median_iqr([r[name] for r in rs if r[name] is not None])

        at = sum(1 for r in rs if r["at_best"])
        below = sum(1 for r in rs if r["below_bound"])
        lines.append(
            f"| {policy} | {len(rs)} | {col('best_ratio')} | {at}/{len(rs)} | "
            f"{col('bound_ratio')} | {col('distance_bound_ratio')} | "
            f"{below if below == 0 else f'**{below} (bug)**'} |"
        )
    return lines


def summary_lines(
    ratios: list[dict[str, Any]], beats: list[dict[str, Any]], n_entries: int
) -> list[str]:
    """The "Against the best known" section of ``summary.md``."""
    from semexplore_gym.evaluation.suites import world_family

    lines = [
        SECTION_TITLE,
        "",
        f"Each mission against the best known result from the same start ({n_entries} "
        "(world, start) entries; `best_known.csv` beside this file is the table updated with "
        "this run) and against the certified lower bound on T99 and on the distance to 99 % "
        "(no explorer can do better; a mission below it is a bug). Median [IQR].",
        "",
    ]
    families: dict[str, dict[str, list[dict[str, Any]]]] = {}
    for r in ratios:
        families.setdefault(world_family(r["world"]), {}).setdefault(r["policy"], []).append(r)
    for fam, by_policy in families.items():
        lines += [f"### {fam}", "", *_policy_table(by_policy), ""]
    if beats:
        lines += [
            f"New best known ({len(beats)} mission{'s' if len(beats) != 1 else ''} beat the "
            "table's T99 by more than "
            f"{BEAT_MARGIN:.1%}); each reproduces with:",
            "",
        ]
        for b in beats:
            lines.append(
                f"- {b['world']} seed {int(b['seed'])}: {b['policy']} {float(b['T99_s']):.1f} s "
                f"(best known {float(b['best_known_T99_s']):.1f} s): `{reproduce_command(b)}`"
            )
        lines.append("")
    return lines


def overview_lines(table: dict[Key, dict[str, Any]]) -> list[str]:
    """The table in brief: per family and start kind, how many starts it holds, the medians
    [IQR] of the best known T99 and D99 and of their certified lower bounds, and which policies
    hold the best T99 (``semexplore report configs/best_known/best_known.csv``)."""
    from semexplore_gym.evaluation.suites import world_family

    groups: dict[tuple[str, str], list[dict[str, Any]]] = {}
    for (world, _, start), row in table.items():
        groups.setdefault((world_family(world), start), []).append(row)

    def cell(rows: list[dict[str, Any]], column: str) -> str:
        v = [float(r[column]) for r in rows if r[column] is not None]
        if not v:
            return "–"
        q1, med, q3 = (float(x) for x in np.percentile(v, [25, 50, 75], method="lower"))
        return f"{med:.1f} [{q1:.1f}–{q3:.1f}]"

    lines = [
        "| family | start | starts | best known T99 (s) | lower bound on T99 (s) | "
        "best known D99 (m) | lower bound on D99 (m) | best T99 held by |",
        "|---|---|---:|---:|---:|---:|---:|---|",
    ]
    for (fam, start), rows in groups.items():
        holders: dict[str, int] = {}
        for r in rows:
            if r["T99_policy"]:
                holders[r["T99_policy"]] = holders.get(r["T99_policy"], 0) + 1
        held = ", ".join(f"{p} {n}" for p, n in sorted(holders.items(), key=lambda x: -x[1]))
        lines.append(
            f"| {fam} | {start} | {len(rows)} | {cell(rows, 'T99_s')} | "
            f"{cell(rows, 'lower_bound_s')} | {cell(rows, 'D99_m')} | "
            f"{cell(rows, 'lower_bound_m')} | {held or '–'} |"
        )
    return lines


def write_best_known(
    out_dir: str | os.PathLike, table_path: str | os.PathLike | None = None
) -> dict[str, Any]:
    """Add the "Against the best known" section to ``out_dir/summary.md`` and write
    ``out_dir/best_known.csv`` (the table updated with this run).

    Returns:
        ``{"missions": n compared, "beats": n, "below_bound": n, "csv": path or None}``;
        nothing is written when the run is not comparable (see :func:`run_start`) or the
        table covers none of its missions.
    """
    from semexplore_gym.evaluation.report import add_distance_to_99
    from semexplore_gym.evaluation.run_row import read_runs

    out = Path(out_dir)
    start = run_start(out)
    table = read_table(table_path)
    none = {"missions": 0, "beats": 0, "below_bound": 0, "csv": None}
    if start is None:
        return none
    rows = read_runs(out / "runs.csv")
    add_distance_to_99(out, rows)
    ratios = mission_ratios(rows, table, start)
    merged, beats = merge_runs(table, rows, start)
    csv_path = write_table(out / "best_known.csv", merged)
    if not ratios:
        return {**none, "csv": str(csv_path)}
    summary = out / "summary.md"
    text = summary.read_text() if summary.exists() else ""
    if SECTION_TITLE in text:
        text = text[: text.index(SECTION_TITLE)].rstrip() + "\n"
    section = summary_lines(ratios, beats, len(table))
    summary.write_text(text + "\n" + "\n".join(section) + "\n")
    return {
        "missions": len(ratios),
        "beats": len(beats),
        "below_bound": sum(1 for r in ratios if r["below_bound"]),
        "csv": str(csv_path),
    }
