"""Benchmark bookkeeping (issue #18, item 5): duplicates, torn rows, run fingerprint, workers
that die with the parent."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from semexplore_gym.cli import main
from semexplore_gym.evaluation.harness import (
    CSV_COLUMNS,
    expand_tasks,
    read_runs,
    run_benchmark,
)

REPO = Path(__file__).resolve().parents[2]


def fake_task(task):
    import numpy as np

    row = dict.fromkeys(CSV_COLUMNS, 1.0)
    row.update(world=task.world, policy=task.policy, seed=task.seed, self_stopped=True)
    row.update(slam_lost=False, slam_false_stop=False, slam_stop_artefact="")  # as self_stopped
    row.update(stop_reason="done", collisions=0, steps=3, T90_s=None, scored_replans=2)
    row["mission_time_s"] = task.max_time_s or 5.0
    return {"row": row, "trace": np.zeros((2, 3)), "trajectory": np.zeros((2, 3))}


@pytest.mark.parametrize(
    "flag,value", [("--policies", "random,random"), ("--worlds", "maze1,maze1")]
)
def test_duplicate_specs_are_refused(tmp_path, capsys, flag, value) -> None:
    argv = ["benchmark", "--worlds", "maze1", "--policies", "random", "--out", str(tmp_path / "b")]
    argv[argv.index(flag) + 1] = value
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert "twice" in err and value.split(",")[0] in err
    with pytest.raises(ValueError, match="twice"):
        expand_tasks(["maze1"], ["random", "random"], [0])


def test_torn_last_row_is_rerun_not_counted(tmp_path) -> None:
    tasks = expand_tasks(["w"], ["p"], [0, 1, 2], max_time_s=5.0)
    run_benchmark(tasks, tmp_path, progress=False, task_fn=fake_task)
    csv_path = tmp_path / "runs.csv"
    data = csv_path.read_bytes()
    # Kill mid-write: the last row loses its end (and its newline).
    csv_path.write_bytes(data[: data.rstrip(b"\r\n").rfind(b",") - 3])
    rows = read_runs(csv_path)
    assert [r["seed"] for r in rows] == [0, 1]
    res = run_benchmark(tasks, tmp_path, progress=False, task_fn=fake_task)
    assert res["ran"] == 1 and res["skipped"] == 2
    rows = read_runs(csv_path)
    assert sorted(r["seed"] for r in rows) == [0, 1, 2]
    assert all(r["mission_time_s"] == 5.0 for r in rows)


def test_broken_middle_row_is_named(tmp_path) -> None:
    tasks = expand_tasks(["w"], ["p"], [0, 1], max_time_s=5.0)
    run_benchmark(tasks, tmp_path, progress=False, task_fn=fake_task)
    csv_path = tmp_path / "runs.csv"
    lines = csv_path.read_text().splitlines(keepends=True)
    lines[1] = lines[1].replace("5.0", "abc", 1)
    csv_path.write_text("".join(lines))
    with pytest.raises(ValueError, match=r"line 2: mission_time_s is not a number: 'abc'"):
        read_runs(csv_path)


def test_changed_max_time_is_refused_on_resume(tmp_path) -> None:
    run_benchmark(
        expand_tasks(["w"], ["p"], [0, 1], max_time_s=5.0),
        tmp_path,
        progress=False,
        task_fn=fake_task,
    )
    with pytest.raises(ValueError, match=r"max_time_s: 5.0 -> 9.0.*new output directory"):
        run_benchmark(
            expand_tasks(["w"], ["p"], [0, 1, 2], max_time_s=9.0),
            tmp_path,
            progress=False,
            task_fn=fake_task,
        )
    # Nothing was mixed in; the same settings still resume.
    assert len(read_runs(tmp_path / "runs.csv")) == 2
    res = run_benchmark(
        expand_tasks(["w"], ["p"], [0, 1, 2], max_time_s=5.0),
        tmp_path,
        progress=False,
        task_fn=fake_task,
    )
    assert res == {"ran": 1, "skipped": 2, "failed": []}


def test_adding_policies_and_seeds_resumes_but_changed_overrides_do_not(tmp_path) -> None:
    run = lambda tasks: run_benchmark(tasks, tmp_path, progress=False, task_fn=fake_task)  # noqa: E731
    run(expand_tasks(["w"], ["a"], [0], max_time_s=5.0, policy_overrides={"x": 1}))
    res = run(expand_tasks(["w"], ["a"], [0, 1], max_time_s=5.0, policy_overrides={"x": 1}))
    assert res["ran"] == 1 and res["skipped"] == 1
    res = run(expand_tasks(["w"], ["b"], [0], max_time_s=5.0, policy_overrides={"x": 2}))
    assert res["ran"] == 1
    with pytest.raises(ValueError, match="overrides of a"):
        run(expand_tasks(["w"], ["a"], [0], max_time_s=5.0, policy_overrides={"x": 3}))


def test_changed_env_config_is_refused_through_the_cli(tmp_path, capsys, monkeypatch) -> None:
    import semexplore_gym.evaluation.harness as harness

    monkeypatch.setattr(harness, "run_task", fake_task)
    monkeypatch.setattr(
        harness.run_benchmark, "__defaults__", (1, "process", None, True, fake_task)
    )
    out = str(tmp_path / "b")
    base = [
        "benchmark",
        "--worlds",
        "maze1",
        "--policies",
        "random",
        "--runs",
        "1",
        "--out",
        out,
        "--no-progress",
        "--no-plots",
        "--max-time-s",
        "5",
    ]
    assert main(base) == 0
    capsys.readouterr()
    assert main([*base, "--env-set", "lidar.n_beams=90"]) == 2
    assert "different settings" in capsys.readouterr().err
    assert main([*base[:-1], "7"]) == 2
    assert "max_time_s: 5.0 -> 7.0" in capsys.readouterr().err


@pytest.mark.parametrize(
    "args,fragment",
    [
        (["--runs", "1000000000"], "--runs must be in"),
        (["--runs", "0"], "--runs must be in"),
        (["--workers", "0"], "--workers must be in"),
        (["--max-time-s", "nan"], "--max-time-s must be"),
        (["--max-time-s", "-1"], "--max-time-s must be"),
        (["--seed0", "-1"], "--seed0 must be"),
    ],
)
def test_bad_numbers_fail_at_once(tmp_path, capsys, args, fragment) -> None:
    argv = ["benchmark", "--worlds", "maze1", "--policies", "random", "--out", str(tmp_path / "b")]
    assert main([*argv, *args]) == 2
    assert fragment in capsys.readouterr().err


def test_out_naming_a_file_is_refused(tmp_path, capsys) -> None:
    f = tmp_path / "file"
    f.write_text("x")
    assert main(["benchmark", "--worlds", "maze1", "--policies", "random", "--out", str(f)]) == 2
    assert "existing file" in capsys.readouterr().err
    assert f.read_text() == "x"


def _spawned_children(pid: int) -> list[int]:
    out = []
    for d in Path("/proc").iterdir():
        if not d.name.isdigit():
            continue
        try:
            stat = (d / "stat").read_text()
            cmd = (d / "cmdline").read_bytes()
        except OSError:
            continue
        ppid = int(stat.rsplit(")", 1)[1].split()[1])
        if ppid == pid and b"spawn_main" in cmd:
            out.append(int(d.name))
    return out


def _alive(pid: int) -> bool:
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return False
    return stat.rsplit(")", 1)[1].split()[0] != "Z"


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
def test_killed_benchmark_leaves_no_worker_behind(tmp_path) -> None:
    code = "import sys; from semexplore_gym.cli import main; sys.exit(main())"
    argv = [
        sys.executable,
        "-c",
        code,
        "benchmark",
        "--worlds",
        "maze1",
        "--policies",
        "random",
        "--runs",
        "4",
        "--workers",
        "2",
        "--max-time-s",
        "100000",
        "--out",
        str(tmp_path / "b"),
        "--no-progress",
        "--no-plots",
    ]
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    proc = subprocess.Popen(argv, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    workers: list[int] = []
    try:
        deadline = time.monotonic() + 60
        while len(workers) < 2 and time.monotonic() < deadline and proc.poll() is None:
            time.sleep(0.2)
            workers = _spawned_children(proc.pid)
        assert len(workers) == 2, "the benchmark did not start its workers"
        time.sleep(3.0)  # let the workers import and start their missions
        proc.send_signal(signal.SIGKILL)
        proc.wait(timeout=10)
        deadline = time.monotonic() + 15
        while any(_alive(w) for w in workers) and time.monotonic() < deadline:
            time.sleep(0.2)
        assert not any(_alive(w) for w in workers), "a worker outlived the killed benchmark"
    finally:
        if proc.poll() is None:
            proc.kill()
        for w in workers:
            if _alive(w):
                os.kill(w, signal.SIGKILL)
