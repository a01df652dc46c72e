"""``semexplore maps list / get / path`` (no network: ``--from`` copies; the downloader itself
is tested against a loopback server in ``tests/maps/test_download.py``)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from semexplore_gym.cli import main
from semexplore_gym.maps.catalogue import CATALOGUE

SHARED_MAPS = Path(__file__).resolve().parents[2].parent / "shared" / "maps"
needs_shared = pytest.mark.skipif(
    not SHARED_MAPS.is_dir(), reason=f"shared maps not found at {SHARED_MAPS}"
)


@pytest.fixture(autouse=True)
def cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.setenv("SEMEXPLORE_CACHE", str(tmp_path / "cache"))
    monkeypatch.delenv("SEMEXPLORE_MAPS_DIR", raising=False)
    monkeypatch.delenv("SEMEXPLORE_MAPS_MIRROR", raising=False)
    return tmp_path / "cache" / "maps"


def test_list_prints_one_line_per_map(capsys) -> None:
    assert main(["maps", "list"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert len(lines) == len(CATALOGUE)
    for line, entry in zip(lines, CATALOGUE.values(), strict=True):
        assert line.split()[0] == entry.name
        assert entry.licence in line and line.endswith(entry.source)
    warehouse = next(line for line in lines if line.startswith("nav2-warehouse "))
    assert "1.6 MB" in warehouse


def test_list_files_gives_each_files_pinned_url_and_sha256(capsys) -> None:
    assert main(["maps", "list", "--files"]) == 0
    out = capsys.readouterr().out
    for entry in CATALOGUE.values():
        for f in entry.files:
            url = entry.url(f)
            line = next(x for x in out.splitlines() if f"sha256 {f.sha256}" in x)
            assert line.strip().startswith(f.filename + " ")
            assert (url in line) if url else "written by this package" in line
            if url:
                assert f"/{entry.commit}/" in url and len(entry.commit) == 40


def test_path_without_name_is_the_cache(cache, capsys) -> None:
    assert main(["maps", "path"]) == 0
    assert capsys.readouterr().out.strip() == str(cache)


def test_errors_name_the_bad_value(tmp_path, capsys) -> None:
    assert main(["maps", "get", "atlantis"]) == 2
    assert "unknown map 'atlantis'" in capsys.readouterr().err
    assert main(["maps", "path", "tb3-world"]) == 2
    assert "semexplore maps get tb3-world" in capsys.readouterr().err
    assert main(["maps", "get", "tb3-world", "--from", str(tmp_path / "nope")]) == 2
    assert str(tmp_path / "nope") in capsys.readouterr().err
    assert main(["maps", "get", "tb3-world", "--timeout-s", "0"]) == 2
    assert "--timeout-s" in capsys.readouterr().err
    assert main(["maps"]) == 2


@pytest.mark.shared_maps
@needs_shared
def test_get_from_then_explore_map_name(cache, capsys) -> None:
    assert main(["maps", "get", "tb3-world", "--from", str(SHARED_MAPS)]) == 0
    assert capsys.readouterr().out.strip() == f"tb3-world: {cache / 'tb3-world' / 'map.yaml'}"
    assert main(["maps", "path", "tb3-world"]) == 0
    assert capsys.readouterr().out.strip() == str(cache / "tb3-world" / "map.yaml")
    argv = ["explore", "--world", "map:tb3-world", "--policy", "random", "--max-time-s", "2"]
    assert main([*argv, "--json", "--no-progress"]) == 0
    result = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert result["mission_time_s"] == pytest.approx(2.0) and 0 < result["coverage"] <= 1


@pytest.mark.shared_maps
@needs_shared
def test_get_into_dir_and_use_it_as_maps_dir(tmp_path, cache, monkeypatch, capsys) -> None:
    maps_dir = tmp_path / "my_maps"
    argv = ["maps", "get", "willow-garage", "--from", str(SHARED_MAPS), "--dir", str(maps_dir)]
    assert main(argv) == 0
    assert sorted(p.name for p in (maps_dir / "willow-garage").iterdir()) == [
        "willow-full.pgm",
        "willow-full.yaml",
    ]
    assert not cache.exists()
    capsys.readouterr()
    monkeypatch.setenv("SEMEXPLORE_MAPS_DIR", str(maps_dir))
    assert main(["maps", "path", "willow-garage"]) == 0
    assert capsys.readouterr().out.strip() == str(maps_dir / "willow-garage" / "willow-full.yaml")
