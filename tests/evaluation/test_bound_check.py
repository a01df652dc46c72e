"""The lower bound's check per family from checked missions (evaluation/bound_check.py), and
`semexplore report` on a checked-missions CSV."""

from __future__ import annotations

import csv
from pathlib import Path

import pytest

from semexplore_gym.cli import main
from semexplore_gym.evaluation.bound_check import (
    MISSION_COLUMNS,
    family_report,
    read_missions,
    report_lines,
)


def _write(path: Path, rows: list[dict[str, str]], columns=MISSION_COLUMNS) -> Path:
    with path.open("w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=columns, extrasaction="ignore")
        w.writeheader()
        w.writerows(rows)
    return path


def _row(folder, world, seed, policy, t99, drive="", bound_s="10", bound_m="2"):
    return {
        "folder": folder,
        "world": world,
        "seed": str(seed),
        "random_start": "True",
        "policy": policy,
        "T99_s": t99,
        "drive_to_99_m": drive,
        "lower_bound_s": bound_s,
        "lower_bound_m": bound_m,
    }


def _missions(tmp_path: Path) -> Path:
    maze, office = "maze:seed=1,size_m=6", "office:seed=2,size_m=10"
    return _write(
        tmp_path / "checked.csv",
        [
            _row("a", maze, 0, "oracle", "30", "6"),
            _row("a", maze, 0, "semantic", "40", "8"),
            _row("a", maze, 1, "oracle", "", ""),  # never reached 99 %: a loss
            _row("a", maze, 1, "semantic", "50", "1.5"),  # drove less than the bound: a violation
            _row("b", maze, 0, "semantic", "20"),  # another folder: best known, not a pair
            _row("a", office, 0, "semantic", "5", bound_s="8"),  # sooner than the bound
        ],
    )


def test_families_count_violations_best_known_and_the_oracles_pairs(tmp_path: Path) -> None:
    fams = family_report(read_missions(_missions(tmp_path)))
    assert list(fams) == ["maze", "office", "all"]
    maze, office = fams["maze"], fams["office"]
    assert (maze["starts"], maze["missions"], maze["with_T99"]) == (2, 5, 4)
    assert (maze["T99_below_bound"], maze["drive_below_bound"]) == (0, 1)
    assert (maze["oracle_wins"], maze["oracle_pairs"]) == (1, 2)
    # Best known per start: 20 s (seed 0, folder b) and 50 s (seed 1), over a 10 s bound.
    assert maze["median_best_known_over_bound"] == pytest.approx(3.5)
    assert maze["median_oracle_over_bound"] == float("inf")  # median of 3.0 and inf
    assert office["T99_below_bound"] == 1 and office["oracle_pairs"] == 0
    assert fams["all"]["missions"] == 6


def test_report_prints_the_family_table_with_all_last(tmp_path: Path, capsys) -> None:
    assert main(["report", str(_missions(tmp_path))]) == 0
    out = capsys.readouterr().out
    assert out.splitlines()[0].startswith("missions: 6; with T99: 5, T99 below the bound: 1")
    assert "| maze | 2 | 5 | 1 | 3.50 | inf (2) | 1/2 (50 %) |" in out
    assert out.index("| office |") < out.index("| all |")
    assert "\n".join(report_lines(read_missions(tmp_path / "checked.csv"))) in out
    # The oracle's wins per folder (a suite or a run): pairs only where it ran.
    assert "| folder | oracle T99 ≤ other's |\n|---|---|\n| a | 1/2 (50 %) |\n\n" in out
    assert "| b |" not in out


def test_bad_checked_missions_are_one_line(tmp_path: Path, capsys) -> None:
    short = _write(tmp_path / "short.csv", [], columns=MISSION_COLUMNS[:-1])
    assert main(["report", str(short)]) == 2  # not a checked-missions file: no such table
    bad = _row("a", "maze1", 0, "oracle", "fast")
    for name, rows, message in (
        ("bad.csv", [bad], "'fast' is not a number"),
        ("empty.csv", [], "no checked missions"),
        ("nobound.csv", [_row("a", "maze1", 0, "oracle", "3", bound_s="")], "bound is empty"),
    ):
        capsys.readouterr()
        assert main(["report", str(_write(tmp_path / name, rows))]) == 2
        err = capsys.readouterr().err.strip()
        assert "error: " in err and message in err and "\n" not in err, err
    assert main(["report", str(_missions(tmp_path)), "--table", "regret"]) == 2
    assert "one table" in capsys.readouterr().err


def test_a_mission_two_folders_ran_counts_once(tmp_path: Path) -> None:
    from semexplore_gym.evaluation.bound_check import unique_missions

    maze = "maze:seed=1,size_m=6"
    missions = read_missions(
        _write(
            tmp_path / "twice.csv",
            [
                _row("a", maze, 0, "semantic", "40"),
                _row("b", maze, 0, "semantic", "40"),  # the same mission again
                _row("b", maze, 0, "nearest", "50"),
                _row("b", maze, 1, "semantic", "45"),  # another start
            ],
        )
    )
    kept, repeats = unique_missions(missions)
    assert repeats == 1 and [m["folder"] for m in kept] == ["a", "b", "b"]
    assert family_report(kept)["maze"]["missions"] == 3
