"""scripts/bench_compute_scaling.py: one small world end to end (CSV, figure, table)."""

from __future__ import annotations

import csv
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parents[2]


def test_small_maze_gives_a_row_per_world_and_a_figure(
    tmp_path: Path, capsys: Any, script: Any
) -> None:
    out, fig = tmp_path / "c.csv", tmp_path / "c.png"
    argv = ["--worlds", "maze:seed=0,size_m=5", "--repeats", "1", "--out", str(out)]
    assert script("bench_compute_scaling").main([*argv, "--figure", str(fig), "--stat", "min"]) == 0
    rows = list(csv.DictReader(out.open()))
    assert len(rows) == 1 and rows[0]["world"] == "maze:seed=0,size_m=5"
    for stage in ("pm_map", "pm_plan", "fe_map", "fe_plan", "nearest_map", "nearest_plan"):
        assert float(rows[0][f"{stage}_ms"]) > 0.0
        assert float(rows[0][f"{stage}_median_ms"]) >= float(rows[0][f"{stage}_ms"])
    assert int(rows[0]["intersections"]) >= 1 and int(rows[0]["cells"]) > 0
    assert fig.stat().st_size > 0
    assert "| maze:seed=0,size_m=5 |" in capsys.readouterr().out
