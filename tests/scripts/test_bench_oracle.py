"""scripts/bench_oracle.py: the oracle command's wall and CPU time, tour and bound, per round."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
SCRIPT = REPO / "scripts" / "bench_oracle.py"


def _run(*args: str) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    return subprocess.run(
        [sys.executable, str(SCRIPT), *args], capture_output=True, text=True, timeout=600, env=env
    )


def test_one_round_reports_the_medians_of_tour_and_bound() -> None:
    res = _run("--world", "maze:seed=1,size_m=4", "--rounds", "1", "--json")
    assert res.returncode == 0, res.stderr
    out = json.loads(res.stdout)
    assert out["world"] == "maze:seed=1,size_m=4" and out["rounds"] == 1
    for key in ("wall_s", "cpu_s", "tour_planning_s", "bound_planning_s"):
        assert out[key] > 0, key
    assert "round 1/1:" in res.stderr


def test_a_bad_world_or_round_count_is_one_line() -> None:
    res = _run("--world", "nope", "--rounds", "1")
    assert res.returncode == 2 and "unknown world 'nope'" in res.stderr
    assert len(res.stderr.strip().splitlines()) == 1
    res = _run("--rounds", "0")
    assert res.returncode == 2 and "--rounds must be >= 1, got 0" in res.stderr
