"""Download or copy a catalogue map into a directory, verifying every file's sha256.

Each file is streamed into a temporary file in the destination directory, checked against the
catalogue's sha256 and only then renamed into place (``os.replace``), so a failed or
interrupted fetch never leaves a partial or corrupt file under the final name. Files already
present with the right checksum are kept. The world file (the yaml) is written last, so a
directory whose world file exists is complete.
"""

from __future__ import annotations

import hashlib
import http.client
import io
import os
import tempfile
import urllib.error
import urllib.request
from collections.abc import Callable, Iterator, Mapping
from contextlib import contextmanager
from pathlib import Path
from typing import BinaryIO

from semexplore_gym.maps.catalogue import (
    RAW_GITHUB_BASE,
    CatalogueMap,
    MapFile,
    candidate_dirs,
    get_catalogue_map,
    maps_cache_dir,
    sha256_file,
    sidecar_bytes,
)

#: No single download may exceed this, whatever the catalogue says.
MAX_DOWNLOAD_BYTES = 50 * 1024 * 1024
_CHUNK = 1 << 16


class MapFetchError(RuntimeError):
    """A map could not be fetched: network error, bad checksum, oversized or missing file."""


@contextmanager
def _destination(dest: Path) -> Iterator[None]:
    """Create ``dest``; if it was created here and a fetch fails, remove it again when empty."""
    created = not dest.exists()
    dest.mkdir(parents=True, exist_ok=True)
    try:
        yield
    except BaseException:
        if created and not any(dest.iterdir()):
            dest.rmdir()
        raise


def _limit(file: MapFile) -> int:
    return min(MAX_DOWNLOAD_BYTES, 2 * file.size_bytes)


@contextmanager
def _atomic_file(dest: Path) -> Iterator[BinaryIO]:
    """A temporary file beside ``dest``, renamed onto it when the block succeeds, else removed."""
    fd, tmp = tempfile.mkstemp(dir=dest.parent, prefix=f".{dest.name}.", suffix=".part")
    try:
        with os.fdopen(fd, "wb") as f:
            yield f
        os.chmod(tmp, 0o644)  # mkstemp makes it 0600; a cached map is ordinary data
        os.replace(tmp, dest)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def _copy_checked(read: Callable[[int], bytes], file: MapFile, dest: Path, origin: str) -> None:
    """Stream ``read`` into ``dest`` atomically, enforcing the size bound and the sha256."""
    limit = _limit(file)
    digest = hashlib.sha256()
    size = 0
    with _atomic_file(dest) as out:
        while chunk := read(_CHUNK):
            size += len(chunk)
            if size > limit:
                raise MapFetchError(
                    f"{origin}: more than {limit} bytes (catalogue size {file.size_bytes}); refused"
                )
            digest.update(chunk)
            out.write(chunk)
        if digest.hexdigest() != file.sha256:
            raise MapFetchError(
                f"{origin}: sha256 mismatch for {file.filename}: got {digest.hexdigest()}, "
                f"catalogue says {file.sha256} (file not kept)"
            )


def _is_current(path: Path, file: MapFile) -> bool:
    return (
        path.is_file()
        and path.stat().st_size == file.size_bytes
        and sha256_file(path) == file.sha256
    )


def _write_sidecar(file: MapFile, dest: Path) -> None:
    _copy_checked(
        io.BytesIO(sidecar_bytes(file)).read, file, dest, f"packaged sidecar {file.filename}"
    )


def _offline_hint(entry: CatalogueMap) -> str:
    """Where a user's own copy of the map's files would be: ``--from DIR`` and DIR's layout."""
    names = ", ".join(f.filename for f in entry.files if f.upstream_path is not None)
    return (
        f"copy it from a local directory instead: semexplore maps get {entry.name} --from DIR, "
        f"with DIR a folder holding {names} (in DIR/{entry.name}/, DIR/{entry.shared_subdir}/ "
        f"or DIR itself), e.g. downloaded from {entry.source} on a machine with a network"
    )


