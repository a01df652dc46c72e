"""Markdown tables from result files: a benchmark's or a team benchmark's ``runs.csv``, a
best-known table, or the lower bound's checked missions.

One function, :func:`report_tables`, serves ``semexplore report`` and the docs build, which
renders the user guide's result tables from the small result files under ``docs/results/`` (a
table in the guide is computed from its data, never pasted). A benchmark's tables are those of
its ``summary.md`` (:mod:`.report`); a ``runs.csv`` trimmed to the columns a table needs is
enough for that table. Several ``runs.csv`` files are read as one: their rows concatenated
(the perfect-map and the SLAM run of ``--table slam-vs-perfect``).
"""

from __future__ import annotations

import csv
import io
import math
import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

#: The tables of a benchmark's ``runs.csv``: the summary's overview (one row per family and
#: policy), its per-policy table over all worlds, its regret against the oracle (a run with
#: ``--oracle``), its SLAM table (missions with SLAM), the same missions on the perfect map and
#: with SLAM paired (:mod:`.slam_comparison`), each policy's T99 paired with the reference's per
#: family (``paired``: the learners' table), or the whole summary as far as ``runs.csv`` holds
#: it (the best-known and learning sections read other files).
RUN_TABLES: tuple[str, ...] = (
    "overview",
    "policies",
    "regret",
    "slam",
    "slam-vs-perfect",
    "paired",
    "summary",
)
_KEYS = ("world", "policy", "seed", "self_stopped")
#: The ``runs.csv`` columns each table reads (the others may be absent).
NEEDED_COLUMNS: dict[str, tuple[str, ...]] = {
    "overview": (*_KEYS, "coverage", "mission_time_s", "T90_s"),
    "policies": (*_KEYS, "coverage", "mission_time_s"),
    "regret": (*_KEYS, "coverage", "mission_time_s", "path_length_m", "T90_s", "T99_s"),
    "slam": (*_KEYS, "ate_m"),
    "slam-vs-perfect": (
        *_KEYS,
        "coverage",
        "collisions",
        "mission_time_s",
        "wall_time_s",
        "ate_m",
        "odom_ate_m",
        "map_error",
        "loop_closures",
        "slam_false_stop",
    ),
    "summary": (
        *_KEYS,
        "coverage",
        "mission_time_s",
        "path_length_m",
        "T90_s",
        "T99_s",
        "mean_map_generation_ms",
        "mean_global_planning_ms",
    ),
    "paired": (*_KEYS, "coverage", "T99_s", "collisions"),
}


@dataclass(frozen=True)
class TableReport:
    """What :func:`report_tables` read and the Markdown it made."""

    kind: str  # "benchmark", "team", "best_known" or "bound_check"
    source: Path  # the CSV file read (the first of several)
    table: str  # a name of RUN_TABLES, "team", "best_known" or "bound_check"
    rows: int  # rows read (missions, or best-known entries)
    markdown: str
    sources: tuple[Path, ...] = ()  # every CSV file read (empty: just ``source``)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready: the fields, and each Markdown table as ``{"columns", "rows"}``."""
        return {
            "kind": self.kind,
            "source": str(self.source),
            "sources": [str(p) for p in self.sources or (self.source,)],
            "table": self.table,
            "rows": self.rows,
            "tables": markdown_tables(self.markdown),
            "markdown": self.markdown,
        }


