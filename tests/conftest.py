"""Shared test helpers."""

from __future__ import annotations

from collections.abc import Callable, Iterator

import pytest


@pytest.fixture(scope="session")
def tiny_macro_train_args() -> Callable[[float], list[str]]:
    """``semexplore train`` overrides for a few-step macro-env training on a 4 m maze.

    Call it with the decision length in simulated seconds (``max_macro_time_s`` and
    ``decision_period_s``).
    """

    def args(decision_s: float) -> list[str]:
        return [
            "--train-set", "env.world=maze:seed=0,size_m=4",
            "--train-set", "env.overrides=[episode.max_time_s=30]",
            "--train-set", "ppo.total_timesteps=8",
            "--train-set", "ppo.n_steps=4",
            "--train-set", "ppo.batch_size=4",
            "--train-set", "ppo.n_epochs=1",
            "--train-set", f"env.macro.max_macro_time_s={decision_s:g}",
            "--train-set", f"env.macro.decision_period_s={decision_s:g}",
            "--no-progress",
        ]  # fmt: skip

    return args


@pytest.fixture(scope="module")
def one_torch_thread() -> Iterator[None]:
    """Torch on one thread for the module: small nets on a shared 2-core machine train several
    times faster than with threads competing (restored afterwards; no-op without torch)."""
    try:
        import torch
    except ImportError:
        yield
        return
    n = torch.get_num_threads()
    torch.set_num_threads(1)
    yield
    torch.set_num_threads(n)
