"""scripts/teacher_headroom.py: the student and the teacher's choices on the same worlds."""

from __future__ import annotations

import csv
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
SCRIPT = REPO / "scripts" / "teacher_headroom.py"


def _run(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, str(SCRIPT), *args], capture_output=True, text=True, timeout=600
    )


@pytest.mark.slow
def test_both_arms_run_paired_and_the_csv_resumes(tmp_path) -> None:
    out = tmp_path / "headroom.csv"
    args = ["--out", str(out), "--episodes", "2", "--workers", "2"]
    for s in ("splits=[mazes]", "max_size_m=6", "max_time_s=120"):
        args += ["--train-set", s]
    first = _run(*args)
    assert first.returncode == 0, first.stderr
    rows = list(csv.DictReader(out.open()))
    assert sorted((int(r["episode"]), float(r["beta"])) for r in rows) == [
        (0, 0.0),
        (0, 1.0),
        (1, 0.0),
        (1, 1.0),
    ]
    assert all(r["world"].startswith("maze:") and float(r["coverage"]) > 0 for r in rows)
    assert "median paired ratio" in first.stdout and "| teacher's choices | 2 |" in first.stdout
    again = _run(*args)  # resumed: nothing rerun, the same table
    assert again.returncode == 0 and len(list(csv.DictReader(out.open()))) == 4
    assert again.stdout == first.stdout
    bad = _run("--out", str(out), "--episodes", "0")
    assert bad.returncode == 2 and "--episodes" in bad.stderr
