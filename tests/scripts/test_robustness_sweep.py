"""scripts/robustness_sweep.py through its command line, with a tiny budget."""

from __future__ import annotations

import csv
import runpy
from pathlib import Path

import numpy as np
import pytest

SCRIPT = Path(__file__).resolve().parents[2] / "scripts" / "robustness_sweep.py"


def test_sweep_writes_runs_and_a_per_family_summary(tmp_path: Path) -> None:
    main = runpy.run_path(str(SCRIPT), run_name="sweep")["main"]
    out = tmp_path / "sweep"
    argv = [
        "--families",
        "maze,forest",
        "--per-family",
        "1",
        "--max-time-s",
        "20",
        "--out",
        str(out),
    ]
    assert main([*argv, "--gifs"]) == 0
    rows = list(csv.DictReader((out / "runs.csv").open()))
    assert sorted(r["world"].split(":")[0] for r in rows) == ["forest", "maze"]
    assert all(float(r["mission_time_s"]) <= 20.0 + 1e-9 for r in rows)
    summary = (out / "sweep.md").read_text()
    assert "| maze | semantic | 1 |" in summary and "| forest | semantic | 1 |" in summary
    assert "Failures (2)" in summary  # 20 s is too short to finish: each listed with its reason
    assert len(list((out / "failures").glob("*.gif"))) == 2  # and animated
    assert main(argv) == 0  # a rerun resumes: nothing is run twice
    assert len(list(csv.DictReader((out / "runs.csv").open()))) == 2


def test_unknown_family_is_a_clear_error(tmp_path: Path) -> None:
    main = runpy.run_path(str(SCRIPT), run_name="sweep")["main"]
    with pytest.raises(SystemExit) as e:
        main(["--families", "castle", "--out", str(tmp_path / "x")])
    assert e.value.code == 2


def test_every_family_variant_builds_a_world_and_value_noise_caves_are_swept() -> None:
    from semexplore_gym.maps.world_specs import make_world

    ns = runpy.run_path(str(SCRIPT), run_name="sweep")
    families = ns["FAMILIES"]
    assert "noisecave" in families  # the value-noise caves are part of the default sweep
    per_family = max(len(v) for v in families.values())
    worlds = ns["sweep_worlds"](list(families), per_family, 0)
    assert len(worlds) == per_family * len(families)
    thresholds = set()
    for spelling in worlds:
        world = make_world(spelling, np.random.default_rng(0))
        free_m2 = world.free_mask.sum() * world.free_geometry.resolution_m**2
        assert free_m2 > 1.0, spelling
        if spelling.startswith("noisecave:"):
            thresholds.add(spelling.split("threshold=")[1])
    assert len(thresholds) >= 3  # several thresholds, narrow to wide passages
