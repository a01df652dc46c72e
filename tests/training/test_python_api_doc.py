"""The Python API snippet of ``docs/README_learning_section.md`` runs as written.

The test reads the block from the document (the first ``python`` fence), so the two cannot drift.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

DOC = Path(__file__).resolve().parents[2] / "docs" / "README_learning_section.md"


def python_blocks(markdown: str) -> list[str]:
    """The ```` ```python ```` fenced blocks of a Markdown text, in order."""
    return re.findall(r"^```python\n(.*?)^```", markdown, flags=re.DOTALL | re.MULTILINE)


def test_api_snippet_runs_as_written(
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
    one_torch_thread: None,
) -> None:
    blocks = python_blocks(DOC.read_text(encoding="utf-8"))
    assert blocks, f"no python block in {DOC}"
    monkeypatch.chdir(tmp_path)  # the snippet writes expert.npz to the working directory
    exec(compile(blocks[0], str(DOC), "exec"), {"__name__": "__doc_snippet__"})
    captured = capsys.readouterr()
    assert "coverage" in captured.out and "samples:" in captured.out
    assert (tmp_path / "expert.npz").is_file()
    # Progress bars are off by default from Python: nothing drawn on stderr.
    assert "it/s" not in captured.err and "%|" not in captured.err