def _download_file(
    url: str, file: MapFile, dest: Path, entry: CatalogueMap, timeout_s: float
) -> None:
    request = urllib.request.Request(url, headers={"User-Agent": "semexplore-maps"})
    try:
        with urllib.request.urlopen(request, timeout=timeout_s) as response:
            length = response.headers.get("Content-Length")
            if length is not None and length.isdigit() and int(length) > _limit(file):
                raise MapFetchError(
                    f"{url}: Content-Length {length} exceeds {_limit(file)} bytes "
                    f"(catalogue size {file.size_bytes}); refused"
                )
            _copy_checked(response.read, file, dest, url)
    except urllib.error.HTTPError as e:
        raise MapFetchError(
            f"cannot download {entry.name}: {url}: HTTP {e.code} {e.reason}"
        ) from None
    except (TimeoutError, urllib.error.URLError, ConnectionError, http.client.HTTPException) as e:
        reason = getattr(e, "reason", e)
        raise MapFetchError(
            f"cannot download {entry.name} from {url} ({reason}); {_offline_hint(entry)}"
        ) from None


def download_map(
    name: str,
    dest_dir: Path | None = None,
    *,
    base_url: str = RAW_GITHUB_BASE,
    timeout_s: float = 30.0,
    catalogue: Mapping[str, CatalogueMap] | None = None,
) -> Path:
    """Download catalogue map ``name`` into ``dest_dir`` (default: the cache's ``NAME/``).

    Args:
        name: Catalogue name.
        dest_dir: Directory for the map's files (created).
        base_url: Replaces ``https://raw.githubusercontent.com`` (a mirror, or a test server);
            ``OWNER/REPO/COMMIT/PATH`` is appended.
        timeout_s: Socket timeout of each request.
        catalogue: Entries to use instead of :data:`CATALOGUE` (tests).

    Returns:
        The path of the map's world file.

    Raises:
        ValueError: unknown map name.
        MapFetchError: network error (with an offline hint), HTTP error, oversized download or
            checksum mismatch. Nothing partial is left under a final file name.
    """
    entry = get_catalogue_map(name, catalogue)
    dest = Path(dest_dir) if dest_dir is not None else maps_cache_dir() / entry.name
    with _destination(dest):
        for file in entry.files:
            target = dest / file.filename
            if _is_current(target, file):
                continue
            url = entry.url(file, base_url)
            if url is None:
                _write_sidecar(file, target)
            else:
                _download_file(url, file, target, entry, timeout_s)
    return dest / entry.world_file.filename


def copy_map(
    name: str,
    source_dir: Path,
    dest_dir: Path | None = None,
    *,
    catalogue: Mapping[str, CatalogueMap] | None = None,
) -> Path:
    """Copy catalogue map ``name`` from a local directory, verifying the checksums.

    Each file is looked for in ``SOURCE/NAME/``, in the shared-collection layout
    (``SOURCE/turtlebot3/world/`` for ``tb3-world``) and in ``SOURCE/`` itself. Sidecar yamls
    (ours, no upstream copy) are always written from the package.

    Returns:
        The path of the map's world file.

    Raises:
        ValueError: unknown map name.
        FileNotFoundError: ``source_dir`` does not exist, or an upstream file is not in it.
        MapFetchError: a file's checksum or size does not match the catalogue.
    """
    entry = get_catalogue_map(name, catalogue)
    source_dir = Path(source_dir)
    if not source_dir.is_dir():
        raise FileNotFoundError(f"--from directory not found: {source_dir}")
    dest = Path(dest_dir) if dest_dir is not None else maps_cache_dir() / entry.name
    roots = candidate_dirs(entry, source_dir, flat=True)
    with _destination(dest):
        _copy_files(entry, roots, dest)
    return dest / entry.world_file.filename


def _copy_files(entry: CatalogueMap, roots: list[Path], dest: Path) -> None:
    for file in entry.files:
        target = dest / file.filename
        if file.upstream_path is None:  # our sidecar: the package's copy is the reference
            if not _is_current(target, file):
                _write_sidecar(file, target)
            continue
        found = next((d / file.filename for d in roots if (d / file.filename).is_file()), None)
        if found is not None and found.resolve() == target.resolve():
            if not _is_current(target, file):
                raise MapFetchError(f"{target}: sha256 does not match the catalogue")
            continue
        if found is None:
            raise FileNotFoundError(
                f"{file.filename} of map {entry.name!r} not found in {', '.join(str(d) for d in roots)}"
            )
        if found.stat().st_size > _limit(file):
            raise MapFetchError(
                f"{found}: {found.stat().st_size} bytes, catalogue size {file.size_bytes}; refused"
            )
        with open(found, "rb") as src:
            _copy_checked(src.read, file, target, str(found))


__all__ = ["MAX_DOWNLOAD_BYTES", "MapFetchError", "copy_map", "download_map"]