def report_tables(
    path: str | os.PathLike | Sequence[str | os.PathLike],
    table: str | None = None,
    reference: str | None = None,
) -> TableReport:
    """The Markdown tables of a result file.

    Args:
        path: a benchmark run folder (its ``runs.csv`` is read), a ``runs.csv`` (a team
            benchmark's is told by its ``n_robots`` column: its summary, with the team
            oracle's columns when the oracle ran, without headings), a best-known table
            (``configs/best_known/best_known.csv``, told by its columns), the checked
            missions of ``scripts/check_lower_bound.py --missions-out`` (the bound's check per
            family, :mod:`.bound_check`); or several benchmark run folders or ``runs.csv``
            files, whose rows are read as one.
        table: for a benchmark's ``runs.csv``, one of :data:`RUN_TABLES` (default
            ``overview``); a team benchmark's summary and a best-known table are one table
            each and take None.
        reference: the policy the others are compared with (default ``semantic``).

    Raises:
        ValueError: one line naming the problem: no such file, no ``runs.csv`` in the folder,
            an unknown table, a column the table needs that the file lacks, no rows.
    """
    from semexplore_gym.evaluation import best_known, bound_check

    paths = [path] if isinstance(path, str | os.PathLike) else list(path)
    if not paths:
        raise ValueError("no result file given")
    sources = [_csv_of(Path(p)) for p in paths]
    if len(sources) > 1:
        return _several_runs_report(sources, table, reference)
    source = sources[0]
    header = _header(source)
    if set(best_known.COLUMNS) <= set(header):
        if table is not None:
            raise ValueError(
                f"{source} is a best-known table, which has one table (got --table {table})"
            )
        entries = best_known.read_table(source)
        if not entries:
            raise ValueError(f"{source} holds no best-known entries")
        md = "\n".join(best_known.overview_lines(entries)) + "\n"
        return TableReport("best_known", source, "best_known", len(entries), md)
    if "n_robots" in header:
        return _team_report(source, header, table)
    if set(bound_check.MISSION_COLUMNS) <= set(header):
        if table is not None:
            raise ValueError(
                f"{source} holds checked missions, which have one table (got --table {table})"
            )
        missions = bound_check.read_missions(source)
        md = "\n".join(bound_check.report_lines(missions)) + "\n"
        return TableReport("bound_check", source, "bound_check", len(missions), md)
    name = table or "overview"
    if name not in RUN_TABLES:
        raise ValueError(f"unknown table {name!r}: choose one of {', '.join(RUN_TABLES)}")
    rows = read_trimmed_runs(source, NEEDED_COLUMNS[name], name)
    md = "\n".join(_run_table_lines(source, rows, name, reference)).strip() + "\n"
    return TableReport("benchmark", source, name, len(rows), md)


def _several_runs_report(
    sources: list[Path], table: str | None, reference: str | None
) -> TableReport:
    """The table of several benchmarks' ``runs.csv`` files read as one."""
    from semexplore_gym.evaluation import best_known, bound_check

    name = table or "overview"
    if name not in RUN_TABLES:
        raise ValueError(f"unknown table {name!r}: choose one of {', '.join(RUN_TABLES)}")
    if name == "summary":
        raise ValueError(f"the summary table reads one run folder (got {len(sources)})")
    for source in sources:
        header = _header(source)
        single = (best_known.COLUMNS, bound_check.MISSION_COLUMNS)
        if "n_robots" in header or any(set(c) <= set(header) for c in single):
            raise ValueError(f"{source} is not a benchmark's runs.csv: report reads it alone")
    rows: list[dict[str, Any]] = []
    for source in sources:
        rows += read_trimmed_runs(source, NEEDED_COLUMNS[name], name, allow_empty=True)
    if not rows:
        raise ValueError(f"no finished missions in {', '.join(map(str, sources))}")
    md = "\n".join(_run_table_lines(sources[0], rows, name, reference)).strip() + "\n"
    return TableReport("benchmark", sources[0], name, len(rows), md, tuple(sources))


#: The columns of a team benchmark's ``runs.csv`` that its summary reads.
TEAM_COLUMNS: tuple[str, ...] = (
    "world",
    "policy",
    "n_robots",
    "seed",
    "coverage",
    "mission_time_s",
    "self_stopped",
    "T90_s",
    "T99_s",
    "path_total_m",
    "path_per_robot_m",
    "overlap_ratio",
    "robot_collisions",
)


#: The team columns that hold numbers (the others: world and policy, free text;
#: ``self_stopped``, True or False; ``path_per_robot_m``, numbers joined by ``;``), and
#: those of them that may be empty (a team that never reached 90 % or 99 %, no bound).
_TEAM_NUMBERS = (
    "n_robots",
    "seed",
    "coverage",
    "mission_time_s",
    "T90_s",
    "T99_s",
    "path_total_m",
    "overlap_ratio",
    "robot_collisions",
    "lower_bound_s",
)
_TEAM_MAY_BE_EMPTY = ("T90_s", "T99_s", "lower_bound_s")
_TEAM_WHOLE = ("n_robots", "seed", "robot_collisions")


