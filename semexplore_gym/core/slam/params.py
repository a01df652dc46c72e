"""Parameters of the SLAM back end (the env's ``slam:`` config section)."""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

#: Inclusive bounds of each numeric parameter: (low, high).
_BOUNDS: dict[str, tuple[float, float]] = {
    "keyframe_distance_m": (0.01, 5.0),
    "keyframe_angle_rad": (0.01, math.pi),
    "search_xy_m": (0.0, 2.0),
    "search_yaw_rad": (0.0, math.pi),
    "match_resolution_m": (0.005, 0.5),
    "likelihood_sigma_m": (0.005, 1.0),
    "submap_keyframes": (1, 1000),
    "match_score_threshold": (0.0, 1.0),
    "loop_search_radius_m": (0.0, 50.0),
    "loop_min_gap_keyframes": (1, 100000),
    "loop_search_xy_m": (0.0, 5.0),
    "loop_score_threshold": (0.0, 1.0),
    "lost_after_keyframes": (1, 100000),
    "degenerate_sd_m": (0.0, 10.0),
    "score_collapse_ratio": (0.0, 1.0),
    "scan_jump_share": (0.05, 1.0),
    "scan_jump_range_m": (0.01, 10.0),
    "refine_max_pair_m": (0.0, 1.0),
    "loop_max_residual_m": (0.0, 1.0),
    "backface_margin_m": (0.0, 1.0),
}
_INTS = ("submap_keyframes", "loop_min_gap_keyframes", "lost_after_keyframes")
_BOOLS = ("enabled", "known_when_seen")


@dataclass(frozen=True)
class SlamParams:
    """Scan matching, keyframes, loop closure and the lost judgement of the SLAM mode.

    Attributes:
        enabled: Build the observed map with SLAM (the mapping mode ``slam``); off: the map is
            built on the (possibly drifting) odometry pose as before.
        keyframe_distance_m: A new keyframe (scan match and map update) after this much travel.
        keyframe_angle_rad: ... or after this much turning since the last keyframe.
        search_xy_m: Half-width of the scan matcher's x and y search around the odometry
            prediction.
        search_yaw_rad: Half-width of its yaw search.
        match_resolution_m: Cell edge of the matcher's likelihood field (the finest step).
        likelihood_sigma_m: Standard deviation of the likelihood field around occupied points.
        submap_keyframes: How many recent keyframes form the local map a scan is matched to.
        match_score_threshold: A scan match scoring below this (mean likelihood of the
            scan's end points, 0..1) is not trusted: odometry alone links the keyframe.
        loop_search_radius_m: Older keyframes this close to the estimate are loop candidates.
        loop_min_gap_keyframes: ... when at least this many keyframes back in the chain.
        loop_search_xy_m: Half-width of the x and y search of a loop-closure match.
        loop_score_threshold: A loop-closure match must score at least this.
        lost_after_keyframes: The back end reports itself lost after this many keyframes in a
            row whose match scored below ``match_score_threshold``.
        degenerate_sd_m: A trusted match whose position standard deviation along its worst
            direction (from the matcher's covariance) exceeds this is *degenerate*: the scan
            pins the pose only across that direction (a featureless corridor). It is counted,
            and along that direction the keyframe keeps the odometry prediction.
        score_collapse_ratio: After a scan jump (``scan_jump_share``), a keyframe match
            scoring below this share of the median score of the recent well-matched
            keyframes has *collapsed* (a kidnapped robot's scan matched somewhere near that
            it is not): the back end is lost (see :mod:`~semexplore_gym.core.slam.backend`).
            0: only a match below ``match_score_threshold`` collapses.
        scan_jump_share: When the odometry says the robot barely moved since the last scan
            (under 0.2 m; any turn for a LiDAR that sees all around, else under 0.35 rad)
            but more than this share of the beams valid in both scans changed by more than
            ``scan_jump_range_m``, the scan *jumped*; a collapsed match at the next keyframe
            then means the robot was carried away (kidnapped): the back end reports itself
            lost at once. 1 turns the kidnap check off.
        scan_jump_range_m: A beam whose range changed by more than this has *changed*.
        refine_max_pair_m: Each match (tracking and loop closure) is refined by point-to-line
            ICP (:mod:`~semexplore_gym.core.slam.icp`), pairing a scan point with a submap
            line no farther than this; 0 keeps the correlative match as it is.
        loop_max_residual_m: When above 0 (and the refinement is on), a loop closure is
            taken only when ICP refined its match and the 90th percentile of the scan points'
            distances to the submap's lines is at most this (a match one yaw step off, which
            the refinement did not pull back, lays its far points centimetres beside the
            walls and bends everything it joins). Off (0) by default: on the suites it did
            not lower the offices' error and it let a warehouse map diverge (docs/slam.md).
        backface_margin_m: When above 0, a match ignores the submap's points on wall faces
            that look away from the sensor: a point is dropped when the sensor, at the
            prediction, lies more than this behind the line of its face (each keyframe's
            normals point towards the sensor that saw them). A LiDAR never sees a face from
            behind; without this, a scan of a wall seen from a room can lie on the same wall's
            corridor face seen earlier, one wall thickness off. 0 keeps every point.
        known_when_seen: Gmapping's map rule for the map SLAM renders: every cell a beam
            touched is known, OCCUPIED when its log-odds is above 0 (a hit share above about a
            third of the beams that touched it), FREE below; only cells no beam touched (and
            the rare cell whose hits and misses cancel out) stay UNKNOWN. Off: the mapping's
            thresholds (``mapping.free_threshold``, ``mapping.occupied_threshold``) as in the
            perfect map, which leave a cell of conflicting evidence UNKNOWN: a wall seen from
            two poses a cell apart then leaves unknown cells beside free ones, frontiers no
            scan can clear.
    """

    enabled: bool = False
    keyframe_distance_m: float = 0.25
    keyframe_angle_rad: float = 0.25
    search_xy_m: float = 0.2
    search_yaw_rad: float = 0.3
    match_resolution_m: float = 0.025
    likelihood_sigma_m: float = 0.04
    submap_keyframes: int = 12
    match_score_threshold: float = 0.35
    loop_search_radius_m: float = 1.5
    loop_min_gap_keyframes: int = 40
    loop_search_xy_m: float = 0.5
    loop_score_threshold: float = 0.6
    lost_after_keyframes: int = 5
    degenerate_sd_m: float = 0.08
    score_collapse_ratio: float = 0.75
    scan_jump_share: float = 0.3
    scan_jump_range_m: float = 0.5
    refine_max_pair_m: float = 0.08
    loop_max_residual_m: float = 0.0
    backface_margin_m: float = 0.05
    known_when_seen: bool = False

    def __post_init__(self) -> None:
        for f in fields(self):
            v = getattr(self, f.name)
            if f.name in _BOOLS:
                if not isinstance(v, bool):
                    raise ValueError(f"slam.{f.name} must be true or false, got {v!r}")
                continue
            ok_type = isinstance(v, int) if f.name in _INTS else isinstance(v, (int, float))
            lo, hi = _BOUNDS[f.name]
            if isinstance(v, bool) or not ok_type or not (math.isfinite(v) and lo <= v <= hi):
                kind = "an integer" if f.name in _INTS else "a number"
                raise ValueError(f"slam.{f.name} must be {kind} in [{lo:g}, {hi:g}], got {v!r}")
