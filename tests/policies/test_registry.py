"""``make_policy`` specs, in particular ``py:`` for a user's own policy."""

from __future__ import annotations

import json
import textwrap

import numpy as np
import pytest
from semexplore_gym.policies.base import Policy
from semexplore_gym.policies.registry import make_policy

USER_POLICY = textwrap.dedent(
    """
    import numpy as np
    from semexplore_gym.policies.base import Policy, StepStats

    class Spinner(Policy):
        name = "spinner"

        def __init__(self, turn: float = 0.5) -> None:
            super().__init__()
            self.turn = turn

        def act(self, obs, info):
            self.last_stats = StepStats()
            return np.array([0.0, self.turn], dtype=np.float32)

    def make_spinner(turn: float = 0.25):
        return Spinner(turn=turn)

    NOT_CALLABLE = 3

    def not_a_policy():
        return "hello"
    """
)


@pytest.fixture
def user_file(tmp_path):
    path = tmp_path / "my_planner.py"
    path.write_text(USER_POLICY)
    return path


def test_py_spec_loads_a_class_from_a_file_with_overrides(user_file) -> None:
    p = make_policy(f"py:{user_file}:Spinner", turn=-0.75)
    assert isinstance(p, Policy) and p.name == "spinner"
    p.reset({}, {})
    assert p.act({}, {}).tolist() == [0.0, -0.75]
    # the file is imported once per process: a second policy shares the class
    q = make_policy(f"py:{user_file}:Spinner")
    assert type(q) is type(p) and q.turn == 0.5


def test_py_spec_loads_a_factory_from_a_module(user_file, monkeypatch) -> None:
    monkeypatch.syspath_prepend(str(user_file.parent))
    p = make_policy("py:my_planner:make_spinner[mine]")
    p.reset({}, {})
    assert p.act({}, {}).tolist() == [0.0, 0.25]


@pytest.mark.parametrize(
    ("spec", "fragment"),
    [
        ("py:{file}", "must name a module or .py file and an object"),
        ("py:{dir}/missing.py:Spinner", "no such file"),
        ("py:{file}:Nope", "has no attribute 'Nope'"),
        ("py:{file}:NOT_CALLABLE", "not a class or function"),
        ("py:{file}:not_a_policy", "returned a str, not a semexplore_gym.policies.base.Policy"),
        ("py:no_such_module_xyz:Spinner", "cannot import module 'no_such_module_xyz'"),
    ],
)
def test_py_spec_errors_name_the_problem(user_file, spec, fragment) -> None:
    spec = spec.format(file=user_file, dir=user_file.parent)
    with pytest.raises((ValueError, FileNotFoundError), match=fragment):
        make_policy(spec)


def test_unknown_policy_mentions_py_specs() -> None:
    with pytest.raises(ValueError, match="py:module:Class"):
        make_policy("semantik")


def test_benchmark_runs_a_user_policy_next_to_a_builtin(user_file, tmp_path, capsys) -> None:
    from semexplore_gym.cli import main
    from semexplore_gym.evaluation.harness import read_runs

    out = tmp_path / "bench"
    spec = f"py:{user_file}:Spinner[spin]"
    argv = ["benchmark", "--worlds", "maze:size_m=3", "--policies", f"random,{spec}"]
    argv += ["--runs", "1", "--max-time-s", "4", "--out", str(out), "--no-progress", "--no-plots"]
    assert main([*argv, "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["failed"] == 0
    rows = {r["policy"]: r for r in read_runs(out / "runs.csv")}
    assert set(rows) == {"random", spec}
    # spinning on the spot: no distance travelled, unlike the random policy
    assert rows[spec]["path_length_m"] < 0.05 < rows["random"]["path_length_m"]
    assert np.isfinite(rows[spec]["coverage"])


def test_benchmark_rejects_a_broken_user_policy_before_running(user_file, tmp_path, capsys):
    from semexplore_gym.cli import main

    out = tmp_path / "bench"
    argv = ["benchmark", "--worlds", "maze1", "--policies", f"py:{user_file}:Nope"]
    assert main([*argv, "--runs", "1", "--out", str(out), "--no-progress"]) == 2
    assert "--policies" in capsys.readouterr().err
    assert not (out / "runs.csv").exists()
