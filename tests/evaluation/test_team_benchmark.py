"""The team benchmark: ``semexplore benchmark --robots``, its columns, summary and resume."""

from __future__ import annotations

import csv
from pathlib import Path

import pytest

pytest.importorskip("pettingzoo")

from semexplore_gym.cli import main  # noqa: E402
from semexplore_gym.evaluation.team_benchmark import COLUMNS, SLAM_COLUMNS  # noqa: E402


@pytest.mark.slow
def test_benchmark_robots_writes_team_columns(tmp_path: Path) -> None:
    out = tmp_path / "team"
    argv = [
        "benchmark",
        "--worlds",
        "maze:seed=2,size_m=6",
        "--robots",
        "1,2",
        "--policies",
        "coordinated,independent",
        "--runs",
        "1",
        "--max-time-s",
        "30",
        "--out",
        str(out),
        "--no-progress",
    ]
    assert main(argv) == 0
    with (out / "runs.csv").open(newline="") as f:
        rows = list(csv.DictReader(f))
    assert tuple(rows[0]) == (*COLUMNS, *SLAM_COLUMNS)
    assert {(r["policy"], r["n_robots"]) for r in rows} == {
        ("team_coordinated", "1"),
        ("team_coordinated", "2"),
        ("team_independent", "1"),
        ("team_independent", "2"),
    }
    for r in rows:
        per_robot = [float(v) for v in r["path_per_robot_m"].split(";")]
        assert len(per_robot) == int(r["n_robots"])
        assert float(r["path_total_m"]) == pytest.approx(sum(per_robot), abs=0.01)
        assert 0.0 <= float(r["overlap_ratio"]) <= 1.0
        if r["n_robots"] == "1":
            assert float(r["overlap_ratio"]) == 0.0
        assert float(r["mission_time_s"]) <= 30.0 + 1e-6
    summary = (out / "summary.md").read_text()
    assert "T99 / 1 robot" in summary and "overlap" in summary and "coverage min" in summary
    assert (out / "team_speedup.png").stat().st_size > 0
    # Rerunning resumes: nothing runs again.
    assert main(argv) == 0
    with (out / "runs.csv").open(newline="") as f:
        assert len(list(csv.DictReader(f))) == 4
    # Two worker processes write the same missions (in the order they end).
    par = tmp_path / "par"
    argv[argv.index(str(out))] = str(par)
    assert main([*argv, "--workers", "2", "--no-plots"]) == 0
    with (par / "runs.csv").open(newline="") as f:
        par_rows = list(csv.DictReader(f))
    assert not (par / "team_speedup.png").exists()

    def key(r: dict[str, str]) -> tuple[str, ...]:
        return tuple(v for k, v in r.items() if k != "wall_time_s")

    assert sorted(map(key, par_rows)) == sorted(map(key, rows))


def test_team_summary_pairs_and_speedups(tmp_path: Path) -> None:
    from semexplore_gym.evaluation.team_report import paired_tests, speedup_ratios

    rows = []
    for seed in range(8):
        for pol, t1, t2 in (("team_semantic", 100.0, 50.0), ("team_independent", 120.0, 90.0)):
            for n, t99 in ((1, t1 + seed), (2, t2 + seed)):
                never = pol == "team_independent" and n == 2 and seed == 7
                rows.append(
                    {
                        "world": f"maze:seed={seed}",
                        "policy": pol,
                        "n_robots": str(n),
                        "seed": str(seed),
                        "T99_s": "" if never else str(t99),
                    }
                )
    ratios = speedup_ratios(rows)
    assert ratios[("maze", "team_semantic", 2)][0] == pytest.approx(0.5)
    assert ratios[("maze", "team_semantic", 1)] == [1.0] * 8
    lines = paired_tests(rows)
    two = [line for line in lines if "2 robots" in line]
    assert len(two) == 1 and "over 7 pairs" in two[0] and "(1 left out: no T99)" in two[0]
    p = float(two[0].split("Wilcoxon p = ")[1].split(" ")[0])
    assert p < 0.05  # semantic was faster on every one of the 7 seeds


@pytest.mark.slow
def test_benchmark_robots_runs_the_team_oracle_and_its_bound_holds(tmp_path: Path) -> None:
    pytest.importorskip("elkai")
    pytest.importorskip("ortools")
    out = tmp_path / "oracle"
    argv = [
        "benchmark",
        "--worlds",
        "maze:seed=*,size_m=5",
        "--robots",
        "1,2",
        "--policies",
        "independent",
        "--oracle",
        "--runs",
        "2",
        "--max-time-s",
        "600",
        "--out",
        str(out),
        "--no-progress",
        "--no-plots",
    ]
    assert main(argv) == 0
    with (out / "runs.csv").open(newline="") as f:
        rows = list(csv.DictReader(f))
    assert {(r["policy"], r["n_robots"]) for r in rows} == {
        (p, n) for p in ("team_independent", "team_oracle") for n in ("1", "2")
    }
    for r in rows:
        assert r["T99_s"], r  # every team reaches 99 % on these small mazes
        assert 0.0 <= float(r["lower_bound_s"]) <= float(r["T99_s"]), r
    summary = (out / "summary.md").read_text()
    assert "| T_oracle(1) / T99 | regret | T99 / bound |" in summary
    oracle_two = next(line for line in summary.splitlines() if line.startswith("| team_oracle | 2"))
    assert oracle_two.split("|")[-3].strip() == "1.00"  # the oracle's regret to itself