def _team_report(source: Path, header: list[str], table: str | None) -> TableReport:
    """A team benchmark's ``summary.md`` as one block of tables: per world family a bold line
    naming it, its table (with the oracle's three columns when the team oracle ran) and the
    paired tests; without the file's headings, so that a page can include it under its own."""
    from semexplore_gym.evaluation.team_report import team_summary_lines

    if table is not None:
        raise ValueError(
            f"{source} is a team benchmark's runs.csv, which has one table (got --table {table})"
        )
    missing = [c for c in TEAM_COLUMNS if c not in header]
    if missing:
        raise ValueError(f"{source} has no column{'s' * (len(missing) > 1)} {', '.join(missing)}")
    with source.open(newline="", encoding="utf-8", errors="replace") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        raise ValueError(f"no finished missions in {source}")
    for line, row in enumerate(rows, start=2):
        _check_team_row(row, f"{source} line {line}")
    lines = []
    for text in team_summary_lines(rows):
        if text.startswith("## "):
            lines.append(f"**{text[3:]}**")
        elif not text.startswith("# "):
            lines.append(text)
    md = "\n".join(lines).strip() + "\n"
    return TableReport("team", source, "team", len(rows), md)


def _check_team_row(row: dict[str, str | None], where: str) -> None:
    """Raise one line naming the cell when a team ``runs.csv`` row cannot be read."""
    for column in ("world", "policy"):
        if not row.get(column):
            raise ValueError(f"{where}: no {column}")
    for column in _TEAM_NUMBERS:
        value = row.get(column)
        if value is None and column != "lower_bound_s":
            raise ValueError(f"{where}: a short row (no {column} cell)")
        if value in (None, "", "None") and column in _TEAM_MAY_BE_EMPTY:
            continue
        try:
            number = int(value or "") if column in _TEAM_WHOLE else float(value or "")
        except ValueError:
            kind = "a whole number" if column in _TEAM_WHOLE else "a number"
            raise ValueError(f"{where}: {column} is {value!r}, not {kind}") from None
        if column == "n_robots" and number < 1:
            raise ValueError(f"{where}: n_robots is {value!r}; a team has at least one robot")
    if row.get("self_stopped") not in ("True", "False"):
        raise ValueError(f"{where}: self_stopped is {row.get('self_stopped')!r}, not True or False")
    per_robot = row.get("path_per_robot_m") or ""
    try:
        [float(v) for v in per_robot.split(";")]
    except ValueError:
        raise ValueError(
            f"{where}: path_per_robot_m is {per_robot!r}, not numbers joined by ';'"
        ) from None


def _csv_of(p: Path) -> Path:
    if p.is_dir():
        if not (p / "runs.csv").is_file():
            raise ValueError(
                f"{p} has no runs.csv (give a benchmark run folder, a runs.csv or a best-known CSV)"
            )
        return p / "runs.csv"
    if not p.is_file():
        raise ValueError(f"{p} does not exist")
    return p


def _header(source: Path) -> list[str]:
    with source.open(newline="", encoding="utf-8", errors="replace") as f:
        first = f.readline()
    return next(csv.reader([first]), []) if first.strip() else []


def read_trimmed_runs(
    source: Path, needed: tuple[str, ...], table: str, allow_empty: bool = False
) -> list[dict[str, Any]]:
    """The rows of a ``runs.csv`` that may lack columns other than ``needed`` (absent cells
    read as empty), numbers parsed as :func:`~.run_row.read_runs` parses them; a file without
    rows is an error unless ``allow_empty``."""
    from semexplore_gym.evaluation.run_row import CSV_COLUMNS, complete_csv_bytes, parse_cells

    text = source.read_bytes()[: complete_csv_bytes(source)].decode("utf-8", errors="replace")
    reader = csv.DictReader(io.StringIO(text, newline=""))
    columns = reader.fieldnames or []
    missing = [c for c in needed if c not in columns]
    if missing:
        s = "s" if len(missing) > 1 else ""
        raise ValueError(
            f"{source} has no column{s} {', '.join(missing)} (the {table} table reads "
            f"{', '.join(needed)})"
        )
    blank = {c: "" for c in CSV_COLUMNS if c not in columns}
    rows = [
        parse_cells({**blank, **raw}, f"{source} line {i}") for i, raw in enumerate(reader, start=2)
    ]
    if not rows and not allow_empty:
        raise ValueError(f"no finished missions in {source}")
    return rows


