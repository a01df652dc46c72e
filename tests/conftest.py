"""Shared test helpers."""

from __future__ import annotations

import os
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest

#: ``SEMEXPLORE_TEST_HIDE_SHARED=1`` runs the tests as on a clean clone, without ``../shared``
#: beside the repository: tests marked ``shared_maps`` skip, and ``tests/test_readme.py`` skips
#: the commands that need the real maps (``.ci/run`` runs it so once more).
HIDE_SHARED_ENV = "SEMEXPLORE_TEST_HIDE_SHARED"
SHARED = Path(__file__).resolve().parents[1].parent / "shared"


def shared_hidden() -> bool:
    """Whether ``../shared`` is hidden from the tests (see :data:`HIDE_SHARED_ENV`)."""
    return os.environ.get(HIDE_SHARED_ENV) == "1"


@pytest.fixture(scope="session")
def shared_dir() -> Path | None:
    """``../shared`` beside the repository, or None when it is absent or hidden."""
    return None if shared_hidden() or not SHARED.is_dir() else SHARED


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    if not shared_hidden():
        return
    skip = pytest.mark.skip(reason=f"../shared hidden ({HIDE_SHARED_ENV}=1)")
    for item in items:
        if item.get_closest_marker("shared_maps") is not None:
            item.add_marker(skip)


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
