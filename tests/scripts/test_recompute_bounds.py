"""scripts/recompute_bounds.py: today's bound written into shipped tables, checked, resumed."""

from __future__ import annotations

import csv
from pathlib import Path

import pytest

from semexplore_gym.evaluation.best_known import read_table
from semexplore_gym.evaluation.bound_check import MISSION_COLUMNS, read_missions

WORLD = "maze:seed=3,size_m=4"
PLACEHOLDER = "maze:seed=*,size_m=4"


def _missions(path: Path, t99_s: float) -> Path:
    rows = [
        ["runs/a", WORLD, 0, "True", "nearest", t99_s, 30.0, 1.0, 0.25],
        ["runs/a", WORLD, 0, "True", "semantic", 400.0, "", 1.0, 0.25],
        ["runs/b", PLACEHOLDER, 5, "False", "nearest", 500.0, 31.5, 2.0, 0.5],
    ]
    with path.open("w", newline="", encoding="utf-8") as fh:
        w = csv.writer(fh)
        w.writerow(MISSION_COLUMNS)
        w.writerows(rows)
    return path


def _best_known(path: Path) -> Path:
    path.write_text(
        "world,seed,start,T99_s,T99_policy,D99_m,D99_policy,lower_bound_s,lower_bound_m\r\n"
        f'"{WORLD}",0,random,250.0,nearest,30.0,nearest,1.0,0.25\r\n',
        encoding="utf-8",
    )
    return path


@pytest.fixture(scope="module")
def truth() -> dict:
    """Each start's bound as `semexplore oracle` computes it."""
    from semexplore_gym.cli.oracle import certified_bound

    a = certified_bound(WORLD, 0, env_overrides=["episode.random_start=true"])
    b = certified_bound("maze:seed=5,size_m=4", 5, env_overrides=["episode.random_start=false"])
    return {(WORLD, 0): (a.time_s, a.distance_m), (PLACEHOLDER, 5): (b.time_s, b.distance_m)}


def test_both_tables_get_today_s_bound_and_keep_every_other_cell(tmp_path, truth, capsys, script):
    missions = _missions(tmp_path / "m.csv", 250.0)
    best = _best_known(tmp_path / "b.csv")
    cache = tmp_path / "cache.csv"
    args = [str(best), str(missions), "--cache", str(cache), "--no-progress"]
    assert script("recompute_bounds").main(args) == 0
    out = capsys.readouterr().out
    assert "2 starts, 0 in" in out and "0 violations" in out
    checked = read_missions(missions)
    assert [m["policy"] for m in checked] == ["nearest", "semantic", "nearest"]
    assert [m["T99_s"] for m in checked] == [250.0, 400.0, 500.0]
    assert checked[1]["drive_m"] is None  # an empty cell stays empty
    for m in checked:
        want_s, want_m = truth[m["start"][:2]]
        assert m["bound_s"] == round(want_s, 4) and m["bound_m"] == round(want_m, 4)
        assert m["bound_m"] != 0.25 and m["bound_m"] != 0.5  # the old ones are gone
    entry = read_table(best)[(WORLD, 0, "random")]
    assert entry["lower_bound_s"] == round(truth[(WORLD, 0)][0], 3)
    assert entry["T99_policy"] == "nearest" and entry["D99_m"] == 30.0
    assert best.read_bytes().count(b"\r\n") == 2  # written as the table writer writes it
    # Rerun: every bound comes from the cache, nothing is computed again.
    assert script("recompute_bounds").main(args + ["--dry-run"]) == 0
    assert "2 starts, 2 in" in capsys.readouterr().out


def test_a_mission_below_the_new_bound_writes_nothing(tmp_path, truth, capsys, script):
    too_fast = truth[(WORLD, 0)][0] * 0.5
    missions = _missions(tmp_path / "m.csv", too_fast)
    before = missions.read_bytes()
    args = [str(missions), "--cache", str(tmp_path / "c.csv"), "--no-progress"]
    assert script("recompute_bounds").main(args) == 1
    captured = capsys.readouterr()
    assert "VIOLATION" in captured.out and "1 violations" in captured.out
    assert "no table written" in captured.err
    assert missions.read_bytes() == before


def test_bad_input_is_one_clear_line(tmp_path, capsys, script):
    other = tmp_path / "x.csv"
    other.write_text("a,b\n1,2\n", encoding="utf-8")
    for args, needle in (
        ([str(tmp_path / "none.csv")], "does not exist"),
        ([str(other)], "neither a best-known table nor a checked-missions CSV"),
        ([str(other), "--workers", "0"], "--workers must be at least 1, got 0"),
    ):
        assert script("recompute_bounds").main(args) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and needle in err[0]


def test_a_map_not_on_this_machine_is_one_clear_line(tmp_path, capsys, script, monkeypatch):
    monkeypatch.setenv("SEMEXPLORE_MAPS_DIR", str(tmp_path / "no_maps"))
    table = tmp_path / "best.csv"
    table.write_text(
        "world,seed,start,T99_s,T99_policy,D99_m,D99_policy,lower_bound_s,lower_bound_m\r\n"
        '"map:brsu-c069",0,random,250.0,nearest,30.0,nearest,1.0,0.25\r\n',
        encoding="utf-8",
    )
    args = [str(table), "--cache", str(tmp_path / "cache.csv"), "--no-progress"]
    assert script("recompute_bounds").main(args) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "brsu-c069" in err[0] and "semexplore maps get" in err[0]
