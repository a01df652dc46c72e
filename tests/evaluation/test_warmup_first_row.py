"""Honest first timings on a fresh install: with an empty numba cache, the warm-up compiles
every kernel the missions reach before their clocks start, so no compile lands inside a timed
mission and the first benchmark row is timed like the rows after it.

One subprocess with its own empty ``NUMBA_CACHE_DIR`` (so everything compiles, as after
``pip install``) runs ``semexplore benchmark`` on identical missions (one world, fixed start)
and reports every kernel numba compiled outside a warm-up. The timings themselves (first row
against the next ones) are measured by ``scripts/bench_first_row.py``, not here: a unit test
that compares milliseconds fails on a loaded machine.
"""

from __future__ import annotations

import csv
import json
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]

#: Runs the benchmark CLI in-process, recording numba compiles that happen outside warm_up.
SCRIPT = r"""
import json, sys
from numba.core import event
import semexplore_gym.evaluation.rollout as rollout
import semexplore_gym.evaluation.warmup as warmup
from semexplore_gym.cli import main

state = {"phase": "set-up", "compiled": {}}

def during(phase, function):
    def wrapped(*args, **kwargs):
        before, state["phase"] = state["phase"], phase
        try:
            return function(*args, **kwargs)
        finally:
            state["phase"] = before
    return wrapped

# The harness imports both when a task runs; the warm-up's own mission is not a mission here.
rollout.run_mission = during("mission", rollout.run_mission)
warmup.warm_up = during("warm-up", warmup.warm_up)

class Compiles(event.Listener):
    def on_start(self, ev):
        f = ev.data["dispatcher"].py_func
        state["compiled"].setdefault(state["phase"], []).append(f"{f.__module__}.{f.__qualname__}")
    def on_end(self, ev):
        pass

with event.install_listener("numba:compile", Compiles()):
    rc = main(sys.argv[1:])
print("RESULT " + json.dumps({"rc": rc, "compiled": state["compiled"]}))
"""


@pytest.mark.slow
@pytest.mark.timeout(1200)
def test_no_kernel_compiles_inside_a_mission_on_an_empty_kernel_cache(
    tmp_path: Path,
) -> None:
    out = tmp_path / "bench"
    argv = ["benchmark", "--worlds", "maze1", "--policies", "semantic,frontier", "--runs", "3"]
    argv += ["--fixed-start", "--max-time-s", "40", "--no-plots", "--no-progress"]
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "numba_cache"), "PYTHONPATH": str(REPO)}
    proc = subprocess.run(
        [sys.executable, "-c", SCRIPT, *argv, "--out", str(out)],
        capture_output=True,
        text=True,
        env=env,
        cwd=tmp_path,
        timeout=1100,
    )
    result_line = [x for x in proc.stdout.splitlines() if x.startswith("RESULT ")]
    assert result_line, proc.stdout[-2000:] + proc.stderr[-2000:]
    result = json.loads(result_line[-1].removeprefix("RESULT "))
    assert result["rc"] == 0, proc.stderr[-2000:]
    assert re.search(r"compiling \d+ numba kernels", proc.stderr)  # the cache really was empty
    assert result["compiled"].get("warm-up"), result["compiled"]
    assert "mission" not in result["compiled"], f"compiled inside a mission: {result['compiled']}"

    rows = list(csv.DictReader((out / "runs.csv").open()))
    assert sorted((r["policy"], r["seed"]) for r in rows) == sorted(
        (p, str(k)) for p in ("semantic", "frontier") for k in range(3)
    )
