"""A Sphinx step that renders the user guide's result tables from their data.

Each table of :data:`TABLES` is computed by ``semexplore report``'s own function
(:func:`semexplore_gym.evaluation.tables.report_tables`) from a small result file shipped
under ``docs/results/`` (or from a shipped table such as ``configs/best_known/best_known.csv``)
and written to ``docs/_generated/NAME.md`` (git ignores it), which a page pulls in with an
``{include} _generated/NAME.md`` block. A table therefore cannot drift from its data: to
refresh one, replace its result file and rebuild (``docs/results/README.md``).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

#: Generated file name -> (its result file, relative to ``docs/``; the table of it).
TABLES: dict[str, tuple[str, str | None]] = {
    "suites_overview": ("results/suites/runs.csv", "overview"),
    "best_known": ("../configs/best_known/best_known.csv", None),
    "oracle_regret": ("results/oracle/runs.csv", "regret"),
    "lower_bound_check": ("results/oracle/missions.csv", None),
    "slam_vs_perfect": ("results/slam/runs.csv", "slam-vs-perfect"),
    "learners_vs_expert": ("results/learning/runs.csv", "paired"),
    "learners_vs_expert_dungeon": ("results/learning_dungeon/runs.csv", "paired"),
    "teams_mazes": ("results/teams/runs.csv", None),
}
GENERATED_DIR = "_generated"


def write_tables(docs_dir: Path, out_dir: Path | None = None) -> dict[str, Path]:
    """Write every table of :data:`TABLES` into ``out_dir`` (default ``docs/_generated``);
    a file is rewritten only when its text changes. Returns ``{name: path}``."""
    from semexplore_gym.evaluation.tables import report_tables

    out = out_dir or docs_dir / GENERATED_DIR
    out.mkdir(parents=True, exist_ok=True)
    written = {}
    for name, (source, table) in TABLES.items():
        result = report_tables(docs_dir / source, table)
        shown = Path(source).as_posix().removeprefix("../")
        if not shown.startswith("configs/"):
            shown = f"docs/{shown}"
        folder = shown.removesuffix("/runs.csv")  # a run folder reads its runs.csv
        command = f"semexplore report {folder}" + (f" --table {table}" if table else "")
        text = (
            f"{result.markdown}\n"
            f"*Computed when the docs are built from `{shown}` ({result.rows} rows), by "
            f"`{command}`.*\n"
        )
        path = out / f"{name}.md"
        if not path.exists() or path.read_text(encoding="utf-8") != text:
            path.write_text(text, encoding="utf-8")
        written[name] = path
    return written


def _on_builder_inited(app: Any) -> None:
    write_tables(Path(app.srcdir))


def setup(app: Any) -> dict[str, Any]:
    app.connect("builder-inited", _on_builder_inited)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
