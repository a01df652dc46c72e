"""The numba warm-up before a mission: kernels loaded before the clocks start, a message only
when numba really compiles."""

from __future__ import annotations

import gc
import io

import gymnasium as gym
import numpy as np
from numba import njit
from numba.core.dispatcher import Dispatcher
from semexplore_gym.policies.base import Policy, StepStats
from semexplore_gym.policies.registry import make_policy

import semexplore_gym  # noqa: F401  (registers the env)
from semexplore_gym.evaluation.rollout import run_mission
from semexplore_gym.evaluation.warmup import COMPILE_MESSAGE, warm_up


def _kernel_calls() -> dict[int, int]:
    """Per project kernel: signatures loaded from the disk cache or compiled so far."""
    out = {}
    for d in gc.get_objects():
        if isinstance(d, Dispatcher) and d.py_func.__module__.startswith(
            ("semexplore_gym", "policies")
        ):
            out[id(d)] = sum(d._cache_hits.values()) + sum(d._cache_misses.values())
    return out


def test_after_warm_up_a_mission_loads_and_compiles_no_kernel() -> None:
    out = io.StringIO()
    # The warm-up's env as the mission's: a fresh map copy per step (gym.make's default).
    warm_up(lambda: make_policy("semantic"), stream=out, env_kwargs={})
    before = _kernel_calls()
    env = gym.make("SemanticExplore-v0", world="maze2")
    try:
        run_mission(env, make_policy("semantic"), seed=0, max_time_s=60, progress=False)
    finally:
        env.close()
    after = _kernel_calls()
    new = {k: v - before.get(k, 0) for k, v in after.items() if v != before.get(k, 0)}
    assert new == {}, "kernels loaded or compiled inside the mission's clocks"


class _FreshKernelPolicy(Policy):
    """A policy whose ``act`` calls a kernel numba has never compiled."""

    name = "fresh-kernel"

    def __init__(self) -> None:
        super().__init__()

        @njit
        def double(x):  # a new function object each time: always a compile
            return 2.0 * x

        self._double = double

    def act(self, obs, info):
        self.last_stats = StepStats()
        self.done = True
        return np.array([self._double(0.0), 0.0], dtype=np.float32)


def test_compile_message_only_when_numba_compiles() -> None:
    out = io.StringIO()
    res = warm_up(_FreshKernelPolicy, stream=out)
    assert res["compiled"] >= 1
    assert "numba kernels not yet cached" in out.getvalue()
    assert "first run only" not in out.getvalue()

    quiet = io.StringIO()
    res = warm_up(lambda: make_policy("random"), stream=quiet)
    assert res["compiled"] == 0
    assert quiet.getvalue() == ""


def test_warm_up_with_a_key_runs_once_per_process() -> None:
    calls = []

    def factory():
        calls.append(1)
        return make_policy("random")

    warm_up(factory, key=("test-key", 1), stream=io.StringIO())
    warm_up(factory, key=("test-key", 1), stream=io.StringIO())
    assert len(calls) == 1


def test_the_compile_notice_gets_a_line_of_its_own_above_a_bar() -> None:
    from tqdm import tqdm

    out = io.StringIO()
    bar = tqdm(total=10, file=out, desc="missions")  # drawn at 0 %, no newline after it
    try:
        warm_up(_FreshKernelPolicy, stream=out)
    finally:
        bar.close()
    text = out.getvalue()
    assert "missions:   0%" in text
    start = text.index("compiling")
    assert text[start - 1] in "\r\n", repr(text[max(0, start - 60) : start + 20])
    notice = text[start:].split("\n", 1)[0]
    assert notice.endswith("...") and "missions" not in notice


def test_uncached_kernels_are_counted(tmp_path, monkeypatch) -> None:
    import importlib
    import sys

    from semexplore_gym.evaluation.warmup import count_uncached_kernels

    (tmp_path / "semexplore_kernel_probe.py").write_text(
        "from numba import njit\n\n@njit(cache=True)\ndef twice(x):\n    return 2 * x\n"
    )
    monkeypatch.syspath_prepend(str(tmp_path))
    module = importlib.import_module("semexplore_kernel_probe")
    try:
        assert count_uncached_kernels(("semexplore_kernel_probe",)) == 1
        assert COMPILE_MESSAGE.format(n=1).startswith("compiling 1 numba kernels not yet cached")
        module.twice(1.0)  # compiled and written to the disk cache
        assert count_uncached_kernels(("semexplore_kernel_probe",)) == 0
    finally:
        sys.modules.pop("semexplore_kernel_probe", None)


def test_the_benchmark_compiles_before_its_bar_starts(tmp_path, monkeypatch) -> None:
    from semexplore_gym.evaluation import harness

    order: list[str] = []
    monkeypatch.setattr(harness, "warm_up_task", lambda task: order.append("warm up"))

    class _Bar:
        def __init__(self, *args, **kwargs) -> None:
            order.append("bar")

        def finished(self, task) -> None:
            pass

        def close(self) -> None:
            pass

    monkeypatch.setattr(harness, "MissionsBar", _Bar)
    tasks = harness.expand_tasks(["maze:seed=0,size_m=3"], ["random"], [0, 1], max_time_s=1.0)
    harness.run_benchmark(tasks, tmp_path / "out", progress=True)
    assert order[0] == "warm up" and order.index("bar") == len(tasks)
