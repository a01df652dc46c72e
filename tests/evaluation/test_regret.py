"""Regret against the oracle: pairing, ratios, and the files a benchmark gets."""

from __future__ import annotations

import csv
import math

import pytest

from semexplore_gym.evaluation.harness import CSV_COLUMNS
from semexplore_gym.evaluation.regret import (
    REGRET_COLUMNS,
    SECTION_TITLE,
    regret_rows,
    write_regret,
)


def _row(world: str, policy: str, seed: int, t99: float | None, path: float) -> dict:
    row = {k: None for k in CSV_COLUMNS}
    row.update(
        world=world,
        policy=policy,
        seed=seed,
        mission_time_s=500.0,
        coverage=0.995,
        self_stopped=True,
        stop_reason="x",
        path_length_m=path,
        collisions=0,
        T90_s=100.0,
        T99_s=t99,
        wall_time_s=1.0,
        explored_area_m2=10.0,
        steps=10,
    )
    return row


ROWS = [
    _row("maze:seed=1", "oracle", 0, 200.0, 50.0),
    _row("maze:seed=1", "semantic", 0, 300.0, 75.0),
    _row("maze:seed=1", "nearest", 0, None, 100.0),
    _row("maze:seed=1", "semantic", 1, 300.0, 75.0),  # no oracle on seed 1: unpaired
    _row("cave:seed=2", "oracle", 0, 100.0, 20.0),
    _row("cave:seed=2", "semantic", 0, 150.0, 30.0),
]


def test_missions_are_paired_with_the_oracle_on_the_same_world_and_seed():
    rows = {(r["world"], r["policy"], r["seed"]): r for r in regret_rows(ROWS)}
    assert set(rows) == {
        ("maze:seed=1", "semantic", 0),
        ("maze:seed=1", "nearest", 0),
        ("cave:seed=2", "semantic", 0),
    }
    sem = rows[("maze:seed=1", "semantic", 0)]
    assert sem["T99_ratio"] == 1.5 and sem["path_ratio"] == 1.5 and sem["T90_ratio"] == 1.0
    assert math.isinf(rows[("maze:seed=1", "nearest", 0)]["T99_ratio"])


def test_write_regret_adds_a_csv_a_summary_section_and_is_idempotent(tmp_path):
    with (tmp_path / "runs.csv").open("w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(CSV_COLUMNS))
        w.writeheader()
        for r in ROWS:
            w.writerow({k: "" if r[k] is None else r[k] for k in CSV_COLUMNS})
    (tmp_path / "summary.md").write_text("# Benchmark\n")
    res = write_regret(tmp_path, plots=False)
    assert res["pairs"] == 3
    with (tmp_path / "regret.csv").open() as f:
        assert tuple(next(csv.reader(f))) == REGRET_COLUMNS
    write_regret(tmp_path, plots=False)
    text = (tmp_path / "summary.md").read_text()
    assert text.startswith("# Benchmark") and text.count(SECTION_TITLE) == 1
    assert "### maze" in text and "### cave" in text and "### all worlds" in text


@pytest.mark.slow
def test_benchmark_with_the_oracle_writes_the_regret(tmp_path, capsys):
    import json

    import pytest

    from semexplore_gym.cli import main
    from semexplore_gym.evaluation.harness import read_runs

    pytest.importorskip("elkai")
    base = ["benchmark", "--worlds", "maze:seed=1,size_m=4", "--policies", "nearest", "--runs", "1"]
    base += ["--max-time-s", "400", "--no-progress"]
    assert main([*base, "--out", str(tmp_path / "plain")]) == 0
    assert not (tmp_path / "plain" / "regret.csv").exists()  # off by default without --suite
    capsys.readouterr()
    assert main([*base, "--oracle", "--out", str(tmp_path / "with"), "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["failed"] == 0
    rows = read_runs(tmp_path / "with" / "runs.csv")
    oracle = next(r for r in rows if r["policy"] == "oracle")
    assert oracle["coverage"] >= 0.99 and oracle["collisions"] == 0 and oracle["self_stopped"]
    assert (tmp_path / "with" / "regret.csv").exists()
    assert (tmp_path / "with" / "regret_ladder.png").exists()
    assert SECTION_TITLE in (tmp_path / "with" / "summary.md").read_text()


def test_a_suite_runs_the_oracle_by_default(tmp_path, capsys):
    """With --suite the oracle is on unless --no-oracle: its missions are in runs.csv and the
    regret files are written (the suite's tasks get the oracle, not only the manifest)."""
    import pytest

    from semexplore_gym.cli import main
    from semexplore_gym.evaluation.harness import read_runs

    pytest.importorskip("elkai")
    suite = tmp_path / "tiny.yaml"
    suite.write_text(
        "name: tiny\nversion: 1\ndescription: one small maze\nruns: 1\nrandom_start: true\n"
        "max_time_s: 400.0\nworlds:\n- maze:seed=1,size_m=4\n"
    )
    base = ["benchmark", "--suite", str(suite), "--policies", "nearest", "--no-progress"]
    assert main([*base, "--no-plots", "--out", str(tmp_path / "on")]) == 0
    assert {r["policy"] for r in read_runs(tmp_path / "on" / "runs.csv")} == {"nearest", "oracle"}
    assert (tmp_path / "on" / "regret.csv").exists()
    assert main([*base, "--no-plots", "--no-oracle", "--out", str(tmp_path / "off")]) == 0
    assert {r["policy"] for r in read_runs(tmp_path / "off" / "runs.csv")} == {"nearest"}
    assert not (tmp_path / "off" / "regret.csv").exists()