def test_team_summary_gains_the_oracle_columns(tmp_path: Path) -> None:
    from semexplore_gym.evaluation.team_report import oracle_ratios

    rows = [
        {
            "world": "maze:seed=1",
            "policy": pol,
            "n_robots": str(n),
            "seed": "1",
            "T99_s": t99,
            "lower_bound_s": bound,
        }
        for pol, n, t99, bound in (
            ("team_oracle", 1, "100", "20"),
            ("team_oracle", 2, "60", "10"),
            ("team_semantic", 1, "150", "20"),
            ("team_semantic", 2, "90", ""),
        )
    ]
    got = oracle_ratios(rows)
    assert got[("maze", "team_oracle", 2)] == [[pytest.approx(100 / 60)], [1.0], [6.0]]
    speedup, regret, over_bound = got[("maze", "team_semantic", 2)]
    assert speedup == [pytest.approx(100 / 90)] and regret == [1.5]
    assert over_bound[0] != over_bound[0]  # no bound: NaN


def test_resuming_an_older_runs_csv_adds_the_bound_column(tmp_path: Path) -> None:
    from semexplore_gym.evaluation.team_benchmark import TeamBenchmarkConfig, run_team_benchmark

    old = [c for c in COLUMNS if c != "lower_bound_s"]
    (tmp_path / "runs.csv").write_text(
        ",".join(old)
        + "\n"
        + ",".join(
            {
                "world": "maze:seed=3",
                "policy": "team_independent",
                "n_robots": "1",
                "seed": "0",
            }.get(c, "1")
            for c in old
        )
        + "\n"
    )
    config = TeamBenchmarkConfig(
        worlds=("maze:seed=3",),
        policies=("independent",),
        robot_counts=(1,),
        seeds=(0,),
        out=tmp_path,
        progress=False,
    )
    assert run_team_benchmark(config)["skipped"] == 1
    with (tmp_path / "runs.csv").open(newline="") as f:
        rows = list(csv.DictReader(f))
    assert tuple(rows[0]) == COLUMNS and rows[0]["lower_bound_s"] == ""
    assert rows[0]["policy"] == "team_independent"


def test_team_mission_gif(tmp_path: Path) -> None:
    from semexplore_gym.policies.team import make_team_policy

    from semexplore_gym.envs.multi_robot import make_multi
    from semexplore_gym.evaluation.team_benchmark import run_team_mission

    env = make_multi(
        world="maze:seed=2,size_m=6",
        n_robots=2,
        render_mode="rgb_array",
        overrides=["episode.coverage_goal=1.0"],
    )
    gif = tmp_path / "team.gif"
    res = run_team_mission(env, make_team_policy("coordinated"), 0, max_time_s=6.0, gif_path=gif)
    assert gif.stat().st_size > 0
    assert res.n_robots == 2 and res.mission_time_s == pytest.approx(6.0)


def test_benchmark_robots_with_a_suite(tmp_path: Path) -> None:
    suite = tmp_path / "tiny.yaml"
    suite.write_text(
        "name: tiny\nversion: 1\nruns: 1\nmax_time_s: 8\nworlds:\n- maze:seed=3,size_m=6\n"
    )
    out = tmp_path / "suite"
    argv = ["benchmark", "--suite", str(suite), "--robots", "2", "--policies", "greedy"]
    assert main([*argv, "--out", str(out), "--no-progress"]) == 0
    with (out / "runs.csv").open(newline="") as f:
        rows = list(csv.DictReader(f))
    assert [(r["world"], r["policy"], r["n_robots"]) for r in rows] == [
        ("maze:seed=3,size_m=6", "team_greedy", "2")
    ]
    assert float(rows[0]["mission_time_s"]) == pytest.approx(8.0)


def test_benchmark_missions_end_by_the_team_stop_rule(tmp_path: Path) -> None:
    # The benchmark's env never ends a mission at its coverage goal: the team stops itself
    # (no robot has a reachable frontier), and runs.csv says so; the time limit says its own.
    out = tmp_path / "stop"
    argv = ["benchmark", "--worlds", "office:seed=304,size_m=8", "--robots", "2"]
    argv += ["--policies", "coordinated", "--runs", "1", "--no-progress"]
    assert main([*argv, "--max-time-s", "200", "--out", str(out)]) == 0
    with (out / "runs.csv").open(newline="") as f:
        (row,) = list(csv.DictReader(f))
    assert row["self_stopped"] == "True"
    assert row["stop_reason"].startswith("no robot has a reachable frontier")
    assert float(row["coverage"]) >= 0.97 and float(row["mission_time_s"]) < 200.0
    assert "| 1/1 |" in (out / "summary.md").read_text()
    short = tmp_path / "short"
    assert main([*argv, "--max-time-s", "5", "--out", str(short)]) == 0
    with (short / "runs.csv").open(newline="") as f:
        (row,) = list(csv.DictReader(f))
    assert row["self_stopped"] == "False"
    assert row["stop_reason"] == "env truncated (episode time limit)"
    assert float(row["mission_time_s"]) == pytest.approx(5.0)


