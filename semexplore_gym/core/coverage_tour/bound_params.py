"""The knobs of the certified lower bound (:func:`.lower_bound.lower_bound`): any values give
a valid bound; they trade speed for tightness."""

from __future__ import annotations

import math
from dataclasses import dataclass


@dataclass(frozen=True)
class LowerBoundParams:
    """Knobs of :func:`lower_bound` (any values give a valid bound; they trade speed for tightness).

    Attributes:
        hop_cells: K of the K-hop metric (open space: exact along a row, about 0.93 of a
            diagonal at K = 8).
        hop_depth: A hop also counts a map cell size per breadth-first move beyond the first
            (step 2; round corners, where the straight gap cuts through the wall).
        distance_cell_factor: Distance cells are this many map cells on a side (one passes
            to a neighbour where their map cells do).
        group_scales: Group block sides to try, as multiples of the side whose square holds one
            more cell than the skip budget (the largest bound wins).
        max_groups: Most groups in the exact route (Held-Karp is 2^n n^2).
        pool_groups: Groups (farthest first) the route's groups are chosen from.
        leg_limit_share: Legs are searched only up to this share of the farthest entry
            piece's distance from the start (longer ones count as that much; 1: no limit).
        keep_share: Share of the well-filled groups, those seen from the fewest cells (on a
            sample every ``sample_stride`` cells), the pool is drawn from.
        entry_tile_m: Side of the tiles that split where a route can first enter a region
            into entry pieces (each piece a node of the route).
        max_entries: Most entry pieces per group (more are merged into the nearest).
        visibility_splits: Times a group's rectangle is quartered to find walls that block a
            cell's view of each quarter (0: one wall for the whole group).
        wall_corners: In the branch bound's regions (step 5), two walls that end at one
            shared point also block a view together: every segment that leaves the sector
            between them crosses one of them or the point, where the env's ray cast counts a
            hit (step 3).
        penetration_tolerance_m: How far the robot may press into a wall beyond its radius.
        mount_offset_m: LiDAR distance from the robot centre.
        branch_block_m: Side of the branch bound's groups (0: no branch bound).
        branch_nested: Seek each branch group's region within that of the block of twice
            the side holding it (the same or a smaller region, quicker; off: tested alone).
        grown_shares: Also route over groups grown from the branch bound's blocks
            (:mod:`.grown_groups`), each up to this share of the skip budget (one route per
            share; empty: none; needs ``branch_block_m > 0``).
        grown_growth: A grown group stops when the least a neighbouring block would widen
            its region exceeds this share of the region.
        branch_max_walls: A branch group with more walls than this within reach is taken as
            seen from every cell within reach, untested (rasterised maps: far quicker, looser).
        coverage_share: Coverage to reach; None for the env's ``coverage_goal``.
        threads: Threads for the independent searches (the bound is the same for any
            number; ``semexplore oracle`` uses one per CPU the process may use).
    """

    hop_cells: int = 8
    hop_depth: bool = True
    distance_cell_factor: int = 2
    group_scales: tuple[float, ...] = (1.0, 1.4)
    max_groups: int = 13
    pool_groups: int = 14
    keep_share: float = 0.5
    leg_limit_share: float = 0.6
    sample_stride: int = 4
    visibility_splits: int = 3
    wall_corners: bool = True
    entry_tile_m: float = 1.0
    max_entries: int = 3
    penetration_tolerance_m: float = 0.01
    mount_offset_m: float = 0.0
    branch_block_m: float = 0.2
    branch_nested: bool = False
    branch_max_walls: int = 400
    grown_shares: tuple[float, ...] = (1.0,)
    grown_growth: float = 0.3
    coverage_share: float | None = None
    threads: int = 1

    def __post_init__(self) -> None:
        for name, lo, hi in (
            ("hop_cells", 1, 64),
            ("distance_cell_factor", 1, 8),
            ("max_groups", 1, 18),
            ("pool_groups", 1, 64),
            ("sample_stride", 1, 16),
            ("visibility_splits", 0, 8),
            ("max_entries", 1, 16),
            ("branch_max_walls", 0, 1_000_000),
            ("threads", 1, 256),
        ):
            v = getattr(self, name)
            if not (isinstance(v, int) and lo <= v <= hi):
                raise ValueError(f"{name} must be an integer in {lo}..{hi}, got {v!r}")
        for name in ("hop_depth", "branch_nested", "wall_corners"):
            if not isinstance(getattr(self, name), bool):
                raise ValueError(f"{name} must be true or false, got {getattr(self, name)!r}")
        if not self.group_scales or not all(
            math.isfinite(g) and 0.05 <= g <= 20 for g in self.group_scales
        ):
            raise ValueError(f"group_scales must be in [0.05, 20], got {self.group_scales!r}")
        if not all(math.isfinite(g) and 0.05 <= g <= 20 for g in self.grown_shares):
            raise ValueError(f"grown_shares must be in [0.05, 20], got {self.grown_shares!r}")
        if not (math.isfinite(self.grown_growth) and 0 <= self.grown_growth <= 100):
            raise ValueError(f"grown_growth must be in [0, 100], got {self.grown_growth!r}")
        for name in ("penetration_tolerance_m", "mount_offset_m"):
            v = getattr(self, name)
            if not (math.isfinite(v) and 0 <= v <= 0.5):
                raise ValueError(f"{name} must be in [0, 0.5] m, got {v!r}")
        if not (math.isfinite(self.branch_block_m) and 0 <= self.branch_block_m <= 10):
            raise ValueError(f"branch_block_m must be in [0, 10] m, got {self.branch_block_m!r}")
        if not (math.isfinite(self.entry_tile_m) and 0.1 <= self.entry_tile_m <= 100):
            raise ValueError(f"entry_tile_m must be in [0.1, 100] m, got {self.entry_tile_m!r}")
        for name in ("keep_share", "leg_limit_share"):
            v = getattr(self, name)
            if not (math.isfinite(v) and 0 < v <= 1):
                raise ValueError(f"{name} must be in (0, 1], got {v!r}")
        share = self.coverage_share
        if share is not None and not (0 < share <= 1):
            raise ValueError(f"coverage_share must be in (0, 1], got {share!r}")
