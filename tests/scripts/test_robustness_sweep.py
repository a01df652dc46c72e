"""scripts/robustness_sweep.py through its command line, with a tiny budget."""

from __future__ import annotations

import csv
import runpy
from pathlib import Path

import pytest

SCRIPT = Path(__file__).resolve().parents[2] / "scripts" / "robustness_sweep.py"


def test_sweep_writes_runs_and_a_per_family_summary(tmp_path: Path) -> None:
    main = runpy.run_path(str(SCRIPT), run_name="sweep")["main"]
    out = tmp_path / "sweep"
    argv = [
        "--families",
        "maze,forest",
        "--per-family",
        "1",
        "--max-time-s",
        "20",
        "--out",
        str(out),
    ]
    assert main([*argv, "--gifs"]) == 0
    rows = list(csv.DictReader((out / "runs.csv").open()))
    assert sorted(r["world"].split(":")[0] for r in rows) == ["forest", "maze"]
    assert all(float(r["mission_time_s"]) <= 20.0 + 1e-9 for r in rows)
    summary = (out / "sweep.md").read_text()
    assert "| maze | semantic | 1 |" in summary and "| forest | semantic | 1 |" in summary
    assert "Failures (2)" in summary  # 20 s is too short to finish: each listed with its reason
    assert len(list((out / "failures").glob("*.gif"))) == 2  # and animated
    assert main(argv) == 0  # a rerun resumes: nothing is run twice
    assert len(list(csv.DictReader((out / "runs.csv").open()))) == 2


def test_unknown_family_is_a_clear_error(tmp_path: Path) -> None:
    main = runpy.run_path(str(SCRIPT), run_name="sweep")["main"]
    with pytest.raises(SystemExit) as e:
        main(["--families", "castle", "--out", str(tmp_path / "x")])
    assert e.value.code == 2
