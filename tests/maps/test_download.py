"""Fetching catalogue maps: a loopback HTTP server stands in for raw.githubusercontent.com.

Covers the checksum, the size bound, offline and HTTP errors, timeouts, atomic writes (nothing
under a final name after a failure), ``--from DIR`` copies and ``map:NAME`` through
``gym.make``. Real catalogue entries are served from ``../shared/maps`` when it is present;
the rest use small generated maps with their own catalogue entries.
"""

from __future__ import annotations

import hashlib
import http.server
import socket
import threading
import time
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest
from PIL import Image

import semexplore_gym  # noqa: F401  (registers the env)
from semexplore_gym.cli import main
from semexplore_gym.maps import make_world
from semexplore_gym.maps.catalogue import CATALOGUE, CatalogueMap, MapFile
from semexplore_gym.maps.download import MapFetchError, copy_map, download_map

SHARED_MAPS = Path(__file__).resolve().parents[2].parent / "shared" / "maps"
needs_shared = pytest.mark.skipif(
    not SHARED_MAPS.is_dir(), reason=f"shared maps not found at {SHARED_MAPS}"
)


@dataclass
class MapServer:
    """What the loopback server serves (URL path -> bytes) and what it was asked for."""

    url: str = ""
    files: dict[str, bytes] = field(default_factory=dict)
    requests: list[str] = field(default_factory=list)
    send_length: bool = True
    delay_s: float = 0.0

    def publish(self, entry: CatalogueMap, source_dir: Path) -> None:
        for f in entry.files:
            if f.upstream_path is not None:
                path = f"/{entry.repo}/{entry.commit}/{f.upstream_path}"
                self.files[path] = (source_dir / f.filename).read_bytes()


@pytest.fixture
def server() -> Iterator[MapServer]:
    state = MapServer()

    class Handler(http.server.BaseHTTPRequestHandler):
        def do_GET(self) -> None:  # noqa: N802 (http.server's name)
            state.requests.append(self.path)
            time.sleep(state.delay_s)
            body = state.files.get(self.path)
            if body is None:
                self.send_error(404)
                return
            self.send_response(200)
            if state.send_length:
                self.send_header("Content-Length", str(len(body)))
            self.end_headers()
            try:
                self.wfile.write(body)
            except (BrokenPipeError, ConnectionResetError):
                pass  # the client gave up (size bound, timeout): what the test wants

        def log_message(self, *args: object) -> None:
            pass

    httpd = http.server.ThreadingHTTPServer(("127.0.0.1", 0), Handler)
    httpd.daemon_threads = True
    thread = threading.Thread(target=httpd.serve_forever, kwargs={"poll_interval": 0.05})
    thread.start()
    state.url = f"http://127.0.0.1:{httpd.server_address[1]}"
    try:
        yield state
    finally:
        httpd.shutdown()
        httpd.server_close()
        thread.join(timeout=10)


@pytest.fixture(autouse=True)
def cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.setenv("SEMEXPLORE_CACHE", str(tmp_path / "cache"))
    monkeypatch.delenv("SEMEXPLORE_MAPS_DIR", raising=False)
    return tmp_path / "cache" / "maps"


def _room(directory: Path, name: str = "test-room") -> CatalogueMap:
    """A 3x3 m walled room (ROS map) in ``directory`` and its catalogue entry."""
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
    return CatalogueMap(name, "a room", "MIT", "owner/repo", "a" * 40, "rooms", files)


def _flip_last_byte(data: bytes) -> bytes:
    return data[:-1] + bytes([data[-1] ^ 0xFF])


def _leftovers(directory: Path) -> list[str]:
    return sorted(p.name for p in directory.iterdir()) if directory.exists() else []


