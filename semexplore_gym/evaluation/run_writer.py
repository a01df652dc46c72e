"""The benchmark's output directory: ``runs.csv`` appended row by row, traces, trajectories and
the manifest ``benchmark.json``; and the distance a mission drove until a coverage level, read
back from its trace and trajectory (:func:`distance_to_coverage_m`)."""

from __future__ import annotations

import csv
import json
import math
import os
import re
import time
from pathlib import Path
from typing import Any

import numpy as np

from semexplore_gym.core.validation import short_repr
from semexplore_gym.evaluation.errors import PARAM, ParameterError
from semexplore_gym.evaluation.run_row import (
    CSV_COLUMNS,
    OPTIONAL_COLUMNS,
    RunRow,
    complete_csv_bytes,
)


def file_slug(text: str) -> str:
    """``text`` made safe as part of a file name (at most 120 characters)."""
    return re.sub(r"[^A-Za-z0-9._=-]+", "_", text).strip("_")[:120] or "x"


def task_stem(world: str, policy: str, seed: int) -> str:
    """The file name (without suffix) of one mission's trace and trajectory."""
    return f"{file_slug(world)}__{file_slug(policy)}__{seed}"


class ResultWriter:
    """Appends finished missions to ``runs.csv`` (flushed per row) and their traces.

    A ``runs.csv`` written by an older version that only lacks optional columns (added since)
    is upgraded in place, those cells left empty, so an old run resumes.

    Raises:
        ParameterError: ``out_dir`` holds a ``runs.csv`` with other columns.
    """

    def __init__(self, out_dir: str | os.PathLike) -> None:
        self.out = Path(out_dir)
        (self.out / "traces").mkdir(parents=True, exist_ok=True)
        (self.out / "trajectories").mkdir(parents=True, exist_ok=True)
        self.csv_path = self.out / "runs.csv"
        if self.csv_path.exists():
            # Drop a row torn by a kill mid-write, so that mission runs again.
            keep = complete_csv_bytes(self.csv_path)
            if keep < self.csv_path.stat().st_size:
                with self.csv_path.open("r+b") as f:
                    f.truncate(keep)
        new = not self.csv_path.exists() or self.csv_path.stat().st_size == 0
        if not new:
            with self.csv_path.open(newline="") as f:
                header = next(csv.reader(f), [])
            if _older_header(header):
                _add_columns(self.csv_path)
            elif tuple(header) != CSV_COLUMNS:
                raise ParameterError(
                    "out_dir",
                    f"{self.csv_path} has columns {short_repr(header)}, expected "
                    f"{list(CSV_COLUMNS)}; use a new output directory ({PARAM})",
                )
        self._f = self.csv_path.open("a", newline="")
        self._w = csv.DictWriter(self._f, fieldnames=list(CSV_COLUMNS))
        if new:
            self._w.writeheader()
            self._f.flush()

    def write(self, record: dict[str, Any]) -> None:
        """Write one mission: ``{"row": RunRow or column dict, "trace", "trajectory"}``."""
        row = record["row"]
        if isinstance(row, RunRow):
            row = row.to_dict()
        stem = task_stem(row["world"], row["policy"], int(row["seed"]))
        # Trace and trajectory first: a row in runs.csv promises they exist.
        trace_path = self.out / "traces" / f"{stem}.csv"
        np.savetxt(
            trace_path,
            record["trace"],
            delimiter=",",
            header="sim_time_s,coverage,explored_area_m2",
            comments="",
            fmt="%.6g",
        )
        np.save(self.out / "trajectories" / f"{stem}.npy", record["trajectory"])
        self._w.writerow({k: ("" if row.get(k) is None else row[k]) for k in CSV_COLUMNS})
        self._f.flush()
        os.fsync(self._f.fileno())

    def close(self) -> None:
        self._f.close()


def write_manifest(out_dir: str | os.PathLike, manifest: dict[str, Any]) -> None:
    """``benchmark.json``: the resolved command, stamped with the time it was written."""
    p = Path(out_dir) / "benchmark.json"
    manifest = dict(manifest, written_at=time.strftime("%Y-%m-%dT%H:%M:%S"))
    p.write_text(json.dumps(manifest, indent=2, default=str))


def _older_header(header: list[str]) -> bool:
    """Whether ``header`` is :data:`CSV_COLUMNS` without some columns added since (a run begun
    by an older version, which resuming brings up to date)."""
    return (
        len(header) < len(CSV_COLUMNS)
        and set(CSV_COLUMNS) - set(header) <= OPTIONAL_COLUMNS
        and header == [c for c in CSV_COLUMNS if c in header]
    )


def _add_columns(path: Path) -> None:
    """Rewrite ``path`` with every column of :data:`CSV_COLUMNS` (new ones empty)."""
    with path.open(newline="") as f:
        rows = list(csv.DictReader(f))
    tmp = path.with_name(path.name + ".tmp")
    with tmp.open("w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(CSV_COLUMNS), restval="")
        w.writeheader()
        w.writerows(rows)
    os.replace(tmp, path)


def distance_to_coverage_m(out_dir: Any, row: dict[str, Any], level: float = 0.99) -> float | None:
    """Distance the robot of ``row`` drove until its coverage first reached ``level`` (inf:
    never; None: its trace or trajectory is missing)."""
    stem = task_stem(row["world"], row["policy"], int(row["seed"]))
    out = Path(out_dir)
    try:
        trace = np.loadtxt(out / "traces" / f"{stem}.csv", delimiter=",", skiprows=1, ndmin=2)
        poses = np.load(out / "trajectories" / f"{stem}.npy")
    except (OSError, ValueError):
        return None
    n = min(len(trace), len(poses))
    hit = np.flatnonzero(trace[:n, 1] >= level)
    if hit.size == 0:
        return math.inf
    steps = np.hypot(*np.diff(poses[: int(hit[0]) + 1, :2], axis=0).T)
    return float(steps.sum())
