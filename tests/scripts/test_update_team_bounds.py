"""scripts/update_team_bounds.py: a team runs.csv's lower bounds computed again after the run."""

from __future__ import annotations

import csv
from pathlib import Path
from typing import Any

import pytest

REPO = Path(__file__).resolve().parents[2]


@pytest.mark.slow
def test_the_bounds_computed_again_are_the_benchmarks(tmp_path: Path, capsys, script: Any) -> None:
    """The starts the script draws are the missions' own: with the same code, it gives back
    the bound each mission of a team benchmark recorded."""
    from semexplore_gym.cli import main

    out = tmp_path / "team"
    argv = ["benchmark", "--worlds", "maze:seed=*,size_m=5", "--robots", "1,3"]
    argv += ["--policies", "independent", "--runs", "2", "--max-time-s", "300"]
    assert main([*argv, "--out", str(out), "--no-progress", "--no-plots"]) == 0
    with (out / "runs.csv").open(newline="") as f:
        recorded = list(csv.DictReader(f))
    assert len(recorded) == 4 and all(r["lower_bound_s"] for r in recorded)
    blank = tmp_path / "blank.csv"
    with blank.open("w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(recorded[0]))
        w.writeheader()
        w.writerows({**r, "lower_bound_s": ""} for r in recorded)
    capsys.readouterr()
    assert script("update_team_bounds").main([str(blank)]) == 0
    printed = capsys.readouterr().out
    assert printed.count(" -> ") == 4 and "wrote " in printed
    with blank.open(newline="") as f:
        again = list(csv.DictReader(f))
    assert [r["lower_bound_s"] for r in again] == [r["lower_bound_s"] for r in recorded]
    assert [r["T99_s"] for r in again] == [r["T99_s"] for r in recorded]  # the rest kept


@pytest.mark.parametrize(
    ("text", "says"),
    [
        ("world,policy,seed\nmaze1,p,0\n", "is no team runs.csv: no column n_robots"),
        ("world,seed,n_robots\nmaze1,zero,2\n", "line 2: seed is 'zero', not a whole number"),
        ("world,seed,n_robots\n", "has no missions"),
    ],
    ids=["not a team run", "bad seed", "empty"],
)
def test_bad_input_is_one_error_line(
    tmp_path: Path, capsys, text: str, says: str, script: Any
) -> None:
    runs = tmp_path / "runs.csv"
    runs.write_text(text)
    assert script("update_team_bounds").main([str(runs)]) == 2
    captured = capsys.readouterr()
    lines = captured.err.strip().splitlines()
    assert captured.out == "" and len(lines) == 1 and lines[0].startswith("error: ")
    assert says in lines[0]
    assert runs.read_text() == text  # left as it was
    assert script("update_team_bounds").main([str(tmp_path / "none")]) == 2
    assert "does not exist" in capsys.readouterr().err


def test_a_bad_env_override_is_one_error_line(tmp_path: Path, capsys, script: Any) -> None:
    runs = tmp_path / "runs.csv"
    runs.write_text('world,seed,n_robots\n"maze:seed=1,size_m=4",0,2\n')
    assert script("update_team_bounds").main([str(runs), "--env-set", "team.no_such_key=1"]) == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: ") and "no_such_key" in lines[0]