def test_download_verifies_and_loads_through_gym_make(tmp_path, server, cache, monkeypatch) -> None:
    entry = _room(tmp_path / "src")
    server.publish(entry, tmp_path / "src")
    monkeypatch.setitem(CATALOGUE, entry.name, entry)
    world_file = download_map(entry.name, base_url=server.url, timeout_s=5)
    assert world_file == cache / "test-room" / "room.yaml"
    assert (cache / "test-room" / "room.pgm").read_bytes() == (
        tmp_path / "src/room.pgm"
    ).read_bytes()
    assert _leftovers(cache / "test-room") == ["room.pgm", "room.yaml"]
    assert server.requests == ["/owner/repo/" + "a" * 40 + "/maps/room.pgm",
                               "/owner/repo/" + "a" * 40 + "/maps/room.yaml"]  # fmt: skip
    # Present and verified: a second get fetches nothing.
    download_map(entry.name, base_url=server.url, timeout_s=5)
    assert len(server.requests) == 2

    env = gym.make("SemanticExplore-v0", world="map:test-room")
    obs, info = env.reset(seed=0)
    assert env.unwrapped.world.name == "map:test-room"
    obs, *_, info = env.step(np.array([0.2, 0.0], np.float32))
    assert 0.0 < info["coverage"] <= 1.0
    env.close()


def test_checksum_mismatch_keeps_nothing(tmp_path, server, cache, monkeypatch) -> None:
    entry = _room(tmp_path / "src")
    server.publish(entry, tmp_path / "src")
    pgm = next(p for p in server.files if p.endswith(".pgm"))
    server.files[pgm] = _flip_last_byte(server.files[pgm])  # same size, one byte changed
    monkeypatch.setitem(CATALOGUE, entry.name, entry)
    with pytest.raises(MapFetchError, match="sha256 mismatch for room.pgm"):
        download_map(entry.name, base_url=server.url, timeout_s=5)
    assert _leftovers(cache / "test-room") == []  # no file, no .part, no empty directory
    with pytest.raises(FileNotFoundError, match="semexplore maps get test-room"):
        make_world("map:test-room")


def test_a_failed_refetch_leaves_the_old_file_untouched(tmp_path, server, monkeypatch) -> None:
    entry = _room(tmp_path / "src")
    server.publish(entry, tmp_path / "src")
    monkeypatch.setitem(CATALOGUE, entry.name, entry)
    dest = tmp_path / "dest"
    dest.mkdir()
    (dest / "room.pgm").write_bytes(b"stale")
    server.files = {k: b"P5 bad" for k in server.files}
    with pytest.raises(MapFetchError, match="sha256 mismatch"):
        download_map(entry.name, dest, base_url=server.url, timeout_s=5)
    assert _leftovers(dest) == ["room.pgm"] and (dest / "room.pgm").read_bytes() == b"stale"


@pytest.mark.parametrize("send_length", [True, False], ids=["content-length", "streamed"])
def test_oversized_download_is_refused(tmp_path, server, monkeypatch, send_length) -> None:
    entry = _room(tmp_path / "src")
    server.publish(entry, tmp_path / "src")
    server.send_length = send_length
    pgm = next(p for p in server.files if p.endswith(".pgm"))
    server.files[pgm] = b"x" * (2 * entry.files[0].size_bytes + 1)
    monkeypatch.setitem(CATALOGUE, entry.name, entry)
    dest = tmp_path / "dest"
    with pytest.raises(MapFetchError, match="refused"):
        download_map(entry.name, dest, base_url=server.url, timeout_s=5)
    assert _leftovers(dest) == []


def test_offline_error_suggests_from(tmp_path, monkeypatch) -> None:
    entry = _room(tmp_path / "src")
    monkeypatch.setitem(CATALOGUE, entry.name, entry)
    with socket.socket() as s:  # a port nobody listens on: connection refused
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    dest = tmp_path / "dest"
    with pytest.raises(MapFetchError) as exc:
        download_map(entry.name, dest, base_url=f"http://127.0.0.1:{port}", timeout_s=5)
    message = str(exc.value)
    assert "cannot download test-room" in message and "--from DIR" in message
    # Where a user's own copy would be, not a folder only this project's checkouts have.
    assert "../shared" not in message and "with DIR a folder holding" in message
    assert all(f.filename in message for f in entry.files if f.upstream_path is not None)
    assert "\n" not in message
    assert not dest.exists()


