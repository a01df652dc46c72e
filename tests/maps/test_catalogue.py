"""The map catalogue: well-formed entries, checksums against the shared copies, resolution of
``map:NAME`` from ``$SEMEXPLORE_MAPS_DIR`` and the cache (no network here)."""

from __future__ import annotations

import hashlib
import os
import re
import shutil
from pathlib import Path

import numpy as np
import pytest
import yaml
from PIL import Image

from semexplore_gym.maps import make_world
from semexplore_gym.maps.catalogue import (
    CATALOGUE,
    CatalogueMap,
    MapFile,
    get_catalogue_map,
    maps_cache_dir,
    resolve_map_file,
    sidecar_bytes,
    validate_map_name,
)

SHARED_MAPS = Path(__file__).resolve().parents[2].parent / "shared" / "maps"
_RAW = re.compile(r"^https://raw\.githubusercontent\.com/[\w.-]+/[\w.-]+/[0-9a-f]{7,40}/[\w./-]+$")


@pytest.fixture(autouse=True)
def _isolated_cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.setenv("SEMEXPLORE_CACHE", str(tmp_path / "cache"))
    monkeypatch.delenv("SEMEXPLORE_MAPS_DIR", raising=False)
    return tmp_path / "cache"


def test_catalogue_has_the_promised_maps() -> None:
    for name in ("tb3-world", "tb3-office", "nav2-depot", "nav2-warehouse", "willow-garage",
                 "intel-lab", "freiburg79"):  # fmt: skip
        assert name in CATALOGUE


@pytest.mark.parametrize("entry", list(CATALOGUE.values()), ids=lambda m: m.name)
def test_entry_is_well_formed(entry: CatalogueMap) -> None:
    assert validate_map_name(entry.name) == entry.name
    assert entry.description and entry.licence and entry.size_bytes > 0
    assert entry.world_file.filename.endswith((".yaml", ".json", ".png"))
    assert len({f.filename for f in entry.files}) == len(entry.files)
    for f in entry.files:
        assert re.fullmatch(r"[0-9a-f]{64}", f.sha256) and f.size_bytes > 0
        url = entry.url(f)
        if f.upstream_path is None:
            assert url is None
            data = sidecar_bytes(f)  # shipped in the package, and matching its checksum
            assert hashlib.sha256(data).hexdigest() == f.sha256 and len(data) == f.size_bytes
        else:
            assert url is not None and _RAW.match(url), url
            assert f"/{entry.repo}/{entry.commit}/" in url
    if entry.world_file.filename.endswith(".yaml"):
        text = (
            sidecar_bytes(entry.world_file)
            if entry.world_file.upstream_path is None
            else (SHARED_MAPS / entry.shared_subdir / entry.world_file.filename).read_bytes()
            if SHARED_MAPS.is_dir()
            else None
        )
        if text is not None:  # the yaml's image is one of the entry's files
            image = Path(yaml.safe_load(text)["image"]).name
            assert image in {f.filename for f in entry.files}


@pytest.mark.shared_maps
@pytest.mark.skipif(not SHARED_MAPS.is_dir(), reason=f"shared maps not found at {SHARED_MAPS}")
@pytest.mark.parametrize(
    "entry",
    [e for e in CATALOGUE.values() if not e.name.startswith("dungeon-")],  # not in the collection
    ids=lambda m: m.name,
)
def test_checksums_match_the_shared_copies(entry: CatalogueMap) -> None:
    import yaml

    for f in entry.files:
        data = (SHARED_MAPS / entry.shared_subdir / f.filename).read_bytes()
        if f.upstream_path is None:
            # Our sidecar is generated, not copied: the same map_server fields as the shared one.
            ours = yaml.safe_load(sidecar_bytes(f))
            theirs = yaml.safe_load(data)
            assert ours == {k: theirs[k] for k in ours}, f.filename
            continue
        assert hashlib.sha256(data).hexdigest() == f.sha256, f.filename
        assert len(data) == f.size_bytes


