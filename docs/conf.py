"""Sphinx configuration of the SemanticExplore documentation (furo + MyST Markdown).

Build: ``python -m sphinx -W --keep-going -b html docs docs/_build/html`` (``pip install
".[docs]"``). Every code block of the pages runs in ``tests/test_readme.py``.
"""

from __future__ import annotations

import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
# The checkout's own package first (also in a git worktree beside an editable install).
sys.path.insert(0, str(ROOT))

import semexplore_gym  # noqa: E402

# The docs' own extension: the user guide's result tables, computed from docs/results/.
sys.path.insert(0, str(Path(__file__).resolve().parent / "_ext"))

project = "SemanticExplore"
author = "SemanticExplore developers"
copyright = "SemanticExplore developers"
release = semexplore_gym.__version__
version = release

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.napoleon",
    "sphinx.ext.viewcode",
    "generated_tables",
]
source_suffix = {".md": "markdown"}
root_doc = "index"
# _generated: tables the pages include; results: the data they are computed from.
exclude_patterns = ["_build", "_generated", "_ext", "results", "Thumbs.db", ".DS_Store"]
suppress_warnings: list[str] = []
if not (Path(__file__).parent / "architecture.md").is_file():
    # A checkout from before docs/architecture.md existed: the toctree's entry is left dangling.
    suppress_warnings.append("toc.not_readable")

myst_enable_extensions = ["colon_fence", "deflist"]
myst_heading_anchors = 3

autodoc_member_order = "bysource"
autodoc_typehints = "description"
autodoc_default_options = {"members": True, "show-inheritance": True}
# Gymnasium's own docstrings (inherited by reset/step/render) are written for its site, not ours.
autodoc_inherit_docstrings = False
napoleon_google_docstring = True
napoleon_numpy_docstring = False
# "Attributes:" sections as fields: NamedTuple fields would otherwise be described twice.
napoleon_use_ivar = True

html_theme = "furo"
html_title = f"SemanticExplore {release}"
html_static_path: list[str] = []


def _headings_to_rubrics(app, what, name, obj, options, lines: list[str]) -> None:
    """The env docstring marks its sections Gymnasium-style (``## Action Space``): render them
    as rubrics, with the blank line reST needs before the section's first list or table."""
    out: list[str] = []
    for line in lines:
        m = re.fullmatch(r"(\s*)#{2,4} (\S.*)", line)
        if m:
            out += [f"{m.group(1)}.. rubric:: {m.group(2)}", ""]
        else:
            out.append(line)
    lines[:] = out


def setup(app):  # type: ignore[no-untyped-def]
    app.connect("autodoc-process-docstring", _headings_to_rubrics)
