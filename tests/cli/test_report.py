"""``semexplore report``: a run folder's or a best-known table's results as Markdown."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import pytest

from semexplore_gym.cli import main
from semexplore_gym.evaluation.best_known import COLUMNS as BEST_KNOWN_COLUMNS
from semexplore_gym.evaluation.report import write_summary
from semexplore_gym.evaluation.run_row import CSV_COLUMNS, RunRow

OFFICE = "office:seed=1,size_m=12"
#: (world, policy, seed) -> (mission time, self-stopped): semantic takes half nearest's time.
MISSIONS = {
    (world, policy, seed): (t * (1 if policy == "semantic" else 2), policy == "semantic" or seed)
    for world in ("maze1", OFFICE)
    for policy in ("semantic", "nearest")
    for seed, t in enumerate((100.0, 110.0, 120.0))
}


def _write_runs(path: Path, columns: tuple[str, ...] = ("world", "policy", "seed")) -> Path:
    """A hand-written runs.csv of :data:`MISSIONS` with ``columns`` (and the overview's)."""
    path.mkdir(parents=True, exist_ok=True)
    cols = [*columns, "self_stopped", "coverage", "mission_time_s", "T90_s"]
    with (path / "runs.csv").open("w", newline="") as f:
        w = csv.writer(f)
        w.writerow(cols)
        for (world, policy, seed), (t, stopped) in MISSIONS.items():
            cells = {"world": world, "policy": policy, "seed": seed}
            cells |= {"self_stopped": bool(stopped), "coverage": 0.99, "mission_time_s": t}
            w.writerow([cells.get(c, t * 0.8) for c in cols])
    return path


def test_report_prints_the_overview_of_a_trimmed_runs_csv(tmp_path: Path, capsys) -> None:
    run = _write_runs(tmp_path / "run")
    assert main(["report", str(run)]) == 0
    out = capsys.readouterr().out
    rows = [ln for ln in out.splitlines() if ln.startswith("| ") and "family" not in ln]
    assert rows == [
        "| paper mazes | semantic | 3 | 3/3 | 0.990 | 110.0 | 88.0 | – | – | – | – |",
        "| paper mazes | nearest | 3 | 2/3 | 0.990 | 220.0 | 176.0 | – | 0.50 | 0.1 | 0.25 |",
        "| office | semantic | 3 | 3/3 | 0.990 | 110.0 | 88.0 | – | – | – | – |",
        "| office | nearest | 3 | 2/3 | 0.990 | 220.0 | 176.0 | – | 0.50 | 0.1 | 0.25 |",
    ]


def test_report_json_is_one_document_with_the_tables_rows(tmp_path: Path, capsys) -> None:
    run = _write_runs(tmp_path / "run")
    assert main(["report", str(run / "runs.csv"), "--table", "policies", "--json"]) == 0
    out = capsys.readouterr().out
    result = json.loads(out)
    assert out.count("\n") == 1
    assert (result["kind"], result["table"], result["rows"]) == ("benchmark", "policies", 12)
    (table,) = result["tables"]
    assert table["columns"][:3] == ["policy", "n", "self-stopped"]
    assert [r[:3] for r in table["rows"]] == [["semantic", "6", "6/6"], ["nearest", "6", "4/6"]]


def test_report_out_writes_the_markdown_to_the_file(tmp_path: Path, capsys) -> None:
    run = _write_runs(tmp_path / "run")
    assert main(["report", str(run), "--out", str(tmp_path / "t.md")]) == 0
    assert capsys.readouterr().out == ""
    assert "| office | nearest | 3 | 2/3 |" in (tmp_path / "t.md").read_text()


def test_report_summary_is_the_benchmarks_summary(tmp_path: Path, capsys) -> None:
    """With every column, ``--table summary`` prints what the benchmark writes to summary.md."""
    run = tmp_path / "run"
    run.mkdir()
    with (run / "runs.csv").open("w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(CSV_COLUMNS))
        w.writeheader()
        for (world, policy, seed), (t, stopped) in MISSIONS.items():
            row = RunRow(world, policy, seed, t, 0.99, bool(stopped), "done", t / 5, 0,
                         t * 0.8, t * 0.95, 2.0 + seed, 3.0, 1.0, 40.0, 100)  # fmt: skip
            w.writerow({k: "" if v is None else v for k, v in row.to_dict().items()})
    assert main(["report", str(run), "--table", "summary"]) == 0
    printed = capsys.readouterr().out
    assert printed.strip() == write_summary(run).read_text().strip()
    assert "## All worlds (2 worlds)" in printed


def test_report_of_a_best_known_table(tmp_path: Path, capsys) -> None:
    table = tmp_path / "best_known.csv"
    with table.open("w", newline="") as f:
        w = csv.writer(f)
        w.writerow(BEST_KNOWN_COLUMNS)
        w.writerow(["maze1", 0, "random", 150.0, "semantic-v3", 30.0, "oracle", 15.0, 3.0])
        w.writerow(["maze1", 1, "random", 160.0, "oracle", 32.0, "oracle", 16.0, 3.2])
        w.writerow(["maze2", 0, "random", 170.0, "semantic-v3", 34.0, "oracle", "", ""])
    assert main(["report", str(table)]) == 0
    rows = [ln for ln in capsys.readouterr().out.splitlines() if ln.startswith("| paper")]
    assert rows == [
        "| paper mazes | random | 3 | 160.0 [150.0–160.0] | 15.0 [15.0–15.0] | "
        "32.0 [30.0–32.0] | 3.0 [3.0–3.0] | semantic-v3 2, oracle 1 |"
    ]


@pytest.mark.parametrize(
    ("make", "argv_tail", "says"),
    [
        (lambda d: d.mkdir(), [], "has no runs.csv"),
        (lambda d: None, [], "does not exist"),
        (lambda d: _write_runs(d, ("world", "seed")), [], "has no column policy"),
        (lambda d: _write_runs(d), ["--table", "summary"], "has no columns path_length_m, T99_s"),
        (lambda d: _write_runs(d), ["--out", "nowhere/x.md"], "--out"),
    ],
    ids=["no runs.csv", "no folder", "missing column", "summary columns", "bad out"],
)
def test_bad_input_is_one_error_line_and_exit_2(
    tmp_path: Path, capsys, make, argv_tail: list[str], says: str
) -> None:
    run = tmp_path / "run"
    make(run)
    assert main(["report", str(run), *argv_tail, "--json"]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    lines = captured.err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("semexplore report: error:")
    assert says in lines[0]


def test_report_of_a_team_benchmark_is_its_summary(tmp_path: Path, capsys) -> None:
    run = tmp_path / "team"
    run.mkdir()
    columns = ["world", "policy", "n_robots", "seed", "coverage", "mission_time_s"]
    columns += ["self_stopped", "T90_s", "T99_s", "path_total_m", "path_per_robot_m"]
    columns += ["overlap_ratio", "robot_collisions"]
    with (run / "runs.csv").open("w", newline="") as f:
        w = csv.writer(f)
        w.writerow(columns)
        for seed in range(2):
            w.writerow(["maze:seed=3,size_m=6", "greedy", 1, seed, 1.0, 200, True, 150, 200,
                        40, "40", 0.0, 0])  # fmt: skip
            w.writerow(["maze:seed=3,size_m=6", "greedy", 2, seed, 1.0, 120, True, 90, 100,
                        44, "20;24", 0.1, 1])  # fmt: skip
    assert main(["report", str(run)]) == 0
    out = capsys.readouterr().out
    assert "| greedy | 2 | 2 | 90.0 | 100.0 | 120.0 | 0.50 | 44.0 | 24.0 | 0.10 | 2 |" in out
    assert main(["report", str(run), "--table", "overview"]) == 2
    assert "one table" in capsys.readouterr().err


def test_report_slam_table_needs_missions_with_slam(tmp_path: Path, capsys) -> None:
    run = _write_runs(tmp_path / "run", ("world", "policy", "seed", "ate_m"))
    assert main(["report", str(run), "--table", "slam"]) == 0
    rows = [ln for ln in capsys.readouterr().out.splitlines() if ln.startswith("| office")]
    assert [r.split(" | ")[:3] for r in rows] == [
        ["| office", "semantic", "3"],
        ["| office", "nearest", "3"],
    ]
    plain = _write_runs(tmp_path / "plain")
    assert main(["report", str(plain), "--table", "slam"]) == 2
    assert "has no column ate_m" in capsys.readouterr().err


def test_report_regret_compares_each_policy_with_the_oracle(tmp_path: Path, capsys) -> None:
    run = tmp_path / "run"
    run.mkdir()
    cols = ["world", "policy", "seed", "self_stopped", "coverage", "mission_time_s"]
    cols += ["path_length_m", "T90_s", "T99_s"]
    with (run / "runs.csv").open("w", newline="") as f:
        w = csv.writer(f)
        w.writerow(cols)
        for seed in range(3):
            w.writerow(["maze1", "oracle", seed, True, 0.995, 100, 20, 80, 100])
            w.writerow(["maze1", "semantic", seed, True, 0.998, 150, 30, 120, 150])
    assert main(["report", str(run), "--table", "regret"]) == 0
    out = capsys.readouterr().out
    assert "Oracle missions: 3; self-stopped 3" in out
    assert "| semantic | 3 | 1.50 [1.50–1.50] | 1.50 [1.50–1.50] |" in out
    assert main(["report", str(_write_runs(tmp_path / "plain")), "--table", "regret"]) == 2
    assert "has no columns path_length_m, T99_s" in capsys.readouterr().err
    text = (run / "runs.csv").read_text().splitlines()
    (run / "runs.csv").write_text("\n".join(ln for ln in text if ",oracle," not in ln) + "\n")
    assert main(["report", str(run), "--table", "regret"]) == 2
    assert "has no oracle missions (run with --oracle)" in capsys.readouterr().err


def _write_slam_pair(path: Path, slam: bool, seeds: range = range(3)) -> Path:
    """A runs.csv of semantic and nearest on maze1, on the perfect map or with SLAM."""
    path.mkdir(parents=True, exist_ok=True)
    cols = ["world", "policy", "seed", "self_stopped", "coverage", "collisions"]
    cols += ["mission_time_s", "wall_time_s", "ate_m", "odom_ate_m", "map_error"]
    cols += ["loop_closures", "slam_false_stop"]
    with (path / "runs.csv").open("w", newline="") as f:
        w = csv.writer(f)
        w.writerow(cols)
        for policy, t in (("semantic", 100.0), ("nearest", 200.0)):
            for seed in seeds:
                figures = [0.02, 0.4, 0.05, 3, False] if slam else [""] * 5
                w.writerow(["maze1", policy, seed, True, 0.99, 0, t * (1.1 if slam else 1) + seed,
                            1.0 + slam, *figures])  # fmt: skip
    return path


def test_report_reads_several_runs_as_one_for_the_slam_pairs(tmp_path: Path, capsys) -> None:
    perfect = _write_slam_pair(tmp_path / "perfect", slam=False)
    slam = _write_slam_pair(tmp_path / "slam", slam=True, seeds=range(2))
    assert main(["report", str(perfect), str(slam / "runs.csv"), "--table", "slam-vs-perfect"]) == 0
    out = capsys.readouterr().out
    assert "| paper mazes | semantic | 2 | 2/2 / 2/2 | 0.990 / 0.990 | 0 / 0 | 1.10 (p = " in out
    assert "| paper mazes | nearest | 2 | 2/2 / 2/2 | 0.990 / 0.990 | 0 / 0 | 1.10 (p = " in out
    assert "| family | map | semantic ÷ nearest |" in out
    assert "| paper mazes | SLAM | 0.50 (p = " in out
    # Several runs read as one for any benchmark table, and --json names every file read.
    assert main(["report", str(perfect), str(slam), "--table", "policies", "--json"]) == 0
    result = json.loads(capsys.readouterr().out)
    assert result["rows"] == 10
    assert result["sources"] == [str(perfect / "runs.csv"), str(slam / "runs.csv")]
    assert [r[:2] for r in result["tables"][0]["rows"]] == [["semantic", "5"], ["nearest", "5"]]


@pytest.mark.parametrize(
    ("second", "argv_tail", "says"),
    [
        ("perfect", ["--table", "slam-vs-perfect"], "two perfect-map missions of world maze1"),
        ("none", ["--table", "slam-vs-perfect"], "no perfect-map mission has a SLAM twin"),
        ("plain", ["--table", "slam-vs-perfect"], "has no columns collisions, wall_time_s"),
        ("slam", ["--table", "summary"], "the summary table reads one run folder (got 2)"),
        ("best_known", [], "is not a benchmark's runs.csv: report reads it alone"),
    ],
)
def test_bad_slam_pairs_are_one_error_line(
    tmp_path: Path, capsys, second: str, argv_tail: list[str], says: str
) -> None:
    perfect = _write_slam_pair(tmp_path / "perfect", slam=False)
    other = {
        "perfect": perfect,
        "none": _write_slam_pair(tmp_path / "none", slam=False, seeds=range(5, 7)),
        "plain": _write_runs(tmp_path / "plain"),
        "slam": _write_slam_pair(tmp_path / "slam", slam=True),
        "best_known": tmp_path / "best_known.csv",
    }[second]
    if second == "best_known":
        other.write_text(",".join(BEST_KNOWN_COLUMNS) + "\n")
    assert main(["report", str(perfect), str(other), *argv_tail]) == 2
    captured = capsys.readouterr()
    lines = captured.err.strip().splitlines()
    assert captured.out == "" and len(lines) == 1, captured.err
    assert lines[0].startswith("semexplore report: error:") and says in lines[0]


#: The team runs.csv's columns, the oracle's bound last.
TEAM_COLUMNS = ["world", "policy", "n_robots", "seed", "coverage", "mission_time_s"]
TEAM_COLUMNS += ["self_stopped", "T90_s", "T99_s", "path_total_m", "path_per_robot_m"]
TEAM_COLUMNS += ["overlap_ratio", "robot_collisions", "lower_bound_s"]


def _write_team_runs(path: Path, edit: dict[str, str] | None = None) -> Path:
    """A team runs.csv: one maze, two starts, the team oracle (T99 100 s alone, 60 s with two
    robots) and independent robots (150 s, 90 s); the bound 20 s alone, 10 s with two; the
    first row's cells replaced by ``edit``."""
    path.mkdir(parents=True, exist_ok=True)
    missions = [("team_oracle", 1, 100.0, 20.0), ("team_oracle", 2, 60.0, 10.0)]
    missions += [("team_independent", 1, 150.0, 20.0), ("team_independent", 2, 90.0, 10.0)]
    with (path / "runs.csv").open("w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=TEAM_COLUMNS)
        w.writeheader()
        for i, (seed, (policy, n, t99, bound)) in enumerate(
            (s, m) for s in range(2) for m in missions
        ):
            per_robot = ";".join([str(40.0 / n)] * n)
            cells = [
                "maze:seed=3,size_m=6", policy, n, seed, 0.995, t99 + 5, True, t99 * 0.8, t99,
                40.0, per_robot, 0.1 * (n - 1), 0, bound,
            ]  # fmt: skip
            row = dict(zip(TEAM_COLUMNS, map(str, cells), strict=True))
            w.writerow({**row, **(edit or {})} if i == 0 else row)
    return path


def test_report_of_a_team_run_with_the_oracle_computes_its_columns(tmp_path: Path, capsys) -> None:
    run = _write_team_runs(tmp_path / "team")
    assert main(["report", str(run)]) == 0
    out = capsys.readouterr().out
    assert out.splitlines()[:2] == ["**maze**", ""]  # no headings: a page includes it
    assert not [ln for ln in out.splitlines() if ln.startswith("#")]
    header = next(ln for ln in out.splitlines() if ln.startswith("| policy"))
    assert header.endswith("| T_oracle(1) / T99 | regret | T99 / bound |")
    rows = [ln for ln in out.splitlines() if ln.startswith("| team_")]
    # T_oracle(1) / T99: 100 / T99; regret: T99 over the team oracle's with as many robots;
    # T99 / bound: T99 over the row's lower_bound_s.
    assert [r.split(" | ")[-3:] for r in rows] == [
        ["0.67", "1.50", "7.50 |"],  # independent alone: 100/150, 150/100, 150/20
        ["1.11", "1.50", "9.00 |"],  # independent, two: 100/90, 90/60, 90/10
        ["1.00", "1.00", "5.00 |"],  # the oracle alone
        ["1.67", "1.00", "6.00 |"],  # the oracle with two: its speed-up 100/60
    ]
    assert rows[0].startswith("| team_independent | 1 | 2 | 120.0 | 150.0 | 155.0 | 1.00 |")
    assert main(["report", str(run), "--json"]) == 0
    result = json.loads(capsys.readouterr().out)
    assert result["kind"] == "team"
    assert result["tables"][0]["rows"][3][-3:] == ["1.67", "1.00", "6.00"]


def test_report_of_a_team_run_without_a_bound_shows_a_dash(tmp_path: Path, capsys) -> None:
    run = _write_team_runs(tmp_path / "team")
    lines = (run / "runs.csv").read_text().splitlines()
    (run / "runs.csv").write_text("\n".join(ln.rsplit(",", 1)[0] for ln in lines) + "\n")
    assert main(["report", str(run)]) == 0
    rows = [ln for ln in capsys.readouterr().out.splitlines() if ln.startswith("| team_")]
    assert rows[1].endswith("| 1.11 | 1.50 | - |")


@pytest.mark.parametrize(
    ("edit", "says"),
    [
        ({"T99_s": "fast"}, "line 2: T99_s is 'fast', not a number"),
        ({"n_robots": "two"}, "line 2: n_robots is 'two', not a whole number"),
        ({"n_robots": "0"}, "line 2: n_robots is '0'; a team has at least one robot"),
        ({"seed": "1.5"}, "line 2: seed is '1.5', not a whole number"),
        ({"self_stopped": "yes"}, "line 2: self_stopped is 'yes', not True or False"),
        ({"path_per_robot_m": "20,20"}, "path_per_robot_m is '20,20', not numbers joined by ';'"),
        ({"world": ""}, "line 2: no world"),
    ],
    ids=["T99", "robots", "no robot", "seed", "self-stopped", "per robot", "world"],
)
def test_a_bad_team_cell_is_one_error_line_naming_it(
    tmp_path: Path, capsys, edit: dict[str, str], says: str
) -> None:
    run = _write_team_runs(tmp_path / "team", edit)
    assert main(["report", str(run)]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    lines = captured.err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("semexplore report: error:"), lines
    assert str(run / "runs.csv") in lines[0] and says in lines[0]
