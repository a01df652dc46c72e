"""``semexplore report --table paired``: each policy's T99 against the reference's on the same
(world, seed), per family (the learners' table of the user guide)."""

from __future__ import annotations

import csv
from pathlib import Path

import pytest

from semexplore_gym.cli import main

COLUMNS = ("world", "policy", "seed", "self_stopped", "coverage", "T99_s", "collisions")
#: (world, seed) -> the expert's T99; the learner takes these factors of it.
EXPERT_T99 = {("maze1", 0): 100.0, ("maze1", 1): 200.0, ("maze2", 0): 400.0, ("maze2", 1): 50.0}
LEARNER_FACTOR = {("maze1", 0): 0.5, ("maze1", 1): 0.8, ("maze2", 0): 1.5, ("maze2", 1): 0.9}


def _write(path: Path, rows: list[tuple]) -> Path:
    path.mkdir(parents=True, exist_ok=True)
    with (path / "runs.csv").open("w", newline="") as f:
        w = csv.writer(f)
        w.writerow(COLUMNS)
        w.writerows(rows)
    return path


def _missions() -> list[tuple]:
    rows = [(w, "semantic", s, True, 0.999, t, 0) for (w, s), t in EXPERT_T99.items()]
    for (w, s), t in EXPERT_T99.items():
        # maze2 seed 1: the learner stopped early at 0.95 and never reached 99 %.
        stopped_short = (w, s) == ("maze2", 1)
        t99 = "" if stopped_short else t * LEARNER_FACTOR[(w, s)]
        rows.append((w, "learner", s, True, 0.95 if stopped_short else 0.998, t99, s))
    rows.append(("office:seed=1,size_m=12", "learner", 0, False, 0.9, "", ""))
    return rows


def _table_rows(out: str) -> list[str]:
    return [ln for ln in out.splitlines() if ln.startswith("| ") and "family" not in ln]


def test_each_policy_is_paired_with_the_reference_per_family(tmp_path: Path, capsys) -> None:
    run = _write(tmp_path / "run", _missions())
    assert main(["report", str(run), "--table", "paired"]) == 0
    # Learner T99s 50, 160, 600, ∞ (never reached 99 %): median 380. Ratios to the expert 0.5,
    # 0.8, 1.5, ∞: the median of the logs is between 0.8 and 1.5 (sqrt(0.8 · 1.5) = 1.10), the
    # upper quartile between 1.5 and ∞ is ∞; faster on 2 of 4; 3 self-stops at ≥ 0.97;
    # collisions 0 + 1 + 0 + 1. The office has no expert missions: nothing to pair with.
    assert _table_rows(capsys.readouterr().out) == [
        "| paper mazes | semantic | 4 | 150.0 | – | – | – | 4/4 | 0 |",
        "| paper mazes | learner | 4 | 380.0 | 1.10 [0.71–∞] | 0.88 | 2/4 | 3/4 | 2 |",
        "| office | learner | 1 | ∞ | – | – | – | 0/1 | – |",
    ]


def test_the_reference_is_the_one_asked_for(tmp_path: Path, capsys) -> None:
    run = _write(tmp_path / "run", _missions()[:8])
    assert main(["report", str(run), "--table", "paired", "--reference", "learner"]) == 0
    rows = _table_rows(capsys.readouterr().out)
    assert [r.split(" | ")[1] for r in rows] == ["learner", "semantic"]
    # Expert / learner: 2.0, 1.25, 0.67 and 0 (the learner never reached 99 %): faster on 2.
    assert rows[1].split(" | ")[4:7] == ["0.91 [0.00–1.41]", "0.88", "2/4"]


def test_identical_pairs_have_no_test(tmp_path: Path, capsys) -> None:
    same = [
        (w, p, s, True, 1.0, t, 0) for (w, s), t in EXPERT_T99.items() for p in ("semantic", "copy")
    ]
    assert main(["report", str(_write(tmp_path / "run", same)), "--table", "paired"]) == 0
    assert "| paper mazes | copy | 4 | 150.0 | 1.00 [1.00–1.00] | – | 0/4 | 4/4 | 0 |" in (
        capsys.readouterr().out
    )


