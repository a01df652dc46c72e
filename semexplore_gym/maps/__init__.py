"""Fetching catalogue maps into the map cache (network and file I/O; the catalogue itself is
:mod:`semexplore_gym.core.worlds.catalogue`). Used by ``semexplore maps``."""

from semexplore_gym.maps.download import (
    MAX_DOWNLOAD_BYTES,
    MapFetchError,
    copy_map,
    download_map,
)

__all__ = ["MAX_DOWNLOAD_BYTES", "MapFetchError", "copy_map", "download_map"]
