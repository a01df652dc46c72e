"""The benchmark harness: incremental CSV, resume, pairing, summary and plots."""

from __future__ import annotations

import csv

import numpy as np
import pytest

from semexplore_gym.evaluation.harness import (
    CSV_COLUMNS,
    Task,
    expand_tasks,
    read_runs,
    run_benchmark,
)
from semexplore_gym.evaluation.report import write_plots, write_summary


def _fake(task: Task) -> dict:
    """A deterministic stand-in mission: 'semantic' is faster than the others."""
    rng = np.random.default_rng(task.seed)
    base = 100.0 if task.policy == "semantic" else 160.0
    t_end = base + rng.uniform(0, 20)
    t = np.linspace(0, t_end, 50)
    cov = np.minimum(1.0, t / t_end)
    row = {
        "world": task.world,
        "policy": task.policy,
        "seed": task.seed,
        "mission_time_s": t_end,
        "coverage": 0.99,
        "self_stopped": True,
        "stop_reason": "no frontier left",
        "path_length_m": t_end * 0.2,
        "collisions": 0,
        "T90_s": 0.9 * t_end,
        "T99_s": None,
        "mean_map_generation_ms": 2.0 if task.policy == "semantic" else 5.0,
        "mean_global_planning_ms": 1.0,
        "wall_time_s": 0.1,
        "explored_area_m2": 40.0,
        "steps": 500,
    }
    traj = np.stack([np.linspace(0.5, 3, 20), np.linspace(0.5, 3, 20), np.zeros(20)], axis=1)
    return {"row": row, "trace": np.stack([t, cov, 40 * cov], axis=1), "trajectory": traj}


def test_expand_tasks_is_paired_and_validated() -> None:
    tasks = expand_tasks(["maze1", "maze2"], ["semantic", "frontier"], [0, 1])
    assert len(tasks) == 8
    for s in (0, 1):
        assert {t.policy for t in tasks if t.seed == s and t.world == "maze1"} == {
            "semantic",
            "frontier",
        }
    assert Task("maze:seed=*,size_m=5", "semantic", 7).resolved_world == "maze:seed=7,size_m=5"
    with pytest.raises(ValueError, match="runs"):
        expand_tasks(["maze1"], ["semantic"], [])


def test_incremental_writes_and_resume(tmp_path) -> None:
    tasks = expand_tasks(["maze1", "maze2"], ["semantic", "frontier"], [0, 1, 2])
    calls = []

    def flaky(task: Task) -> dict:
        calls.append(task.key)
        if len(calls) == 5:
            raise RuntimeError("simulated crash")
        return _fake(task)

    res = run_benchmark(tasks, tmp_path, progress=False, task_fn=flaky)
    assert res["ran"] == 11 and len(res["failed"]) == 1
    rows = read_runs(tmp_path / "runs.csv")
    assert len(rows) == 11
    with open(tmp_path / "runs.csv") as f:
        assert tuple(next(csv.reader(f))) == CSV_COLUMNS
    # Resume: only the failed mission runs again.
    calls.clear()
    res2 = run_benchmark(tasks, tmp_path, progress=False, task_fn=_fake)
    assert res2 == {"ran": 1, "skipped": 11, "failed": []}
    assert len(read_runs(tmp_path / "runs.csv")) == 12
    for r in read_runs(tmp_path / "runs.csv"):
        stem = f"{r['world']}__{r['policy']}__{r['seed']}"
        assert (tmp_path / "traces" / f"{stem}.csv").exists()
        assert (tmp_path / "trajectories" / f"{stem}.npy").exists()


def test_summary_compares_reference_with_each_baseline(tmp_path) -> None:
    tasks = expand_tasks(["maze1"], ["semantic", "frontier"], list(range(6)))
    run_benchmark(tasks, tmp_path, progress=False, task_fn=_fake)
    text = write_summary(tmp_path).read_text()
    assert "## maze1" in text and "| semantic | 6 | 6/6 |" in text
    line = next(ln for ln in text.splitlines() if ln.startswith("| frontier | mission time |"))
    ratio, paired, p, p_w, wins = (c.strip() for c in line.strip("|").split("|")[2:7])
    assert float(ratio) < 0.75  # ~110 s vs ~170 s
    assert float(paired) < 0.75
    assert float(p) < 0.01
    assert float(p_w) < 0.05  # six pairs, all the same way: the smallest two-sided p is 1/32
    assert wins == "6/6"


