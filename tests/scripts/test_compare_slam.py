"""scripts/compare_slam.py: perfect-map and SLAM missions paired, per family and policy."""

from __future__ import annotations

import csv
import importlib.util
import sys
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parents[2]


def _script() -> Any:
    spec = importlib.util.spec_from_file_location(
        "compare_slam", REPO / "scripts" / "compare_slam.py"
    )
    assert spec is not None and spec.loader is not None
    mod = importlib.util.module_from_spec(spec)
    sys.modules["compare_slam"] = mod
    spec.loader.exec_module(mod)
    return mod


def _write(path: Path, rows: list[dict[str, Any]]) -> None:
    from semexplore_gym.evaluation.run_row import CSV_COLUMNS

    path.mkdir(parents=True)
    with (path / "runs.csv").open("w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(CSV_COLUMNS))
        w.writeheader()
        for r in rows:
            base = {k: "" for k in CSV_COLUMNS}
            base.update(stop_reason="done", T90_s="", T99_s="", steps="10", explored_area_m2="1")
            base.update(mean_map_generation_ms="1", mean_global_planning_ms="1", path_length_m="1")
            w.writerow({**base, **{k: str(v) for k, v in r.items()}})


def _row(policy: str, seed: int, time_s: float, wall_s: float, **slam: Any) -> dict[str, Any]:
    return {
        "world": "maze1",
        "policy": policy,
        "seed": seed,
        "mission_time_s": time_s,
        "coverage": 0.99,
        "self_stopped": True,
        "collisions": 0,
        "wall_time_s": wall_s,
        **slam,
    }


def test_missions_pair_by_world_policy_and_seed(tmp_path, capsys) -> None:
    slam_figures = {"ate_m": 0.02, "odom_ate_m": 0.4, "map_error": 0.05, "loop_closures": 3}
    perfect = [_row("semantic", s, 100.0, 1.0) for s in range(4)]
    perfect += [_row("nearest", s, 200.0, 1.0) for s in range(4)]
    slam = [
        _row("semantic", s, 110.0, 2.0, slam_false_stop=s == 0, **slam_figures) for s in range(3)
    ]
    slam += [_row("nearest", s, 150.0, 2.0, **slam_figures) for s in range(4)]
    _write(tmp_path / "perfect", perfect)
    _write(tmp_path / "slam", slam)
    assert _script().main([str(tmp_path / "perfect"), str(tmp_path / "slam")]) == 0
    out = capsys.readouterr().out
    (semantic,) = [
        line for line in out.splitlines() if line.startswith("| paper mazes | semantic |")
    ]
    cells = [c.strip() for c in semantic.strip("|").split("|")]
    assert cells[2] == "3"  # seed 3 has no SLAM twin
    assert cells[3] == "3/3 / 3/3"
    assert cells[5].startswith("1.10 (p = ")
    assert cells[6:10] == ["0.020", "20.0", "0.050", "3"]
    assert cells[10] == "1/3" and cells[12] == "2.00×"
    assert "| paper mazes | perfect | –, n = 0 | 0.50 (p = " in out  # no frontier runs
    assert "| paper mazes | SLAM | –, n = 0 | 0.73 (p = " in out


def test_a_directory_without_runs_is_one_error_line(tmp_path, capsys) -> None:
    assert _script().main([str(tmp_path / "nothing"), str(tmp_path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "no runs.csv" in err[0]
