"""Parameters of the egocentric observation (:mod:`.egocentric`): crop, channels, scan bins."""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any

#: Number of scalar features in the ``features`` entry.
N_FEATURES = 3

#: Image channels an :class:`~.egocentric.EgocentricEncoder` can produce (see
#: :mod:`.egocentric`).
CHANNELS: tuple[str, ...] = ("occupancy", "frontier_distance", "trail")


@dataclass(frozen=True)
class EgocentricParams:
    """How the egocentric observation is built.

    Attributes:
        crop_cells: Side of the square map crop, in crop cells (the image is crop x crop).
        crop_resolution_m: Side of one crop cell in metres; None uses the map resolution.
            When coarser than the map, each crop cell takes the minimum over the map cells it
            covers (OCCUPIED < UNKNOWN < FREE), so thin walls are never lost.
        n_scan_bins: Number of angular bins the scan is min-pooled into; must divide the
            number of beams.
        channels: Image channels, in order (names from :data:`CHANNELS`, no repeats).
        frontier_clearance_m: ``frontier_distance`` paths keep at least this far from walls.
        distance_scale_per_m: ``frontier_distance`` grey levels per metre of path length.
        trail_radius_m: Radius of the ``trail`` disc stamped round every pose.
        scan_bins_centred: Centre scan bin 0 on the heading (beams ``-k//2 .. k - k//2 - 1``
            for ``k`` beams per bin) instead of starting it there. With an odd ``k`` the pooled
            scan then mirrors exactly under a left-right flip (bin ``b`` <-> bin ``-b``).
        pool_map: Min-pool the map to the crop resolution first (blocks of ``f x f`` map cells,
            ``f = crop_resolution_m / map resolution``, which must be a whole number; cells
            beyond the map read UNKNOWN), then search the frontier field, stamp the trail and
            sample each crop cell once on that coarser grid. About 2.5x cheaper than sampling
            ``f x f`` points of the rotated full-resolution map per crop cell (False), and a
            slightly different image: a crop cell is the minimum over the axis-aligned block its
            centre falls in. Models record the setting; the default (False) is what models
            trained before it used.
    """

    crop_cells: int = 64
    crop_resolution_m: float | None = 0.1
    n_scan_bins: int = 60
    channels: tuple[str, ...] = ("occupancy",)
    frontier_clearance_m: float = 0.1
    distance_scale_per_m: float = 20.0
    trail_radius_m: float = 0.1
    scan_bins_centred: bool = False
    pool_map: bool = False

    def __post_init__(self) -> None:
        if (
            not isinstance(self.crop_cells, int)
            or isinstance(self.crop_cells, bool)
            or not 8 <= self.crop_cells <= 512
        ):
            raise ValueError(f"crop_cells must be an integer in [8, 512], got {self.crop_cells!r}")
        if self.crop_resolution_m is not None and not (
            isinstance(self.crop_resolution_m, (int, float))
            and math.isfinite(self.crop_resolution_m)
            and self.crop_resolution_m > 0
        ):
            raise ValueError(
                f"crop_resolution_m must be a positive number or None, got {self.crop_resolution_m!r}"
            )
        if (
            not isinstance(self.n_scan_bins, int)
            or isinstance(self.n_scan_bins, bool)
            or self.n_scan_bins < 1
        ):
            raise ValueError(f"n_scan_bins must be a positive integer, got {self.n_scan_bins!r}")
        if isinstance(self.channels, str) or not isinstance(self.channels, (tuple, list)):
            raise ValueError(f"channels must be a tuple of channel names, got {self.channels!r}")
        # Lists arrive from YAML/JSON; store a tuple so the parameters stay hashable.
        object.__setattr__(self, "channels", tuple(self.channels))
        bad = [c for c in self.channels if c not in CHANNELS]
        if bad or not self.channels or len(set(self.channels)) != len(self.channels):
            raise ValueError(
                f"channels must be distinct names from {list(CHANNELS)}, got {list(self.channels)}"
            )
        for name in ("frontier_clearance_m", "distance_scale_per_m", "trail_radius_m"):
            v = getattr(self, name)
            if not (isinstance(v, (int, float)) and math.isfinite(v) and v >= 0):
                raise ValueError(f"{name} must be a finite number >= 0, got {v!r}")
        if not isinstance(self.scan_bins_centred, bool):
            raise ValueError(f"scan_bins_centred must be a bool, got {self.scan_bins_centred!r}")
        if not isinstance(self.pool_map, bool):
            raise ValueError(f"pool_map must be a bool, got {self.pool_map!r}")
        if self.pool_map and self.crop_resolution_m is None:
            raise ValueError("pool_map needs crop_resolution_m (a multiple of the map resolution)")

    @property
    def n_channels(self) -> int:
        return len(self.channels)

    def to_dict(self) -> dict[str, Any]:
        d = dataclasses.asdict(self)
        d["channels"] = list(self.channels)
        return d

    @classmethod
    def from_dict(cls, d: dict[str, Any] | None) -> EgocentricParams:
        d = dict(d or {})
        names = {f.name for f in dataclasses.fields(cls)}
        unknown = sorted(set(d) - names)
        if unknown:
            raise ValueError(f"unknown egocentric parameter(s) {unknown}; valid: {sorted(names)}")
        return cls(**d)
