"""scripts/update_best_known.py: run folders merged into a table, bounds added and resumed."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from semexplore_gym.evaluation.best_known import read_table

REPO = Path(__file__).resolve().parents[2]
WORLD = "maze:seed=1,size_m=4"


@pytest.fixture(scope="module")
def run_folder(tmp_path_factory: pytest.TempPathFactory) -> Path:
    from semexplore_gym.cli import main

    out = tmp_path_factory.mktemp("bk") / "run"
    args = ["benchmark", "--worlds", WORLD, "--policies", "nearest,semantic", "--runs", "2"]
    args += ["--max-time-s", "400", "--no-progress", "--no-plots", "--out", str(out)]
    assert main(args) == 0
    return out


def test_a_run_is_merged_and_its_bounds_hold(
    run_folder: Path, tmp_path: Path, capsys: Any, script: Any
):
    pytest.importorskip("elkai")
    from semexplore_gym.evaluation.run_row import read_runs

    table = tmp_path / "t.csv"
    assert (
        script("update_best_known").main(
            [str(run_folder), "--table", str(table), "--bounds", "--json", "--no-progress"]
        )
        == 0
    )
    report = json.loads(capsys.readouterr().out)
    assert report["entries"] == 2 and report["bounds_computed"] == 2
    assert report["without_bound"] == 0
    entries = read_table(table)
    rows = read_runs(run_folder / "runs.csv")
    for (world, seed, start), e in entries.items():
        assert (world, start) == (WORLD, "random")
        mine = [r for r in rows if r["seed"] == seed and r["T99_s"] is not None]
        assert e["T99_s"] == pytest.approx(min(r["T99_s"] for r in mine), abs=1e-3)
        assert e["T99_policy"] in ("nearest", "semantic-v4")  # semantic named by its version
        # The certified bound never lies above what a policy did.
        assert 0 < e["lower_bound_s"] <= e["T99_s"]
        assert 0 < e["lower_bound_m"] <= e["D99_m"]
    # Run again: nothing new, no bound computed twice.
    assert (
        script("update_best_known").main(
            [str(run_folder), "--table", str(table), "--bounds", "--json"]
        )
        == 0
    )
    again = json.loads(capsys.readouterr().out)
    assert again["new_best_known"] == 0 and again["bounds_computed"] == 0


def test_a_folder_without_runs_is_one_error_line(tmp_path: Path, capsys: Any, script: Any):
    assert (
        script("update_best_known").main([str(tmp_path), "--table", str(tmp_path / "t.csv")]) == 2
    )
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "no runs.csv" in err[0]


def test_an_infinite_bound_is_kept_and_not_computed_again(
    tmp_path: Path, monkeypatch, capsys, script: Any
):
    mod = script("update_best_known")
    table = tmp_path / "t.csv"
    table.write_text(
        "world,seed,start,T99_s,T99_policy,D99_m,D99_policy,lower_bound_s,lower_bound_m\n"
        f'"{WORLD}",0,random,50.0,nearest,9.0,nearest,,\n'
    )
    calls: list[tuple[str, int, str]] = []

    def no_reach(world: str, seed: int, start: str) -> tuple[float, float]:
        calls.append((world, seed, start))
        return mod.math.inf, mod.math.inf

    monkeypatch.setattr(mod, "entry_bound", no_reach)
    for _ in range(2):
        assert mod.main(["--table", str(table), "--bounds", "--json", "--no-progress"]) == 0
    reports = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    assert [r["bounds_computed"] for r in reports] == [1, 0]
    assert calls == [(WORLD, 0, "random")]
    e = read_table(table)[(WORLD, 0, "random")]
    assert e["lower_bound_s"] == float("inf") and e["lower_bound_m"] == float("inf")


def test_bounds_come_from_the_folder_s_check_before_any_is_computed(
    run_folder: Path, tmp_path: Path, monkeypatch, capsys, script: Any
):
    import shutil

    mod = script("update_best_known")
    folder = tmp_path / "run"
    shutil.copytree(run_folder, folder)
    (folder / "lower_bounds.csv").write_text(
        "world,seed,lower_bound_m,lower_bound_s,groups,bound_planning_s\n"
        f'"{WORLD}",0,1.5,7.25,2,0.1\n"{WORLD}",1,inf,inf,0,0.1\n'
    )
    monkeypatch.setattr(mod, "entry_bound", lambda *a: pytest.fail(f"computed {a}"))
    table = tmp_path / "t.csv"
    assert mod.main([str(folder), "--table", str(table), "--bounds", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["bounds_computed"] == 0
    entries = read_table(table)
    assert (
        entries[(WORLD, 0, "random")]["lower_bound_s"],
        entries[(WORLD, 0, "random")]["lower_bound_m"],
    ) == (7.25, 1.5)
    assert entries[(WORLD, 1, "random")]["lower_bound_s"] == float("inf")