def test_http_error_and_timeout(tmp_path, server, monkeypatch) -> None:
    entry = _room(tmp_path / "src")
    monkeypatch.setitem(CATALOGUE, entry.name, entry)
    with pytest.raises(MapFetchError, match="HTTP 404"):
        download_map(entry.name, tmp_path / "a", base_url=server.url, timeout_s=5)
    server.publish(entry, tmp_path / "src")
    server.delay_s = 1.0
    t0 = time.monotonic()
    with pytest.raises(MapFetchError, match="timed out"):
        download_map(entry.name, tmp_path / "b", base_url=server.url, timeout_s=0.2)
    assert time.monotonic() - t0 < 5.0
    assert _leftovers(tmp_path / "b") == []


def test_copy_from_a_local_directory(tmp_path, cache, monkeypatch) -> None:
    entry = _room(tmp_path / "collection" / "rooms")  # the shared layout: DIR/SHARED_SUBDIR
    monkeypatch.setitem(CATALOGUE, entry.name, entry)
    world_file = copy_map(entry.name, tmp_path / "collection")
    assert world_file == cache / "test-room" / "room.yaml"
    assert make_world("map:test-room").name == "map:test-room"
    # A flat directory works too; a corrupt copy is refused and not kept.
    flat = tmp_path / "flat"
    flat.mkdir()
    (flat / "room.pgm").write_bytes(
        _flip_last_byte((tmp_path / "collection/rooms/room.pgm").read_bytes())
    )
    (flat / "room.yaml").write_bytes((tmp_path / "collection/rooms/room.yaml").read_bytes())
    with pytest.raises(MapFetchError, match="sha256 mismatch"):
        copy_map(entry.name, flat, tmp_path / "out")
    assert _leftovers(tmp_path / "out") == []
    (flat / "room.pgm").unlink()
    with pytest.raises(FileNotFoundError, match="room.pgm of map 'test-room' not found"):
        copy_map(entry.name, flat, tmp_path / "out")
    with pytest.raises(FileNotFoundError, match="--from directory not found"):
        copy_map(entry.name, tmp_path / "missing")


@pytest.mark.shared_maps
@needs_shared
def test_real_entries_from_a_mirror_of_the_shared_maps(tmp_path, server, cache, capsys) -> None:
    """tb3-world (two upstream files) and stage-cave (image upstream, our sidecar packaged)."""
    for name in ("tb3-world", "stage-cave"):
        entry = CATALOGUE[name]
        server.publish(entry, SHARED_MAPS / entry.shared_subdir)
    argv = ["maps", "get", "tb3-world", "stage-cave", "--mirror", server.url, "--timeout-s", "5"]
    assert main(argv) == 0
    out = capsys.readouterr().out
    assert f"tb3-world: {cache / 'tb3-world' / 'map.yaml'}" in out
    assert len(server.requests) == 3  # cave.yaml comes from the package
    import yaml

    for name, sub in (("tb3-world", "turtlebot3/world"), ("stage-cave", "stage")):
        for f in CATALOGUE[name].files:
            got = (cache / name / f.filename).read_bytes()
            shared = (SHARED_MAPS / sub / f.filename).read_bytes()
            if f.upstream_path is None:  # our generated sidecar: the same fields
                ours = yaml.safe_load(got)
                assert ours == {k: yaml.safe_load(shared)[k] for k in ours}
            else:
                assert got == shared
    world = make_world("map:stage-cave")
    assert world.n_segments == make_world(SHARED_MAPS / "stage" / "cave.yaml").n_segments


def test_cli_get_offline_is_one_clear_line(tmp_path, capsys, monkeypatch) -> None:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    monkeypatch.setenv("SEMEXPLORE_MAPS_MIRROR", f"http://127.0.0.1:{port}")
    from semexplore_gym.cli import build_parser

    args = build_parser().parse_args(["maps", "get", "tb3-world"])
    assert args.mirror == f"http://127.0.0.1:{port}"  # the env var is the default mirror
    assert main(["maps", "get", "tb3-world", "--timeout-s", "5"]) == 1
    err = capsys.readouterr().err.strip()
    assert err.startswith("semexplore maps get: error: cannot download tb3-world")
    assert "--from DIR" in err and len(err.splitlines()) == 1
