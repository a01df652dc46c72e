"""DungeonMaps (Chen et al. 2019): the PNG loader on images written here, the catalogue sample
and its checksum verification with local files (no network, no file of theirs)."""

from __future__ import annotations

import hashlib
import re
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from semexplore_gym.cli import main
from semexplore_gym.maps import make_world
from semexplore_gym.maps.catalogue import CATALOGUE, DUNGEON_PREFIX, CatalogueMap, MapFile
from semexplore_gym.maps.download import MapFetchError, copy_map
from semexplore_gym.maps.dungeon_catalogue import (
    DUNGEON_COMMIT,
    DUNGEON_REPO,
    TEST_SAMPLE,
    TRAIN_SAMPLE,
    VALIDATION_SAMPLE,
)
from semexplore_gym.maps.dungeon_maps import (
    DUNGEON_M_PER_PX,
    FREE_RGB,
    START_RGB,
    WALL_RGB,
    load_dungeon_map_world,
)


@pytest.fixture(autouse=True)
def _isolated_cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("SEMEXPLORE_CACHE", str(tmp_path / "cache"))
    monkeypatch.delenv("SEMEXPLORE_MAPS_DIR", raising=False)


def _write_dungeon(path: Path, *, marker: bool = True, stray: bool = False) -> Path:
    """A 40 x 30 px map in their colours: a walled room split by a wall with a door, the 4 x 4
    start marker at image rows 4..7, columns 30..33 (top right)."""
    rgb = np.empty((30, 40, 3), dtype=np.uint8)
    rgb[:] = WALL_RGB
    rgb[2:-2, 2:-2] = FREE_RGB
    rgb[2:-2, 19:21] = WALL_RGB  # the dividing wall ...
    rgb[12:18, 19:21] = FREE_RGB  # ... with a door
    if marker:
        rgb[4:8, 30:34] = START_RGB
    if stray:
        rgb[25, 5] = (10, 200, 30)  # a colour that is none of theirs
    alpha = np.full((30, 40, 1), 255, dtype=np.uint8)
    path.parent.mkdir(parents=True, exist_ok=True)
    Image.fromarray(np.concatenate([rgb, alpha], axis=-1)).save(path)
    return path


def test_loader_reads_their_colours_and_starts_on_the_marker(tmp_path: Path) -> None:
    world = load_dungeon_map_world(_write_dungeon(tmp_path / "img_1.png"), name="d")
    res = DUNGEON_M_PER_PX
    assert world.free_geometry.resolution_m == res
    # free space: the room (26 x 36 px) minus the dividing wall (26 x 2) plus its door (6 x 2)
    assert int(world.free_mask.sum()) == 26 * 36 - 26 * 2 + 6 * 2
    # the marker's centre: image columns 30..33 -> x = 32 px; rows 4..7 from the top of 30
    # -> rows 22..25 from the bottom -> y = 24 px
    x, y, yaw = world.start_pose
    assert (x, y, yaw) == pytest.approx((32 * res, 24 * res, 0.0))
    assert world.bounds_m == pytest.approx((2 * res, 2 * res, 38 * res, 28 * res))
    assert world.metadata["sensor_range_m"] == pytest.approx(3.5)
    assert world.metadata["other_pixels"] == 0


def test_scale_is_a_parameter_and_other_colours_are_walls(tmp_path: Path) -> None:
    png = _write_dungeon(tmp_path / "img_2.png", stray=True)
    world = load_dungeon_map_world(png, m_per_px=0.1)
    assert world.start_pose[:2] == pytest.approx((3.2, 2.4))
    assert world.metadata["other_pixels"] == 1
    assert int(world.free_mask.sum()) == 26 * 36 - 26 * 2 + 6 * 2 - 1
    with pytest.raises(ValueError, match="m_per_px"):
        load_dungeon_map_world(png, m_per_px=0.0)
    with pytest.raises(ValueError, match="no start marker"):
        load_dungeon_map_world(_write_dungeon(tmp_path / "img_3.png", marker=False))
    # a .png path is a DungeonMaps world spec
    assert make_world(str(png)).start_pose == pytest.approx(load_dungeon_map_world(png).start_pose)


