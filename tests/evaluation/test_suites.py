"""Benchmark suites: shipped suites load and build, YAML round trip, clear errors."""

from __future__ import annotations

from pathlib import Path

import pytest

from semexplore_gym.evaluation.suites import (
    Suite,
    SuiteWorld,
    list_suites,
    load_suite,
    save_suite,
    suite_from_dict,
    world_family,
    world_time_limit_s,
)
from semexplore_gym.maps import make_world

SHARED_MAPS = Path(__file__).resolve().parents[2].parent / "shared" / "maps"


def test_the_shipped_suites_are_there() -> None:
    assert {"paper", "mazes", "offices", "caves", "open", "real"} <= set(list_suites())


def test_the_real_suite_names_catalogue_maps(monkeypatch: pytest.MonkeyPatch) -> None:
    from semexplore_gym.maps.catalogue import CATALOGUE

    suite = load_suite("real")
    names = [w.world.removeprefix("map:") for w in suite.worlds]
    assert all(w.world.startswith("map:") for w in suite.worlds)
    assert set(names) <= set(CATALOGUE) and len(names) >= 10
    assert {world_family(w.world) for w in suite.worlds} == {"real maps"}
    if not SHARED_MAPS.is_dir():
        pytest.skip(f"shared maps not found at {SHARED_MAPS}")
    monkeypatch.setenv("SEMEXPLORE_MAPS_DIR", str(SHARED_MAPS))
    limits = {}
    for entry in suite.worlds:
        world = make_world(entry.world)
        area = float(world.free_mask.sum()) * world.free_geometry.resolution_m**2
        limits[entry.world] = (area, world_time_limit_s(suite, entry, area))
    # Per-map limits grow with the explorable area (600 s at least).
    big = max(limits.values())
    assert big[1] == pytest.approx(suite.time_per_m2_s * big[0])
    assert min(v[1] for v in limits.values()) == suite.min_time_s == 600.0


#: The world families of each shipped suite: one each, but 'caves' (v3) holds both kinds of
#: cave.
SUITE_FAMILIES = {
    "paper": {"paper mazes"},
    "mazes": {"maze"},
    "offices": {"office"},
    "caves": {"cave", "noisecave"},
    "open": {"forest"},
}


@pytest.mark.parametrize("name", sorted(SUITE_FAMILIES))
def test_every_world_of_a_shipped_suite_builds(name: str) -> None:
    suite = load_suite(name)
    assert suite.name == name and suite.version >= 1 and suite.worlds
    families = {world_family(w.world) for w in suite.worlds}
    assert families == SUITE_FAMILIES[name]
    for entry in suite.worlds:
        world = make_world(entry.world)
        area = float(world.free_mask.sum()) * world.free_geometry.resolution_m**2
        limit = world_time_limit_s(suite, entry, area)
        assert limit is not None and limit >= 600.0


def test_round_trip(tmp_path: Path) -> None:
    suite = Suite(
        name="mine",
        version=3,
        worlds=(SuiteWorld("maze:seed=1,size_m=6"), SuiteWorld("cave:seed=2", 900.0)),
        description="two worlds",
        runs=4,
        random_start=False,
        time_per_m2_s=5.0,
        min_time_s=100.0,
    )
    back = load_suite(save_suite(suite, tmp_path / "mine.yaml"))
    assert back == suite
    assert world_time_limit_s(back, back.worlds[1], 10.0) == 900.0
    assert world_time_limit_s(back, back.worlds[0], 10.0) == 100.0
    assert world_time_limit_s(back, back.worlds[0], 40.0) == 200.0


def test_a_suite_by_directory_variable(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    (tmp_path / "tiny.yaml").write_text("name: tiny\nworlds: [maze1]\n")
    monkeypatch.setenv("SEMEXPLORE_SUITES_DIR", str(tmp_path))
    assert list_suites() == ["tiny"]
    assert load_suite("tiny").worlds == (SuiteWorld("maze1"),)


@pytest.mark.parametrize(
    "data, needle",
    [
        ({"name": "x", "worlds": ["maze1"], "runz": 2}, "unknown key"),
        ({"worlds": ["maze1"]}, "'name'"),
        ({"name": "x", "worlds": []}, "'worlds'"),
        ({"name": "x", "worlds": ["maze1"], "runs": 0}, "runs"),
        ({"name": "x", "worlds": [{"world": "maze1", "max_time_s": -1}]}, "max_time_s"),
        ({"name": "x", "worlds": [3]}, r"worlds\[0\]"),
        ({"name": "x", "worlds": ["maze1"], "max_time_s": 10, "time_per_m2_s": 1}, "not both"),
        ({"name": "x", "worlds": ["maze1"], "time_per_m2_s": float("nan")}, "time_per_m2_s"),
    ],
)
def test_malformed_suites_are_named(data: dict, needle: str) -> None:
    with pytest.raises(ValueError, match=needle):
        suite_from_dict(data, "s.yaml")


def test_unknown_and_broken_files(tmp_path: Path) -> None:
    with pytest.raises(FileNotFoundError, match="known suites: .*mazes"):
        load_suite("no_such_suite")
    bad = tmp_path / "bad.yaml"
    bad.write_text("name: [unclosed\n")
    with pytest.raises(ValueError, match="not valid YAML"):
        load_suite(bad)
