"""Parameters of :func:`~semexplore_gym.core.topometric.segment_map` (lengths in metres)."""

from __future__ import annotations

import math
from dataclasses import dataclass, fields


@dataclass(frozen=True)
class SegmentationParams:
    """Tuning of the semantic topometric segmentation.

    The robot clearance is an argument of :func:`segment_map`, not a parameter here; several
    defaults below are derived from it when left at ``None``.

    Attributes:
        max_speckle_area_m2: Occupied blobs up to this area whose neighbours are all free are
            erased (SLAM speckles, 1-4 cells at 0.05 m). 0 disables.
        max_hole_area_m2: Unknown blobs up to this area not touching the map border are closed:
            made free when surrounded by free cells, occupied when they touch a wall. 0 disables.
        spur_ratio: A skeleton branch from a junction to an end is pruned when it protrudes
            less than ``spur_ratio * r + min_dead_end_depth_m`` beyond the junction's inscribed
            circle of radius ``r`` (room corners protrude about ``0.41 r``). Dimensionless.
        min_dead_end_depth_m: See ``spur_ratio``: the smallest dead end (niche) kept.
        neck_ratio: A branch is also kept when it has a corridor stretch: clearance within 25 %
            of its maximum ``m <= neck_ratio * r`` over at least ``min_dead_end_depth_m + m/2``
            (a dead-end corridor or closet off a big room; a room corner, whose clearance
            changes steadily along its branch, has none). Dimensionless.
        core_radius_ratio: An intersection's core is the inscribed circle of each of its
            junctions scaled by this factor; openings are searched outside it. Junctions whose
            cores overlap along the skeleton are merged into one intersection. Dimensionless.
        opening_distance_weight: Openings slide outwards from the core to the narrowest point
            of the branch, minimising ``width + weight * distance``. Dimensionless.
        min_pathway_length_m: Two junctions closer (along the skeleton, outside their cores)
            than this are merged into one intersection.
        min_frontier_width_m: A frontier (reachable free cells next to unknown) must be at
            least this wide; ``None`` means the robot width ``2 * clearance``.
        min_frontier_depth_m: The unknown space behind a frontier must be at least this deep
            (rejects unknown slivers along walls, where the robot could not go); ``None`` means
            the robot width ``2 * clearance``.
        cover_depth_m: How far beyond the robot's configuration space the per-cell area raster
            extends (so room corners and wall-side cells get an area); ``None`` means
            ``2 * clearance + 2 cells``.
        path_tolerance_m: Paths follow the area's skeleton and are simplified (Douglas-Peucker)
            to within this distance of it; every simplified segment stays in the configuration
            space of its area (0 keeps every cell).
        match_radius_m: Areas without cells (frontier pathways on an intersection wall) keep
            their id across updates when their frontier moved less than this.
        chord_search_deg: An opening is the shortest wall-to-wall chord through its skeleton
            point within this angle of the skeleton's normal.
        max_prune_iterations: Rounds of spur pruning (each round can expose new spurs).
        keep_debug: Store skeleton and configuration-space cells in ``TopometricMap.extras``.
    """

    max_speckle_area_m2: float = 0.01
    max_hole_area_m2: float = 0.1
    spur_ratio: float = 0.5
    min_dead_end_depth_m: float = 0.25
    neck_ratio: float = 0.7
    core_radius_ratio: float = 1.0
    opening_distance_weight: float = 0.5
    min_pathway_length_m: float = 0.1
    min_frontier_width_m: float | None = None
    min_frontier_depth_m: float | None = None
    cover_depth_m: float | None = None
    path_tolerance_m: float = 0.1
    match_radius_m: float = 0.5
    chord_search_deg: float = 40.0
    max_prune_iterations: int = 8
    keep_debug: bool = False

    def __post_init__(self) -> None:
        for f in fields(self):
            v = getattr(self, f.name)
            if f.name == "keep_debug":
                if not isinstance(v, bool):
                    raise TypeError(f"SegmentationParams.keep_debug must be a bool, got {v!r}")
                continue
            if v is None and f.name in (
                "min_frontier_width_m",
                "min_frontier_depth_m",
                "cover_depth_m",
            ):
                continue
            if isinstance(v, bool) or not isinstance(v, (int, float)):
                raise TypeError(f"SegmentationParams.{f.name} must be a number, got {v!r}")
            if not math.isfinite(v):
                raise ValueError(f"SegmentationParams.{f.name} must be finite, got {v!r}")
            if v < 0:
                raise ValueError(f"SegmentationParams.{f.name} must be >= 0, got {v!r}")
        if self.core_radius_ratio <= 0:
            raise ValueError(
                f"SegmentationParams.core_radius_ratio must be > 0, got {self.core_radius_ratio!r}"
            )
        if not 0 <= self.chord_search_deg <= 80:
            raise ValueError(
                f"SegmentationParams.chord_search_deg must be in [0, 80], got {self.chord_search_deg!r}"
            )
        if int(self.max_prune_iterations) != self.max_prune_iterations:
            raise ValueError(
                f"SegmentationParams.max_prune_iterations must be an integer, got {self.max_prune_iterations!r}"
            )

    @classmethod
    def from_dict(cls, d: dict) -> SegmentationParams:
        """Build from a mapping, rejecting unknown keys by name."""
        known = {f.name for f in fields(cls)}
        unknown = sorted(set(d) - known)
        if unknown:
            raise ValueError(
                f"unknown SegmentationParams key(s): {', '.join(unknown)}; known: {', '.join(sorted(known))}"
            )
        return cls(**d)