def test_catalogue_sample_is_pinned_and_disjoint() -> None:
    assert [row[0] for row in TEST_SAMPLE] == [f"img_{i}" for i in range(9900, 10000)]
    assert len(TRAIN_SAMPLE) == 200 and len(VALIDATION_SAMPLE) == 50
    train = {row[0] for row in TRAIN_SAMPLE}
    assert len(train) == 200 and not train & {row[0] for row in VALIDATION_SAMPLE}
    entries = [e for e in CATALOGUE.values() if e.name.startswith(DUNGEON_PREFIX)]
    assert len(entries) == 350
    raw = re.compile(
        rf"^https://raw\.githubusercontent\.com/{DUNGEON_REPO}/{DUNGEON_COMMIT}/"
        r"DungeonMaps/(test|train)/(img_)?\d+\.png$"
    )
    for e in entries:
        (f,) = e.files
        assert re.fullmatch(r"[0-9a-f]{64}", f.sha256) and 1000 < f.size_bytes < 100_000
        assert raw.match(e.url(f) or ""), e.name
        assert e.licence == "BSD-3-Clause" and e.shared_subdir == str(Path(f.upstream_path).parent)
    assert CATALOGUE["dungeon-test-img-9900"].files[0].filename == "img_9900.png"


def _fake_entry(png: Path, name: str = "dungeon-test-img-9900") -> CatalogueMap:
    """The catalogue entry ``name`` with the checksum of a PNG written here."""
    real = CATALOGUE[name]
    data = png.read_bytes()
    f = real.files[0]
    mine = MapFile(f.filename, hashlib.sha256(data).hexdigest(), len(data), f.upstream_path)
    return CatalogueMap(
        name, real.description, real.licence, real.repo, real.commit, real.shared_subdir, (mine,)
    )


def test_checksums_are_verified_and_a_checkout_of_theirs_is_a_maps_dir(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # laid out as their repository: DIR/DungeonMaps/test/img_9900.png
    theirs = tmp_path / "DRL_robot_exploration"
    png = _write_dungeon(theirs / "DungeonMaps" / "test" / "img_9900.png")
    # the real entry's sha256 is that of their file: ours is refused, nothing is kept
    with pytest.raises(MapFetchError, match="sha256 mismatch"):
        copy_map("dungeon-test-img-9900", theirs, tmp_path / "got")
    assert not (tmp_path / "got" / "img_9900.png").exists()
    monkeypatch.setitem(CATALOGUE, "dungeon-test-img-9900", _fake_entry(png))
    world_file = copy_map("dungeon-test-img-9900", theirs)  # into the cache, checked
    assert world_file.name == "img_9900.png" and world_file.read_bytes() == png.read_bytes()
    world = make_world("map:dungeon-test-img-9900")
    assert world.name == "map:dungeon-test-img-9900"
    assert world.start_pose == pytest.approx(load_dungeon_map_world(png).start_pose)
    scaled = make_world("map:dungeon-test-img-9900,m_per_px=0.1")
    assert scaled.start_pose[:2] == pytest.approx((3.2, 2.4))
    with pytest.raises(ValueError, match="unknown option"):
        make_world("map:dungeon-test-img-9900,scale=2")
    # $SEMEXPLORE_MAPS_DIR may point at a checkout of their repository
    (world_file).unlink()
    monkeypatch.setenv("SEMEXPLORE_MAPS_DIR", str(theirs))
    assert make_world("map:dungeon-test-img-9900").start_pose == pytest.approx(world.start_pose)


def test_maps_get_takes_a_pattern(tmp_path: Path, capsys) -> None:
    empty = tmp_path / "empty"
    empty.mkdir()
    assert main(["maps", "get", "dungeon-nothing-*", "--from", str(empty)]) == 2
    assert "no catalogue map matches 'dungeon-nothing-*'" in capsys.readouterr().err
    # a pattern expands to its matches (here: ten maps, the first one missing from DIR)
    assert main(["maps", "get", "dungeon-test-img-990?", "--from", str(empty)]) == 2
    assert "img_9900.png of map 'dungeon-test-img-9900' not found" in capsys.readouterr().err