def test_plots_are_written(tmp_path) -> None:
    run_benchmark(
        expand_tasks(["maze1", "maze2"], ["semantic", "frontier"], [0, 1]),
        tmp_path,
        progress=False,
        task_fn=_fake,
    )
    paths = write_plots(tmp_path)
    names = {p.name for p in paths}
    assert names == {
        "explored_area.png",
        "mission_time.png",
        "map_generation_time.png",
        "global_planning_time.png",
        "trajectories.png",
    }
    for p in paths:
        assert p.stat().st_size > 5000


def test_csv_with_other_columns_is_refused(tmp_path) -> None:
    (tmp_path / "runs.csv").write_text("a,b\n1,2\n")
    with pytest.raises(ValueError, match="columns"):
        run_benchmark(
            expand_tasks(["maze1"], ["semantic"], [0]), tmp_path, progress=False, task_fn=_fake
        )


def test_a_run_of_an_older_version_resumes_its_new_optional_columns_left_empty(tmp_path) -> None:
    import csv

    from semexplore_gym.evaluation.run_row import CSV_COLUMNS, OPTIONAL_COLUMNS

    tasks = expand_tasks(["maze1"], ["semantic", "frontier"], [0])
    run_benchmark(tasks[:1], tmp_path, progress=False, task_fn=_fake)
    # Rewrite runs.csv as an older version wrote it: without the optional columns.
    path = tmp_path / "runs.csv"
    rows = list(csv.DictReader(path.open(newline="")))
    old = [c for c in CSV_COLUMNS if c not in OPTIONAL_COLUMNS]
    with path.open("w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=old, extrasaction="ignore")
        w.writeheader()
        w.writerows(rows)
    ran = []

    def counting(task):
        ran.append(task)
        return _fake(task)

    run_benchmark(tasks, tmp_path, progress=False, task_fn=counting)
    assert len(ran) == 1  # the old row was kept, only the new mission ran
    header, *body = list(csv.reader(path.open(newline="")))
    assert tuple(header) == CSV_COLUMNS and len(body) == 2
    assert body[0][header.index("mission_time_s")] == rows[0]["mission_time_s"]


def test_summary_with_one_pair_prints_no_p_value(tmp_path) -> None:
    tasks = expand_tasks(["maze1"], ["semantic", "frontier"], [0])
    run_benchmark(tasks, tmp_path, progress=False, task_fn=_fake)
    text = write_summary(tmp_path).read_text()
    line = next(ln for ln in text.splitlines() if ln.startswith("| frontier | mission time |"))
    p = line.strip("|").split("|")[4].strip()
    assert p == "– (1 pair)"
    assert "nan" not in text


def test_errors_name_parameters_and_the_cli_names_flags(tmp_path) -> None:
    from semexplore_gym.evaluation.errors import ParameterError
    from semexplore_gym.evaluation.harness import parse_seeds

    with pytest.raises(ParameterError, match="^runs must be >= 1, got 0") as info:
        parse_seeds(0)
    assert info.value.param == "runs"
    assert str(info.value.for_flags({"runs": "--runs"})) == "--runs must be >= 1, got 0"
    with pytest.raises(ParameterError, match="^policies lists 'a' twice") as info:
        expand_tasks(["w"], ["a", "a"], [0])
    assert info.value.named("--policies").startswith("--policies lists 'a' twice")
    (tmp_path / "runs.csv").write_text("a,b\n1,2\n")
    with pytest.raises(ParameterError, match=r"new output directory \(out_dir\)"):
        run_benchmark(expand_tasks(["w"], ["p"], [0]), tmp_path, progress=False, task_fn=_fake)
