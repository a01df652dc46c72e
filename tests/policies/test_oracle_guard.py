"""The guard: on small worlds of every family the oracle reaches 99 % no later than the expert
and nearest frontier, so an expert that gets faster cannot silently pass its yardstick, and no
policy reaches it sooner than the certified lower bound of its start allows."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from semexplore_gym.maps.dungeon_maps import FREE_RGB, START_RGB, WALL_RGB

pytest.importorskip("elkai")

_TIE = (
    "a 6 m cave: the expert's first 10 s of scans happen to see 99 %; the oracle, driving its "
    "tour, gets there 2 s later"
)

_PRUNED = (
    "a 5 m maze: the live map makes a viewpoint unnecessary just short of it, and the leg from "
    "there to the next, predicted from single scans, leaves two wedges behind a corner unseen "
    "that the dropped viewpoint's leg would have seen: a detour at the end, T99 139 s against "
    "the expert's 109 s (99 s driving the least-cost paths, drive_planned_legs=false, which "
    "loses elsewhere: docs/oracle.md)"
)

#: (world, seed of the random start): small worlds of each procedural family. Marked: where
#: the oracle still loses (strict: the mark must go when it stops losing).
WORLDS = [
    ("maze:seed=1,size_m=5", 0),
    pytest.param("maze:seed=2,size_m=5", 0, marks=pytest.mark.xfail(strict=True, reason=_PRUNED)),
    ("maze:seed=3,size_m=5", 2),
    ("office:seed=2,size_m=8", 0),
    ("office:seed=3,size_m=8", 1),
    ("cave:seed=1,size_m=6", 0),
    pytest.param("cave:seed=2,size_m=6", 0, marks=pytest.mark.xfail(strict=True, reason=_TIE)),
    ("forest:seed=1,size_m=6", 0),
    ("forest:seed=2,size_m=6", 1),
]


def _rooms_and_corridors(path: Path) -> Path:
    """A DungeonMap in their format (0.04375 m/px): four rooms off an L-shaped corridor, each
    through a door, the start marker in the corridor (about 6 m x 5 m)."""
    rgb = np.empty((110, 140, 3), dtype=np.uint8)
    rgb[:] = WALL_RGB
    rgb[50:64, 4:136] = FREE_RGB  # the corridor, west to east ...
    rgb[4:64, 60:74] = FREE_RGB  # ... and north from its middle
    for r0, c0 in ((4, 4), (4, 80), (70, 4), (70, 80)):  # four rooms
        rgb[r0 : r0 + 36, c0 : c0 + 50] = FREE_RGB
    rgb[40:50, 20:30] = FREE_RGB  # doors: north-west room ...
    rgb[20:30, 74:80] = FREE_RGB  # ... north-east (off the north corridor) ...
    rgb[64:70, 30:40] = FREE_RGB  # ... south-west ...
    rgb[64:70, 110:120] = FREE_RGB  # ... south-east
    rgb[54:58, 64:68] = START_RGB
    alpha = np.full((110, 140, 1), 255, dtype=np.uint8)
    Image.fromarray(np.concatenate([rgb, alpha], axis=-1)).save(path)
    return path


def _check_the_oracle_is_first(world: str, seed: int, short_mission) -> None:
    from semexplore_gym.cli.oracle import certified_bound

    bound_s = certified_bound(world, seed, env_overrides=["episode.random_start=true"]).time_s
    oracle, _ = short_mission(world, "oracle", seed, 900)
    assert oracle.t99_s is not None and oracle.collisions == 0
    assert oracle.t99_s >= bound_s, (world, "oracle", bound_s)
    for spec in ("semantic", "nearest"):
        other, _ = short_mission(world, spec, seed, 900)
        assert other.t99_s is None or other.t99_s >= bound_s, (world, spec, bound_s)
        assert other.t99_s is None or oracle.t99_s <= other.t99_s, (world, spec)


@pytest.mark.slow
@pytest.mark.parametrize("world, seed", WORLDS)
def test_the_oracle_reaches_99_percent_first_on_small_worlds(world, seed, short_mission):
    _check_the_oracle_is_first(world, seed, short_mission)


@pytest.mark.slow
def test_the_oracle_reaches_99_percent_first_on_a_room_and_corridor_map(tmp_path, short_mission):
    png = _rooms_and_corridors(tmp_path / "img_1.png")
    _check_the_oracle_is_first(str(png), 0, short_mission)
