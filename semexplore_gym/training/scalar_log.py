"""Training scalars to TensorBoard when it is installed, else to a CSV file."""

from __future__ import annotations

import csv
from pathlib import Path
from typing import Any


class ScalarLogger:
    """Scalars to TensorBoard when installed, else to ``scalars.csv``; always to ``metrics``."""

    def __init__(self, log_dir: Path) -> None:
        log_dir.mkdir(parents=True, exist_ok=True)
        self._writer: Any = None
        self._csv: Any = None
        try:
            from torch.utils.tensorboard import SummaryWriter

            self._writer = SummaryWriter(str(log_dir))
        except ImportError:
            f = open(log_dir / "scalars.csv", "w", newline="")  # noqa: SIM115 (closed in close())
            self._csv = (f, csv.writer(f))
            self._csv[1].writerow(["tag", "step", "value"])

    def __call__(self, tag: str, value: float, step: int) -> None:
        if self._writer is not None:
            self._writer.add_scalar(tag, value, step)
        else:
            self._csv[1].writerow([tag, step, value])

    def close(self) -> None:
        if self._writer is not None:
            self._writer.close()
        if self._csv is not None:
            self._csv[0].close()