def test_unknown_and_malformed_names() -> None:
    with pytest.raises(ValueError, match="unknown map 'atlantis'.*tb3-world"):
        get_catalogue_map("atlantis")
    with pytest.raises(ValueError, match=r"'\.\./etc'"):
        validate_map_name("../etc")
    with pytest.raises(ValueError, match="unknown map 'atlantis'"):
        make_world("map:atlantis")


def test_cache_dir_precedence(tmp_path: Path) -> None:
    assert maps_cache_dir({"SEMEXPLORE_CACHE": "/a", "XDG_CACHE_HOME": "/b"}) == Path("/a/maps")
    assert maps_cache_dir({"XDG_CACHE_HOME": "/b"}) == Path("/b/semexplore/maps")
    assert maps_cache_dir({"SEMEXPLORE_CACHE": "", "HOME": str(tmp_path)}) == (
        Path("~/.cache/semexplore/maps").expanduser()
    )


def _room(directory: Path) -> CatalogueMap:
    """A 3x3 m walled room as a ROS map, with a catalogue entry for it."""
    directory.mkdir(parents=True, exist_ok=True)
    pixels = np.full((30, 30), 254, np.uint8)
    pixels[[0, -1], :] = 0
    pixels[:, [0, -1]] = 0
    Image.fromarray(pixels).save(directory / "room.pgm")
    (directory / "room.yaml").write_text("image: room.pgm\nresolution: 0.1\norigin: [0, 0, 0]\n")
    files = tuple(
        MapFile(n, hashlib.sha256((directory / n).read_bytes()).hexdigest(),
                (directory / n).stat().st_size, f"maps/{n}")
        for n in ("room.pgm", "room.yaml")
    )  # fmt: skip
    return CatalogueMap("test-room", "a room", "MIT", "o/r", "0" * 40, "rooms/small", files)


def test_resolution_order_and_make_world(tmp_path: Path, monkeypatch, _isolated_cache) -> None:
    entry = _room(tmp_path / "src")
    monkeypatch.setitem(CATALOGUE, entry.name, entry)
    with pytest.raises(FileNotFoundError, match="semexplore maps get test-room"):
        make_world("map:test-room")
    # In the cache: CACHE/NAME/.
    shutil.copytree(tmp_path / "src", _isolated_cache / "maps" / "test-room")
    assert resolve_map_file("test-room") == _isolated_cache / "maps" / "test-room" / "room.yaml"
    world = make_world("map:test-room")
    assert world.name == "map:test-room"
    assert world.bounds_m == pytest.approx((0.1, 0.1, 2.9, 2.9))
    # $SEMEXPLORE_MAPS_DIR wins, in the shared layout (DIR/SHARED_SUBDIR/)...
    shared = tmp_path / "shared"
    shutil.copytree(tmp_path / "src", shared / "rooms" / "small")
    monkeypatch.setenv(
        "SEMEXPLORE_MAPS_DIR", os.pathsep.join([str(tmp_path / "nowhere"), str(shared)])
    )
    assert resolve_map_file("test-room") == shared / "rooms" / "small" / "room.yaml"
    # ...but only a directory that holds every file counts.
    (shared / "rooms" / "small" / "room.pgm").unlink()
    assert resolve_map_file("test-room").parent == _isolated_cache / "maps" / "test-room"


@pytest.mark.shared_maps
@pytest.mark.skipif(not SHARED_MAPS.is_dir(), reason=f"shared maps not found at {SHARED_MAPS}")
def test_map_spec_reads_the_shared_collection(monkeypatch) -> None:
    monkeypatch.setenv("SEMEXPLORE_MAPS_DIR", str(SHARED_MAPS))
    world = make_world("map:tb3-world")
    assert world.name == "map:tb3-world"
    direct = make_world(SHARED_MAPS / "turtlebot3" / "world" / "map.yaml")
    assert world.n_segments == direct.n_segments and world.bounds_m == direct.bounds_m
