"""scripts/rerun_oracle.py: today's oracle written into shipped tables, checked, resumed."""

from __future__ import annotations

import csv
from pathlib import Path

import pytest

from semexplore_gym.evaluation.best_known import read_table
from semexplore_gym.evaluation.bound_check import MISSION_COLUMNS, read_missions

pytest.importorskip("elkai")

WORLD = "maze:seed=3,size_m=4"


def _missions(path: Path, bound_s: float = 1.0) -> Path:
    rows = [
        ["runs/a", WORLD, 0, "True", "oracle", 999.0, 99.0, bound_s, 0.25],
        ["runs/a", WORLD, 0, "True", "nearest", 400.0, 80.0, bound_s, 0.25],
    ]
    with path.open("w", newline="", encoding="utf-8") as fh:
        w = csv.writer(fh)
        w.writerow(MISSION_COLUMNS)
        w.writerows(rows)
    return path


def _runs(path: Path, world: str = WORLD) -> Path:
    path.write_text(
        "world,policy,seed,self_stopped,coverage,mission_time_s,path_length_m,T90_s,T99_s\n"
        f'"{world}",oracle,0,False,0.5,999.0,99.0,900.0,999.0\n'
        f'"{world}",nearest,0,True,1.0,400.0,80.0,300.0,400.0\n',
        encoding="utf-8",
    )
    return path


def _best_known(path: Path, t99_s: float) -> Path:
    path.write_text(
        "world,seed,start,T99_s,T99_policy,D99_m,D99_policy,lower_bound_s,lower_bound_m\r\n"
        f'"{WORLD}",0,random,{t99_s},oracle,500.0,nearest,1.0,0.25\r\n',
        encoding="utf-8",
    )
    return path


@pytest.fixture
def today(short_mission) -> dict:
    """Today's oracle from the table's start, as a benchmark runs it."""
    res, _ = short_mission(WORLD, "oracle", 0, 900)
    assert res.t99_s is not None
    return {"T99_s": res.t99_s, "coverage": res.coverage, "path_m": res.path_length_m}


def test_the_tables_get_today_s_oracle_and_keep_every_other_row(tmp_path, today, capsys, script):
    missions, runs = _missions(tmp_path / "m.csv"), _runs(tmp_path / "r.csv")
    best = _best_known(tmp_path / "b.csv", t99_s=1e4)  # today's oracle is faster
    cache = tmp_path / "cache.csv"
    args = [str(missions), str(runs), str(best), "--cache", str(cache), "--no-progress"]
    assert script("rerun_oracle").main(args) == 0
    out = capsys.readouterr().out
    assert "1 starts, 0 in" in out
    checked = read_missions(missions)
    assert [m["policy"] for m in checked] == ["oracle", "nearest"]
    assert checked[0]["T99_s"] == round(today["T99_s"], 1) and checked[0]["drive_m"] < 99.0
    assert checked[1]["T99_s"] == 400.0 and checked[1]["drive_m"] == 80.0  # not the oracle's
    rows = list(csv.DictReader(runs.open(newline="", encoding="utf-8")))
    assert rows[0]["T99_s"] == repr(round(today["T99_s"], 1))
    assert rows[0]["self_stopped"] == "True" and rows[0]["coverage"] == repr(
        round(today["coverage"], 4)
    )
    assert rows[0]["path_length_m"] == repr(round(today["path_m"], 2))
    assert rows[1] == {"world": WORLD, "policy": "nearest", "seed": "0", "self_stopped": "True",
                       "coverage": "1.0", "mission_time_s": "400.0", "path_length_m": "80.0",
                       "T90_s": "300.0", "T99_s": "400.0"}  # fmt: skip
    entry = read_table(best)[(WORLD, 0, "random")]
    assert entry["T99_policy"] == "oracle" and entry["T99_s"] == round(today["T99_s"], 3)
    assert entry["D99_policy"] == "oracle" and entry["D99_m"] < 500.0
    # Rerun: every mission comes from the cache.
    assert script("rerun_oracle").main(args + ["--dry-run"]) == 0
    assert "1 starts, 1 in" in capsys.readouterr().out


def test_a_faster_old_oracle_stays_best_known_under_the_spec_that_runs_it(
    tmp_path, today, capsys, script
):
    best = _best_known(tmp_path / "b.csv", t99_s=round(today["T99_s"] * 0.9, 1))
    before = best.read_bytes()
    args = [str(best), "--cache", str(tmp_path / "c.csv"), "--no-progress"]
    assert script("rerun_oracle").main(args) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--old-spec" in err[0] and WORLD in err[0]
    assert best.read_bytes() == before
    assert script("rerun_oracle").main(args + ["--old-spec", "oracle[old=1]"]) == 0
    entry = read_table(best)[(WORLD, 0, "random")]
    assert entry["T99_policy"] == "oracle[old=1]" and entry["T99_s"] < today["T99_s"]
    assert entry["D99_policy"] == "oracle"  # the drive: today's is shorter than nearest's


def test_a_mission_below_its_bound_writes_nothing(tmp_path, today, capsys, script):
    missions = _missions(tmp_path / "m.csv", bound_s=today["T99_s"] * 2)
    before = missions.read_bytes()
    args = [str(missions), "--cache", str(tmp_path / "c.csv"), "--no-progress"]
    assert script("rerun_oracle").main(args) == 1
    captured = capsys.readouterr()
    assert "BELOW THE BOUND" in captured.out and "no table written" in captured.err
    assert missions.read_bytes() == before


def test_bad_input_is_one_line(tmp_path, capsys, script):
    rerun = script("rerun_oracle")
    runs = _runs(tmp_path / "r.csv")
    assert rerun.main([str(runs), "--cache", str(tmp_path / "c.csv")]) == 2  # start unknown
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "start of" in err[0] and WORLD in err[0]
    (tmp_path / "x.csv").write_text("a,b\n1,2\n", encoding="utf-8")
    assert rerun.main([str(tmp_path / "x.csv")]) == 2
    assert rerun.main([str(tmp_path / "nope.csv")]) == 2
    assert rerun.main([str(runs), "--workers", "0"]) == 2
    assert rerun.main([str(runs), "--max-time-s", "nan"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 4 and all(line.startswith("error: ") for line in err)