def test_two_commands_share_one_study_directory(tmp_path: Path) -> None:
    # One command per family into one directory: runs.csv, summary.md and the manifest hold both.
    import json

    out = tmp_path / "study"
    base = ["benchmark", "--robots", "1,2", "--policies", "independent", "--max-time-s", "10"]
    base += ["--out", str(out), "--no-progress", "--no-plots"]
    assert main([*base, "--worlds", "maze:seed=*,size_m=6", "--runs", "2", "--seed0", "5"]) == 0
    assert main([*base, "--worlds", "office:seed=*,size_m=8", "--runs", "1", "--seed0", "7"]) == 0
    with (out / "runs.csv").open(newline="") as f:
        rows = list(csv.DictReader(f))
    assert sorted((r["world"], r["n_robots"]) for r in rows) == sorted(
        [(f"maze:seed={s},size_m=6", n) for s in (5, 6) for n in ("1", "2")]
        + [("office:seed=7,size_m=8", n) for n in ("1", "2")]
    )
    summary = (out / "summary.md").read_text()
    assert "## maze" in summary and "## office" in summary
    runs = json.loads((out / "manifest.json").read_text())["runs"]
    assert [r["seeds"] for r in runs] == [[5, 6], [7]]


def test_benchmark_robots_compares_team_variants(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # A team spec with a bracket of overrides is a variant of its own: rows, summary and
    # resume key carry the bracket; a variant that changes nothing drives the same missions.
    out = tmp_path / "variants"
    argv = [
        "benchmark",
        "--worlds",
        "maze:seed=2,size_m=6",
        "--robots",
        "2",
        "--policies",
        "greedy,greedy[claim_radius_m=2.0],greedy[claim_radius_m=0]",
        "--runs",
        "1",
        "--max-time-s",
        "20",
        "--out",
        str(out),
        "--no-progress",
        "--no-plots",
    ]
    assert main(argv) == 0
    with (out / "runs.csv").open(newline="") as f:
        rows = {r["policy"]: r for r in csv.DictReader(f)}
    assert set(rows) == {
        "team_greedy",
        "team_greedy[claim_radius_m=2.0]",
        "team_greedy[claim_radius_m=0]",
    }
    same = ("coverage", "mission_time_s", "path_per_robot_m", "steps")
    # 2.0 m is greedy's default claim radius: the same missions.
    assert [rows["team_greedy"][k] for k in same] == [
        rows["team_greedy[claim_radius_m=2.0]"][k] for k in same
    ]
    assert "team_greedy[claim_radius_m=0]" in (out / "summary.md").read_text()
    capsys.readouterr()
    # A misspelt parameter fails before any mission, naming the spec and the key.
    bad = [*argv[:6], "semantic[discount_wieght=6]", *argv[7:]]
    bad[bad.index(str(out))] = str(tmp_path / "bad")
    assert main(bad) != 0
    err = capsys.readouterr().err
    assert "semantic[discount_wieght=6]" in err and "unknown config key" in err
    assert not (tmp_path / "bad").exists()


def test_explore_robots_takes_a_team_variant(capsys: pytest.CaptureFixture[str]) -> None:
    argv = ["explore", "--world", "maze:seed=2,size_m=6", "--robots", "2", "--max-time-s", "5"]
    assert main([*argv, "--policy", "greedy[claim_radius_m=1]"]) == 0
    assert "team_greedy[claim_radius_m=1]" in capsys.readouterr().out
    assert main([*argv, "--policy", "greedy[claim_radius_m=x]"]) != 0
    assert "claim_radius_m: expected a number, got 'x'" in capsys.readouterr().err


def test_a_worlds_own_time_limit_reaches_the_env(tmp_path: Path) -> None:
    # A suite's limit above the env's default (1,200 s) must not be cut at the default: the
    # env's own limit is set to each world's, and the user's --env-set still wins.
    from semexplore_gym.evaluation.team_benchmark import TeamBenchmarkConfig, team_tasks

    config = TeamBenchmarkConfig(
        worlds=("maze1", "maze2"),
        policies=("independent",),
        robot_counts=(2,),
        seeds=(0,),
        out=tmp_path,
        time_limits={"maze1": 4000.0},
        env_overrides=("episode.max_time_s=50",),
    )
    by_world = {t.world: t for t in team_tasks(config)}
    assert by_world["maze1"].max_time_s == 4000.0
    maze1 = by_world["maze1"].overrides
    assert "episode.max_time_s=4000.0" in maze1
    assert maze1[-1] == "episode.max_time_s=50"  # the user's override comes last: it wins
    assert by_world["maze2"].max_time_s is None
    assert not any(o.startswith("episode.max_time_s=") for o in by_world["maze2"].overrides[:-1])
