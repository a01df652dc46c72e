"""The benchmark's progress bar over missions (tqdm on stderr), or nothing."""

from __future__ import annotations

import sys
from typing import Any


class MissionsBar:
    """Counts finished missions of ``total`` (``done`` already in the output); off when
    ``enabled`` is False, so callers never test for it."""

    def __init__(self, enabled: bool, total: int, done: int) -> None:
        self._bar: Any = None
        if enabled:
            from tqdm import tqdm

            self._bar = tqdm(
                total=total,
                initial=done,
                desc="missions",
                unit="mission",
                file=sys.stderr,
                dynamic_ncols=True,
            )

    def finished(self, task: Any) -> None:
        """One more mission ended (ran or failed): a task with ``world``, ``policy`` and
        ``seed`` (the team benchmark's adds ``n_robots``)."""
        if self._bar is not None:
            self._bar.update(1)
            robots = f" n={task.n_robots}" if hasattr(task, "n_robots") else ""
            self._bar.set_postfix_str(
                f"{task.world} {task.policy}{robots} seed={task.seed}", refresh=False
            )

    def close(self) -> None:
        if self._bar is not None:
            self._bar.close()
