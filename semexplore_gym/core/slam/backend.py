"""The SLAM back end: keyframes, scan matching, loop closure, the pose graph and the map.

Each step :meth:`ScanSlam.update` takes the odometry pose and the scan. Between keyframes the
estimate is the last keyframe's pose moved by the odometry since then. After
``keyframe_distance_m`` of travel or ``keyframe_angle_rad`` of turning the scan is matched to
the local map of the recent keyframes (:mod:`.matcher`; without the wall faces that look away
from the scan's sensor, which no LiDAR sees from behind), the keyframe is linked to the last one
by the match (or, when the match scores too low, by odometry alone), and an older keyframe
within ``loop_search_radius_m`` and far back in the chain is tried as a loop closure against
its own submap. A verified closure adds a robust edge and the pose graph is optimised
(:mod:`.pose_graph`); the map is then re-rendered from all keyframes at their new poses.
Otherwise the keyframe's scan is fused into the map incrementally.

Faults are counted, never silent: :attr:`ScanSlam.lost` (and :attr:`ScanSlam.lost_events`, how
often it became so) when matches keep scoring too low (a kidnapped robot, a scan unlike the
map), :attr:`ScanSlam.degenerate_matches` when a match pins the pose only across one direction
(a featureless corridor; see ``SlamParams.degenerate_sd_m``). :meth:`ScanSlam.kidnap` moves the
odometry's frame without telling the estimate, as a robot picked up and put down elsewhere.

A kidnapped robot is noticed from two signs together. Its scan *jumps*: the odometry says it
barely moved since the last scan, yet many beams changed by far more than that explains
(``scan_jump_share``, ``scan_jump_range_m``). And the next keyframe's match *collapses*: it
scores below ``match_score_threshold``, or below ``score_collapse_ratio`` of the median of the
recent well-matched keyframes (in a cluttered map the scan still fits somewhere near). Both
together: the back end is lost at once, and it freezes the local map from before the jump
(the *reference*). Until a later keyframe matches the reference again as well as the
keyframes before the jump matched, every keyframe is also matched to it and the back end stays
lost, however well the keyframes taken since, at the wrong place, match each other. Either
sign alone is no kidnap: a scan changes that much when a door or a teammate passes close, and
a match collapses for a keyframe when the robot turns into a new room. These checks only
judge: the estimate and the map are built as before.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from semexplore_gym.core.grid import GridGeometry, wrap_angle_rad
from semexplore_gym.core.mapping.occupancy_grid import MappingParams, OccupancyGrid
from semexplore_gym.core.slam.icp import local_normals, pair_residuals_m, refine_point_to_line
from semexplore_gym.core.slam.matcher import (
    MatchResult,
    build_likelihood_field,
    match_scan,
    scan_points,
    transform_points,
)
from semexplore_gym.core.slam.params import SlamParams
from semexplore_gym.core.slam.pose_graph import Edge, optimise

Pose = tuple[float, float, float]

#: The thresholds of ``SlamParams.known_when_seen``: a log-odds this close to 0 is UNKNOWN, any
#: other is FREE or OCCUPIED by its sign. A cell no beam touched is exactly 0; a touched one is a
#: sum of the two increments (multiples of 0.05 with the defaults), so one within this of 0 is a
#: cell whose hits and misses cancel, up to float32 rounding.
_SEEN_LOG_ODDS = 1e-4


def _worst_sd_m(match: MatchResult) -> float:
    """The position standard deviation of ``match`` along its worst-pinned direction."""
    values = np.linalg.eigvalsh(np.asarray(match.covariance)[:2, :2])
    return math.sqrt(max(float(values[-1]), 0.0))


def compose(a: Pose, b: Pose) -> Pose:
    """``a (+) b``: the pose ``b``, given in the frame of ``a``, in the world frame."""
    c, s = math.cos(a[2]), math.sin(a[2])
    return (a[0] + c * b[0] - s * b[1], a[1] + s * b[0] + c * b[1], wrap_angle_rad(a[2] + b[2]))


def relative(a: Pose, b: Pose) -> Pose:
    """``a^-1 (+) b``: the pose ``b`` in the frame of ``a``."""
    c, s = math.cos(a[2]), math.sin(a[2])
    dx, dy = b[0] - a[0], b[1] - a[1]
    return (c * dx + s * dy, -s * dx + c * dy, wrap_angle_rad(b[2] - a[2]))


class ScanSlam:
    """Keyframe SLAM on one robot's odometry and scans (see the module docstring).

    Args:
        params: The SLAM parameters.
        geometry: The map frame of the grid it builds.
        mapping: The occupancy update parameters of that grid (with
            ``params.known_when_seen``, its thresholds are Gmapping's rule instead).
        beam_angles_rad: ``(n,)`` beam angles of the scans, relative to the heading.
        max_range_m: The LiDAR's maximum range (returns at it are "no return").
        mount_xy_m: The sensor's offset from the robot centre, in the robot frame.
    """

    def __init__(
        self,
        params: SlamParams,
        geometry: GridGeometry,
        mapping: MappingParams,
        beam_angles_rad: np.ndarray,
        max_range_m: float,
        mount_xy_m: tuple[float, float] = (0.0, 0.0),
    ) -> None:
        self.params = params
        if params.known_when_seen:
            mapping = dataclasses.replace(
                mapping, free_threshold=-_SEEN_LOG_ODDS, occupied_threshold=_SEEN_LOG_ODDS
            )
        self.grid = OccupancyGrid(geometry, mapping)
        self._beams = np.asarray(beam_angles_rad, dtype=np.float64)
        self._max_range_m = float(max_range_m)
        self._mount = (float(mount_xy_m[0]), float(mount_xy_m[1]))
        self.reset((0.0, 0.0, 0.0), np.zeros(len(self._beams), dtype=np.float32))

    # ------------------------------------------------------------------ state
    def reset(self, pose: Pose, ranges_m: np.ndarray) -> None:
        """Start again at ``pose`` (the shared start pose) with its first scan fused."""
        self.grid.reset()
        self.keyframe_poses: list[Pose] = []
        self._ranges: list[np.ndarray] = []
        self._points: list[np.ndarray] = []
        self._normals: list[np.ndarray] = []
        # Each keyframe's end points and normals in the world frame at its pose (kept in step
        # with keyframe_poses: recomputed when an optimisation moves the poses).
        self._world_points: list[np.ndarray] = []
        self._world_normals: list[np.ndarray] = []
        self.edges: list[Edge] = []
        self.loop_closures = 0
        self.low_score_streak = 0
        self.lost_events = 0
        self.degenerate_matches = 0
        self.last_score = 1.0
        self._cooldown = 0
        self._reference: range | None = None
        self._reference_floor = 0.0
        self._good_scores: list[float] = []
        self._jump_pending = False
        self._last_odom: Pose = tuple(float(v) for v in pose)  # type: ignore[assignment]
        self._prev_odom = self._last_odom
        self._prev_ranges = np.array(ranges_m, dtype=np.float32)
        self.estimate: Pose = self._last_odom
        self._add_keyframe(self._last_odom, ranges_m)
        self._fuse(0)

    @property
    def lost(self) -> bool:
        """Whether the last ``lost_after_keyframes`` keyframes all matched below the threshold."""
        return self.low_score_streak >= self.params.lost_after_keyframes

    def kidnap(self, odom_pose: Pose) -> None:
        """The robot was carried elsewhere: the odometry now reads ``odom_pose``, and the
        back end is told nothing else. Its estimate stays at the last keyframe, where it
        believes the robot is; only the odometry's jump is not taken as motion."""
        self._last_odom = tuple(float(v) for v in odom_pose)  # type: ignore[assignment]
        self._prev_odom = self._last_odom  # the wheels did not turn: odometry saw no motion
        self.estimate = self.keyframe_poses[-1]

    def _add_keyframe(self, pose: Pose, ranges_m: np.ndarray) -> None:
        ranges = np.array(ranges_m, dtype=np.float32)
        self.keyframe_poses.append(pose)
        self._ranges.append(ranges)
        points = scan_points(ranges, self._beams, self._max_range_m, self._mount)
        self._points.append(points)
        normals = local_normals(points)
        # Oriented towards the sensor that saw them: the side of the wall that faces it.
        away = np.sum(normals * (np.asarray(self._mount) - points), axis=1) < 0
        normals[away] *= -1.0
        self._normals.append(normals)
        self._world_points.append(transform_points(points, pose))
        self._world_normals.append(transform_points(self._normals[-1], (0.0, 0.0, pose[2])))

    def _fuse(self, k: int) -> None:
        sx, sy, syaw = compose(self.keyframe_poses[k], (*self._mount, 0.0))
        self.grid.integrate_scan(sx, sy, syaw, self._beams, self._ranges[k], self._max_range_m)

    # ------------------------------------------------------------------- step
    def update(self, odom_pose: Pose, ranges_m: np.ndarray) -> Pose:
        """One step: the odometry pose and the scan taken there. Returns the new estimate."""
        if self._scan_jumped(odom_pose, ranges_m):
            self._jump_pending = True
        self._prev_odom = tuple(float(v) for v in odom_pose)  # type: ignore[assignment]
        self._prev_ranges = np.array(ranges_m, dtype=np.float32)
        delta = relative(self._last_odom, tuple(float(v) for v in odom_pose))  # type: ignore[arg-type]
        prediction = compose(self.keyframe_poses[-1], delta)
        p = self.params
        if (
            math.hypot(delta[0], delta[1]) < p.keyframe_distance_m
            and abs(delta[2]) < p.keyframe_angle_rad
        ):
            self.estimate = prediction
            return prediction
        self._last_odom = tuple(float(v) for v in odom_pose)  # type: ignore[assignment]
        points = scan_points(np.asarray(ranges_m), self._beams, self._max_range_m, self._mount)
        pose, cov, trusted = self._track(prediction, points, delta)
        self._judge(self._agrees_with_reference(trusted, prediction, points))
        n = len(self.keyframe_poses)
        self.edges.append(Edge(n - 1, n, relative(self.keyframe_poses[-1], pose), cov))
        self._add_keyframe(pose, ranges_m)
        if not self._close_loop(points):
            self._fuse(n)
        self.estimate = self.keyframe_poses[-1]
        return self.estimate

    def _judge(self, good: bool) -> None:
        """Count a keyframe towards the lost judgement (``good``: its match was trusted)."""
        if good:
            self.low_score_streak = 0
            return
        self.low_score_streak += 1
        if self.low_score_streak == self.params.lost_after_keyframes:
            self.lost_events += 1

    def _scan_jumped(self, odom_pose: Pose, ranges_m: np.ndarray) -> bool:
        """Whether the scan changed far more than the odometry's motion since the last scan
        explains (see the module docstring)."""
        p = self.params
        d = relative(self._prev_odom, tuple(float(v) for v in odom_pose))  # type: ignore[arg-type]
        n = len(self._beams)
        step = float(self._beams[1] - self._beams[0]) if n > 1 else 0.0
        full_circle = step > 0 and abs(n * step - 2 * math.pi) < 1e-3
        if p.scan_jump_share >= 1.0 or math.hypot(d[0], d[1]) > 0.2 or step <= 0:
            return False
        if not full_circle and abs(d[2]) > 0.35:
            return False
        k = int(round(d[2] / step))
        before = np.roll(self._prev_ranges, -k)  # beam i now looks where beam i + k looked
        now = np.asarray(ranges_m, dtype=np.float32)
        valid = (now > 0) & (before > 0)
        if k != 0 and not full_circle:  # no wrap-around
            if k > 0:
                valid[n - k :] = False
            else:
                valid[:-k] = False
        n_valid = int(np.count_nonzero(valid))
        if n_valid < 30:
            return False
        changed = np.count_nonzero(valid & (np.abs(now - before) > p.scan_jump_range_m))
        return bool(changed > p.scan_jump_share * n_valid)

    def _freeze_reference(self, floor: float, lost_now: bool = False) -> None:
        """Freeze the recent keyframes as the reference later ones must match at ``floor``;
        ``lost_now``: the back end is lost at once (a jump), not after more failures."""
        p = self.params
        n = len(self.keyframe_poses)
        self._reference = range(max(0, n - p.submap_keyframes), n)
        self._reference_floor = max(floor, p.match_score_threshold)
        if lost_now and not self.lost:
            self.low_score_streak = p.lost_after_keyframes
            self.lost_events += 1

    def _agrees_with_reference(self, trusted: bool, prediction: Pose, points: np.ndarray) -> bool:
        """Whether the new keyframe counts as well matched (see the module docstring): its
        match was trusted and, after a kidnap, its scan also matches the frozen reference as
        well as the keyframes before the kidnap matched. A scan jump followed by a collapsed
        match here is a kidnap: lost at once."""
        p = self.params
        jumped, self._jump_pending = self._jump_pending, False
        if self._reference is None:
            median = self._good_median()
            if trusted and self.last_score >= p.score_collapse_ratio * median:
                self._good_scores = [
                    *self._good_scores[-(p.submap_keyframes - 1) :],
                    self.last_score,
                ]
                return True
            if jumped:
                self._freeze_reference(median, lost_now=True)
                return False
            return trusted
        match, _ = self._match(self._reference, points, prediction, p.search_xy_m)
        if len(points) >= 10 and match.score >= self._reference_floor:
            self._reference = None
            return True
        return False  # still lost; a jump now changes nothing: the reference stays as it was

    def _good_median(self) -> float:
        """The median score of the recent well-matched keyframes (0 before three)."""
        if len(self._good_scores) < 3:
            return 0.0
        return float(np.median(self._good_scores))

    def _track(
        self, prediction: Pose, points: np.ndarray, delta: Pose
    ) -> tuple[Pose, np.ndarray, bool]:
        """The keyframe pose, its edge covariance and whether the match was trusted: the scan
        match to the recent keyframes, or the odometry prediction when it is not trusted."""
        p = self.params
        first = max(0, len(self.keyframe_poses) - p.submap_keyframes)
        keyframes = range(first, len(self.keyframe_poses))
        match, _ = self._match(
            keyframes, points, prediction, p.search_xy_m, p.match_score_threshold
        )
        self.last_score = match.score
        if len(points) >= 10 and match.score >= p.match_score_threshold:
            return self._unless_degenerate(match, prediction), match.covariance, True
        trans = math.hypot(delta[0], delta[1])
        sd_xy, sd_yaw = 0.02 + 0.2 * trans, 0.02 + 0.2 * abs(delta[2])
        return prediction, np.diag([sd_xy**2, sd_xy**2, sd_yaw**2]), False

    def _unless_degenerate(self, match: MatchResult, prediction: Pose) -> Pose:
        """The match's pose; for a degenerate match (its worst position standard deviation
        above ``degenerate_sd_m``: counted) the prediction along that worst direction."""
        values, vectors = np.linalg.eigh(np.asarray(match.covariance)[:2, :2])
        if math.sqrt(max(float(values[-1]), 0.0)) <= self.params.degenerate_sd_m:
            return match.pose
        self.degenerate_matches += 1
        axis = vectors[:, -1]
        shift = np.array(match.pose[:2]) - np.array(prediction[:2])
        xy = np.array(match.pose[:2]) - axis * float(axis @ shift)
        return (float(xy[0]), float(xy[1]), match.pose[2])

    def _match(
        self,
        keyframes: range,
        points: np.ndarray,
        prediction: Pose,
        search_xy_m: float,
        refine_from: float = math.inf,
        fit: bool = False,
    ) -> tuple[MatchResult, float]:
        """The scan ``points`` matched to the ``keyframes``' scans around ``prediction``; a
        match scoring at least ``refine_from`` is refined by ICP (the others are not used
        for a pose). With it, when ``fit`` is asked for, the 90th percentile of the refined
        scan's point-to-line distances (m); infinite when ICP did not refine the match (and
        0 when it did and ``fit`` was not asked for)."""
        p = self.params
        cloud, normals = self._submap(keyframes, prediction)
        field = build_likelihood_field(cloud, p.match_resolution_m, p.likelihood_sigma_m)
        match = match_scan(field, points, prediction, search_xy_m, p.search_yaw_rad)
        if (
            p.refine_max_pair_m <= 0
            or match.score < refine_from
            or min(len(cloud), len(points)) < 10
        ):
            return match, math.inf
        pose, pairs = refine_point_to_line(
            field, cloud, normals, points, match.pose, max_pair_m=p.refine_max_pair_m
        )
        # The refinement polishes the correlative basin; a jump out of it is not trusted: more
        # than one coarse lattice step in x-y (2 cells) or two in yaw (the matcher's yaw step
        # is one cell's edge in radians: it moves a point 2 m off by the x-y step).
        moved_m = math.hypot(pose[0] - match.pose[0], pose[1] - match.pose[1])
        turned_rad = abs(wrap_angle_rad(pose[2] - match.pose[2]))
        step_xy_m = 2.0 * p.match_resolution_m
        step_yaw_rad = step_xy_m / 2.0
        if pairs == 0 or moved_m > step_xy_m or turned_rad > 2.0 * step_yaw_rad:
            return match, math.inf
        fit_m = 0.0
        if fit:
            residuals = pair_residuals_m(field, cloud, normals, points, pose, p.refine_max_pair_m)
            fit_m = float(np.quantile(residuals, 0.9)) if len(residuals) else math.inf
        return MatchResult(pose, match.score, match.covariance), fit_m

    def _submap(self, keyframes: range, prediction: Pose) -> tuple[np.ndarray, np.ndarray]:
        """The ``keyframes``' end points and normals (world frame) a scan taken at
        ``prediction`` is matched to: without the points on faces that look away from its
        sensor (``SlamParams.backface_margin_m``)."""
        if not keyframes:
            return np.zeros((0, 2)), np.zeros((0, 2))
        cloud = np.concatenate([self._world_points[k] for k in keyframes])
        normals = np.concatenate([self._world_normals[k] for k in keyframes])
        margin = self.params.backface_margin_m
        if margin <= 0:
            return cloud, normals
        sensor = compose(prediction, (*self._mount, 0.0))
        # A point without a line (zero normal) has facing 0 and stays.
        facing = np.sum(normals * (np.asarray(sensor[:2]) - cloud), axis=1)
        keep = facing >= -margin
        return cloud[keep], normals[keep]

    def _close_loop(self, points: np.ndarray) -> bool:
        """Try a loop closure from the newest keyframe; True when one re-rendered the map."""
        p = self.params
        n = len(self.keyframe_poses) - 1
        if self._cooldown > 0:
            self._cooldown -= 1
            return False
        last_old = n - p.loop_min_gap_keyframes
        if last_old < 0 or len(points) < 10:
            return False
        here = np.asarray(self.keyframe_poses[n][:2])
        old = np.asarray([kp[:2] for kp in self.keyframe_poses[: last_old + 1]])
        dist = np.hypot(*(old - here).T)
        i = int(np.argmin(dist))
        if dist[i] > p.loop_search_radius_m:
            return False
        half = p.submap_keyframes // 2
        sub = range(max(0, i - half), min(last_old + 1, i + half + 1))
        match, fit_m = self._match(
            sub,
            points,
            self.keyframe_poses[n],
            p.loop_search_xy_m,
            p.loop_score_threshold,
            fit=p.loop_max_residual_m > 0,  # the residuals only when the check is on
        )
        if match.score < p.loop_score_threshold:
            return False
        if p.refine_max_pair_m > 0 and 0 < p.loop_max_residual_m < fit_m:
            return False  # not refined, or the refined scan lies beside the old walls
        if _worst_sd_m(match) > p.degenerate_sd_m:
            return False  # a closure the scan pins only across one direction: not trusted
        delta = relative(self.keyframe_poses[i], match.pose)
        self.edges.append(Edge(i, n, delta, match.covariance, robust=True))
        self.loop_closures += 1
        self._cooldown = p.submap_keyframes
        new = optimise(np.asarray(self.keyframe_poses), self.edges)
        moved = float(np.abs(new - np.asarray(self.keyframe_poses))[:, :2].max())
        self.keyframe_poses = [(float(x), float(y), wrap_angle_rad(float(t))) for x, y, t in new]
        self._world_points = [
            transform_points(pts, kp)
            for pts, kp in zip(self._points, self.keyframe_poses, strict=True)
        ]
        self._world_normals = [
            transform_points(nrm, (0.0, 0.0, kp[2]))
            for nrm, kp in zip(self._normals, self.keyframe_poses, strict=True)
        ]
        if moved < 0.25 * self.grid.geometry.resolution_m:
            return False
        self.grid.reset()
        for k in range(n + 1):
            self._fuse(k)
        return True
