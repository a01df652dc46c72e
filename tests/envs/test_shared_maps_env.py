"""Every map in ../shared/maps runs in the env (or, if far too large, fails with a clear hint)."""

from __future__ import annotations

from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest

import semexplore_gym  # noqa: F401
from semexplore_gym import FREE

SHARED_MAPS = Path(__file__).resolve().parents[2].parent / "shared" / "maps"


def _maps() -> list[Path]:
    if not SHARED_MAPS.is_dir():
        return []
    return sorted(list(SHARED_MAPS.rglob("*.yaml")) + list(SHARED_MAPS.rglob("*.json")))


@pytest.mark.shared_maps
@pytest.mark.skipif(not SHARED_MAPS.is_dir(), reason=f"shared maps not found at {SHARED_MAPS}")
@pytest.mark.parametrize("path", _maps(), ids=lambda p: str(p.relative_to(SHARED_MAPS)))
def test_env_runs_on_shared_map(path: Path) -> None:
    try:
        env = gym.make("SemanticExplore-v0", world=str(path))
    except ValueError as e:
        # Only an outdoor map hundreds of metres wide may refuse the default 5 cm grid.
        assert "mapping.resolution_m" in str(e), str(e)
        env = gym.make(
            "SemanticExplore-v0", world=str(path), config={"mapping": {"resolution_m": 0.5}}
        )
    obs, info = env.reset(seed=0)
    assert (obs["map"] == FREE).sum() > 0
    for _ in range(5):
        obs, *_, info = env.step(np.array([0.5, 0.2], np.float32))
    assert 0.0 < info["coverage"] <= 1.0
    assert info["collisions"] <= 1
