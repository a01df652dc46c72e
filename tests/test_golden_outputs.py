"""Pinned outputs: refactors and speed-ups must leave these bit-identical.

Each case digests what a user would compare between two versions: a mission's trajectory,
coverage trace and row (the benchmark harness's ``run_task``), env steps under random actions
(scans, maps, poses, rewards), and the semantic topometric map of a mission's final map.
Digests are sha256 over the exact float bytes, so any change in the last bit shows.

A change that is *meant* to alter behaviour regenerates the pins in the same commit, saying why:
``SEMEXPLORE_REGENERATE_GOLDEN=1 pytest tests/test_golden_outputs.py``.
"""

from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np
import pytest

import semexplore_gym  # noqa: F401  (registers the env)
from semexplore_gym.core.topometric import segment_map
from semexplore_gym.evaluation.harness import Task, run_task
from semexplore_gym.evaluation.path_decomposition import DECOMPOSITION_COLUMNS
from semexplore_gym.evaluation.run_row import SLAM_COLUMNS

GOLDEN = Path(__file__).with_name("golden_outputs.json")
REGENERATE = os.environ.get("SEMEXPLORE_REGENERATE_GOLDEN") == "1"

#: Wall-clock fields differ from run to run; everything else in a row is pinned.
_TIMED = {"mean_map_generation_ms", "mean_global_planning_ms", "wall_time_s"}
#: Columns added after the pins were taken: missions are pinned by the rest (the same trace,
#: trajectory and figures mean the same missions); coverage at the planner's clearance
#: (tests/evaluation/test_planner_coverage.py), the decomposition and the expert's version
#: (tests/policies/test_expert_versions.py) and the SLAM columns (empty without the SLAM mode;
#: tests/evaluation/test_slam_benchmark.py) have their own tests.
_ADDED_AFTER_PINS = {
    "coverage_at_planner_clearance",
    *DECOMPOSITION_COLUMNS,
    "policy_version",
    *SLAM_COLUMNS,
}

MISSIONS = [
    ("maze1", "semantic", 0, None),
    ("maze2", "semantic", 1, None),
    ("office:seed=1,size_m=12", "semantic", 0, None),
    ("cave:seed=1", "semantic", 0, None),
    # The paper's method alone: changes to the robust expert must leave it as it is.
    ("maze1", "semantic-paper", 0, 400.0),
    ("cave:seed=1", "semantic-paper", 0, 400.0),
    ("maze1", "frontier", 0, 120.0),
    ("maze2", "nearest", 0, 120.0),
]

STEP_WORLDS = ["maze1", "cave:seed=2", "office:seed=1,size_m=12"]


def _feed(h: Any, obj: Any) -> None:
    """Hash ``obj`` exactly: arrays by dtype, shape and bytes; floats by their bits."""
    if isinstance(obj, np.ndarray):
        h.update(f"nd{obj.dtype.str}{obj.shape}".encode())
        h.update(np.ascontiguousarray(obj).tobytes())
    elif isinstance(obj, float | np.floating):
        h.update(b"f" + np.float64(obj).tobytes())
    elif isinstance(obj, bool | int | np.integer | str | None):
        h.update(f"{type(obj).__name__}:{obj!r};".encode())
    elif isinstance(obj, dict):
        h.update(b"{")
        for k in sorted(obj, key=repr):
            _feed(h, k)
            _feed(h, obj[k])
        h.update(b"}")
    elif isinstance(obj, list | tuple):
        h.update(f"[{len(obj)}".encode())
        for v in obj:
            _feed(h, v)
        h.update(b"]")
    elif hasattr(obj, "value") and hasattr(obj, "name"):  # enums
        _feed(h, obj.name)
    elif hasattr(obj, "__dict__"):
        _feed(h, {k: v for k, v in vars(obj).items() if k != "time_ms"})
    else:
        raise TypeError(f"cannot digest {type(obj).__name__}")


def digest(obj: Any) -> str:
    h = hashlib.sha256()
    _feed(h, obj)
    return h.hexdigest()[:24]


def _topometric_digest(tmap: Any) -> str:
    return digest(
        {
            "area_ids": tmap.area_ids,
            "areas": {k: tuple(a) for k, a in tmap.areas.items()},
            "openings": [tuple(o) for o in tmap.openings],
            "frontiers": [tuple(f) for f in tmap.frontiers],
            "edges": [tuple(e) for e in tmap.edges],
            "L_path": tmap.mean_intersection_path_m,
            "clearance": tmap.clearance_m,
        }
    )


def mission_case(world: str, policy: str, seed: int, max_time_s: float | None) -> dict[str, str]:
    rec = run_task(Task(world, policy, seed, max_time_s))
    row = {k: v for k, v in rec["row"].items() if k not in _TIMED | _ADDED_AFTER_PINS}
    return {
        "row": digest(row),
        "trace": digest(rec["trace"]),
        "trajectory": digest(rec["trajectory"]),
        "summary": f"cov={row['coverage']:.4f} t={row['mission_time_s']:.1f} {row['stop_reason']}",
    }


def steps_case(world: str) -> dict[str, str]:
    env = gym.make("SemanticExplore-v0", world=world)
    rng = np.random.default_rng(7)
    try:
        obs, info = env.reset(seed=3)
        scans, poses, rewards, maps = [obs["scan"]], [obs["pose"]], [], []
        for i in range(300):
            obs, r, term, trunc, info = env.step(rng.uniform(-1, 1, 2).astype(np.float32))
            scans.append(obs["scan"])
            poses.append(obs["pose"])
            rewards.append(r)
            if i % 50 == 49:
                maps.append(obs["map"])
        final_map = obs["map"]
        geometry = env.unwrapped.map_geometry
        tmap = segment_map(final_map, geometry, 0.155)
        return {
            "scans": digest(np.stack(scans)),
            "poses": digest(np.stack(poses)),
            "rewards": digest(np.asarray(rewards, dtype=np.float64)),
            "maps": digest(maps),
            "collisions": str(info["collisions"]),
            "segmentation": _topometric_digest(tmap),
        }
    finally:
        env.close()


def _compute() -> dict[str, dict[str, str]]:
    out: dict[str, dict[str, str]] = {}
    for world, policy, seed, max_time_s in MISSIONS:
        out[f"mission|{world}|{policy}|{seed}"] = mission_case(world, policy, seed, max_time_s)
    for world in STEP_WORLDS:
        out[f"steps|{world}"] = steps_case(world)
    return out


@pytest.fixture(scope="module")
def golden() -> dict[str, dict[str, str]]:
    if REGENERATE:
        GOLDEN.write_text(json.dumps(_compute(), indent=1, sort_keys=True) + "\n")
    return json.loads(GOLDEN.read_text())


@pytest.mark.slow
@pytest.mark.parametrize("case", MISSIONS, ids=lambda c: f"{c[1]}-{c[0]}-{c[2]}")
def test_mission_outputs_are_pinned(case: tuple, golden: dict) -> None:
    world, policy, seed, max_time_s = case
    assert (
        mission_case(world, policy, seed, max_time_s) == golden[f"mission|{world}|{policy}|{seed}"]
    )


@pytest.mark.parametrize("world", STEP_WORLDS)
def test_env_steps_and_segmentation_are_pinned(world: str, golden: dict) -> None:
    assert steps_case(world) == golden[f"steps|{world}"]


def test_digest_sees_the_last_bit() -> None:
    a = np.array([1.0, 2.0])
    b = a.copy()
    b[1] = np.nextafter(b[1], 3.0)
    assert digest(a) != digest(b)
    assert digest({"x": 1}) != digest({"x": 1.0})