def _run_table_lines(
    source: Path, rows: list[dict[str, Any]], table: str, reference: str | None
) -> list[str]:
    from semexplore_gym.evaluation import regret, report
    from semexplore_gym.evaluation.slam_report import slam_table

    ref = reference or report.REFERENCE_POLICY
    if table == "paired":
        return _paired_lines(source, rows, ref)
    has_oracle = any(r["policy"] == regret.ORACLE_SPEC for r in rows)
    if table == "summary":
        lines = report.summary_lines(source.parent, rows, ref)
        return lines + (regret.summary_lines(rows, regret.regret_rows(rows)) if has_oracle else [])
    if table == "regret":
        if not has_oracle:
            raise ValueError(f"{source} has no {regret.ORACLE_SPEC} missions (run with --oracle)")
        lines = regret.summary_lines(rows, regret.regret_rows(rows))
        return lines[lines.index("") + 1 :]  # without the section's heading
    if table == "policies":
        return report.policy_table(report.policies_of(rows))
    if table == "slam-vs-perfect":
        from semexplore_gym.evaluation.slam_comparison import slam_vs_perfect_lines

        return slam_vs_perfect_lines(rows, ref)
    if table == "slam":
        lines = slam_table(report.group_by_family(rows))
        if not lines:
            raise ValueError(f"{source} has no mission with SLAM (its ate_m cells are empty)")
        return lines[lines.index("") + 1 :]  # without the section's heading
    lines = report.overview_table(report.group_by_family(rows), ref)
    return lines[lines.index("") + 1 :]  # without the section's heading


def _paired_lines(source: Path, rows: list[dict[str, Any]], reference: str) -> list[str]:
    from semexplore_gym.evaluation.learning_table import paired_table_lines

    policies = list(dict.fromkeys(r["policy"] for r in rows))
    if reference not in policies:
        raise ValueError(
            f"{source} has no {reference} missions to pair with (its policies: "
            f"{', '.join(policies)}; pick one with --reference)"
        )
    best, bound = _best_known_columns(source)
    return paired_table_lines(rows, reference, best, bound)


def _best_known_columns(
    source: Path,
) -> tuple[dict[tuple[str, int], float], dict[tuple[str, int], float]]:
    """The shipped best-known T99 and certified lower bound (s) per (world, seed) of
    ``source``'s start poses, as the run's ``benchmark.json`` (beside the CSV) gives them; none
    without one, or when its env config is not the default one (the table's missions ran on the
    default env)."""
    from semexplore_gym.evaluation.best_known import read_table, run_start

    start = run_start(source if source.is_dir() else source.parent)
    if start is None:
        return {}, {}
    entries = {(w, s): row for (w, s, st), row in read_table().items() if st == start}
    best = {k: float(r["T99_s"]) for k, r in entries.items() if r["T99_s"] is not None}
    bound = {
        k: float(r["lower_bound_s"])
        for k, r in entries.items()
        if r["lower_bound_s"] is not None and 0 < float(r["lower_bound_s"]) < math.inf
    }
    return best, bound


def markdown_tables(markdown: str) -> list[dict[str, Any]]:
    """Each pipe table of ``markdown`` as ``{"columns": [...], "rows": [[...], ...]}``."""
    tables: list[dict[str, Any]] = []
    block: list[list[str]] = []
    for line in [*markdown.splitlines(), ""]:
        if line.startswith("|"):
            block.append([c.strip() for c in line.strip().strip("|").split("|")])
            continue
        if len(block) >= 2:
            tables.append({"columns": block[0], "rows": block[2:]})
        block = []
    return tables
