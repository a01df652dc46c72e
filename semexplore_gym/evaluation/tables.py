"""Markdown tables from result files: a benchmark's or a team benchmark's ``runs.csv``, or a
best-known table.

One function, :func:`report_tables`, serves ``semexplore report`` and the docs build, which
renders the user guide's result tables from the small result files under ``docs/results/`` (a
table in the guide is computed from its data, never pasted). A benchmark's tables are those of
its ``summary.md`` (:mod:`.report`); a ``runs.csv`` trimmed to the columns a table needs is
enough for that table.
"""

from __future__ import annotations

import csv
import io
from dataclasses import dataclass
from pathlib import Path
from typing import Any

#: The tables of a benchmark's ``runs.csv``: the summary's overview (one row per family and
#: policy), its per-policy table over all worlds, its regret against the oracle (a run with
#: ``--oracle``), its SLAM table (missions with SLAM), or the whole summary as far as
#: ``runs.csv`` holds it (the best-known and learning sections read other files), or each
#: policy's T99 paired with the reference's per family (``paired``: the learners' table).
RUN_TABLES: tuple[str, ...] = ("overview", "policies", "regret", "slam", "summary", "paired")
_KEYS = ("world", "policy", "seed", "self_stopped")
#: The ``runs.csv`` columns each table reads (the others may be absent).
NEEDED_COLUMNS: dict[str, tuple[str, ...]] = {
    "overview": (*_KEYS, "coverage", "mission_time_s", "T90_s"),
    "policies": (*_KEYS, "coverage", "mission_time_s"),
    "regret": (*_KEYS, "coverage", "mission_time_s", "path_length_m", "T90_s", "T99_s"),
    "slam": (*_KEYS, "ate_m"),
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

    kind: str  # "benchmark", "team" or "best_known"
    source: Path  # the CSV file read
    table: str  # a name of RUN_TABLES, "team" or "best_known"
    rows: int  # rows read (missions, or best-known entries)
    markdown: str

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready: the fields, and each Markdown table as ``{"columns", "rows"}``."""
        return {
            "kind": self.kind,
            "source": str(self.source),
            "table": self.table,
            "rows": self.rows,
            "tables": markdown_tables(self.markdown),
            "markdown": self.markdown,
        }


def report_tables(
    path: str | Path, table: str | None = None, reference: str | None = None
) -> TableReport:
    """The Markdown tables of a result file.

    Args:
        path: a benchmark run folder (its ``runs.csv`` is read), a ``runs.csv`` (a team
            benchmark's is told by its ``n_robots`` column), or a best-known table
            (``configs/best_known/best_known.csv``, told by its columns).
        table: for a benchmark's ``runs.csv``, one of :data:`RUN_TABLES` (default
            ``overview``); a team benchmark's summary and a best-known table are one table
            each and take None.
        reference: the policy the others are compared with (default ``semantic``).

    Raises:
        ValueError: one line naming the problem: no such file, no ``runs.csv`` in the folder,
            an unknown table, a column the table needs that the file lacks, no rows.
    """
    from semexplore_gym.evaluation import best_known

    source = _csv_of(Path(path))
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
    name = table or "overview"
    if name not in RUN_TABLES:
        raise ValueError(f"unknown table {name!r}: choose one of {', '.join(RUN_TABLES)}")
    rows = read_trimmed_runs(source, NEEDED_COLUMNS[name], name)
    md = "\n".join(_run_table_lines(source, rows, name, reference)).strip() + "\n"
    return TableReport("benchmark", source, name, len(rows), md)


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


def _team_report(source: Path, header: list[str], table: str | None) -> TableReport:
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
    try:
        md = "\n".join(team_summary_lines(rows)).strip() + "\n"
    except (TypeError, IndexError) as e:
        raise ValueError(f"{source}: a malformed row ({e})") from None
    return TableReport("team", source, "team", len(rows), md)


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


def read_trimmed_runs(source: Path, needed: tuple[str, ...], table: str) -> list[dict[str, Any]]:
    """The rows of a ``runs.csv`` that may lack columns other than ``needed`` (absent cells
    read as empty), numbers parsed as :func:`~.run_row.read_runs` parses them."""
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
    if not rows:
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
    return paired_table_lines(rows, reference)


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