@pytest.mark.parametrize(
    ("rows", "argv_tail", "says"),
    [
        (
            [("maze1", "learner", 0, True, 1.0, 80.0, 0)],
            [],
            "has no semantic missions to pair with",
        ),
        ([("maze1", "semantic", 0, True, 1.0, 80.0, 0)], ["--reference", "nearest"], "no nearest"),
        ([("maze1", "semantic", 0, True, 1.0, "fast", 0)], [], "T99_s is not a number: 'fast'"),
    ],
    ids=["no reference", "unknown reference", "bad cell"],
)
def test_bad_input_is_one_error_line(
    tmp_path: Path, capsys, rows: list[tuple], argv_tail: list[str], says: str
) -> None:
    run = _write(tmp_path / "run", rows)
    assert main(["report", str(run), "--table", "paired", *argv_tail]) == 2
    captured = capsys.readouterr()
    lines = captured.err.strip().splitlines()
    assert captured.out == "" and len(lines) == 1, captured
    assert lines[0].startswith("semexplore report: error:") and says in lines[0], lines[0]


def test_a_runs_csv_without_collisions_names_the_column(tmp_path: Path, capsys) -> None:
    run = tmp_path / "run"
    run.mkdir()
    (run / "runs.csv").write_text("world,policy,seed,self_stopped,coverage,T99_s\n")
    assert main(["report", str(run), "--table", "paired"]) == 2
    assert "has no column collisions (the paired table reads" in capsys.readouterr().err


def test_gap_closed_is_the_share_of_the_references_gap_to_the_best_known() -> None:
    from semexplore_gym.evaluation.learning_table import gap_closed

    ref = {("w", 0): {"T99_s": 100.0}, ("w", 1): {"T99_s": 200.0}, ("w", 2): {"T99_s": 50.0}}
    best = {("w", 0): 60.0, ("w", 1): 100.0, ("w", 2): 50.0}
    rows = [
        {"world": "w", "seed": 0, "T99_s": 80.0},  # gains 20 of a 40 s gap
        {"world": "w", "seed": 1, "T99_s": 220.0},  # loses 20 of a 100 s gap
        {"world": "w", "seed": 2, "T99_s": 45.0},  # the reference is the best known: no gap
    ]
    share, n = gap_closed(rows, ref, best)
    assert n == 3 and share == pytest.approx((20.0 - 20.0 + 5.0) / (40.0 + 100.0 + 0.0))
    # A pair without a 99 % on one side, or without a best known, is left out.
    rows.append({"world": "w", "seed": 3, "T99_s": 10.0})
    rows.append({"world": "w", "seed": 0, "T99_s": None})
    assert gap_closed(rows, ref, best)[1] == 3
    # No gap at all: no share.
    assert gap_closed(rows[2:3], ref, best) == (None, 1)


def test_a_default_env_run_gets_the_gap_closed_and_bound_columns_from_the_best_known_table(
    tmp_path: Path, capsys
) -> None:
    import json

    from semexplore_gym.evaluation.best_known import read_table

    run = _write(tmp_path / "run", _missions()[:8])
    (run / "benchmark.json").write_text(json.dumps({"fixed_start": False, "env_overrides": []}))
    table = {(w, s): row for (w, s, st), row in read_table().items() if st == "random"}
    assert all(k in table for k in EXPERT_T99)  # the paper suite's starts are in the table
    best = {k: row["T99_s"] for k, row in table.items()}
    bound = {k: row["lower_bound_s"] for k, row in table.items()}
    assert main(["report", str(run), "--table", "paired"]) == 0
    rows = _table_rows(capsys.readouterr().out)
    gain = sum(t - t * LEARNER_FACTOR[k] for k, t in EXPERT_T99.items() if k != ("maze2", 1))
    gap = sum(t - best[k] for k, t in EXPERT_T99.items() if k != ("maze2", 1))
    # The last two columns: the gap closed, and the median T99 over the start's bound (the
    # learner's mission short of 99 % counts as infinite, above the other three).
    expert = sorted(t / bound[k] for k, t in EXPERT_T99.items())
    learner = sorted(
        float("inf") if k == ("maze2", 1) else t * LEARNER_FACTOR[k] / bound[k]
        for k, t in EXPERT_T99.items()
    )
    assert rows[0].endswith(f" | – | {(expert[1] + expert[2]) / 2:.2f} (4) |"), rows[0]
    want = f" | {gain / gap:.2f} (3) | {(learner[1] + learner[2]) / 2:.2f} (4) |"
    assert rows[1].endswith(want), rows[1]
    # Another env config: not comparable with the table, no column.
    (run / "benchmark.json").write_text(json.dumps({"config": "slam", "env_overrides": []}))
    assert main(["report", str(run), "--table", "paired"]) == 0
    out = capsys.readouterr().out
    assert "gap closed" not in out and "bound" not in out
