"""The docs' Python API snippet (Getting started, "From Python") runs as written.

The test reads the block from docs/getting-started.md (the first ``python`` fence after that heading), so
the two cannot drift.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

DOC = Path(__file__).resolve().parents[2] / "docs" / "getting-started.md"
HEADING = "## From Python: policies, missions, datasets"


def python_blocks(markdown: str) -> list[str]:
    """The ```` ```python ```` fenced blocks of a Markdown text, in order."""
    return re.findall(r"^```python\n(.*?)^```", markdown, flags=re.DOTALL | re.MULTILINE)


def test_api_snippet_runs_as_written(
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
    one_torch_thread: None,
) -> None:
    text = DOC.read_text(encoding="utf-8")
    assert HEADING in text, f"no {HEADING!r} section in {DOC}"
    blocks = python_blocks(text[text.index(HEADING) :])
    assert blocks, f"no python block in {DOC}"
    monkeypatch.chdir(tmp_path)  # the snippet writes expert.npz to the working directory
    exec(compile(blocks[0], str(DOC), "exec"), {"__name__": "__doc_snippet__"})
    captured = capsys.readouterr()
    assert "coverage" in captured.out and "samples:" in captured.out
    assert (tmp_path / "expert.npz").is_file()
    # Progress bars are off by default from Python: nothing drawn on stderr.
    assert "it/s" not in captured.err and "%|" not in captured.err
