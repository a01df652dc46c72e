"""The SLAM back end on a ring world driven around with drifting odometry."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from semexplore_gym.core.grid import OCCUPIED, UNKNOWN, GridGeometry
from semexplore_gym.core.mapping.occupancy_grid import MappingParams
from semexplore_gym.core.mapping.odometry import OdometryDrift, OdometryNoiseParams
from semexplore_gym.core.mapping.raycast import SegmentIndex, cast_scan
from semexplore_gym.core.slam.backend import ScanSlam
from semexplore_gym.core.slam.params import SlamParams

pytest.importorskip("gtsam")

BEAMS = np.arange(360) * (2 * math.pi / 360)
MAX_RANGE_M = 3.5


def _ring_segments() -> np.ndarray:
    """A square ring corridor 1.5 m wide around a 3 x 3 m block, with wall stubs as features."""
    walls = [
        [0, 0, 6, 0], [6, 0, 6, 6], [6, 6, 0, 6], [0, 6, 0, 0],
        [1.5, 1.5, 4.5, 1.5], [4.5, 1.5, 4.5, 4.5], [4.5, 4.5, 1.5, 4.5], [1.5, 4.5, 1.5, 1.5],
    ]  # fmt: skip
    for t in (1.3, 2.9, 4.1):
        walls += [[t, 0, t, 0.3], [6, t, 5.7, t], [6 - t, 6, 6 - t, 5.7], [0, 6 - t, 0.3, 6 - t]]
    walls += [
        [2.2, 1.5, 2.2, 1.25],
        [4.5, 3.6, 4.75, 3.6],
        [3.1, 4.5, 3.1, 4.8],
        [1.5, 2.5, 1.2, 2.5],
    ]
    return np.array(walls, dtype=np.float64)


def _drive(corners: list[tuple[float, float]], step_m: float = 0.044, turn_rad: float = 0.5):
    """True poses driving straight between ``corners``, turning in place at each one."""
    x, y = corners[0]
    yaw = math.atan2(corners[1][1] - y, corners[1][0] - x)
    poses = [(x, y, yaw)]
    for tx, ty in corners[1:]:
        goal = math.atan2(ty - y, tx - x)
        while abs(d := math.remainder(goal - yaw, 2 * math.pi)) > 1e-9:
            yaw += max(-turn_rad, min(turn_rad, d))
            poses.append((x, y, yaw))
        while (left := math.hypot(tx - x, ty - y)) > 1e-9:
            s = min(step_m, left)
            x, y = x + s * math.cos(yaw), y + s * math.sin(yaw)
            poses.append((x, y, yaw))
    return poses


def _run(params: SlamParams, seed: int):
    index = SegmentIndex(_ring_segments())
    geometry = GridGeometry.covering(0.0, 0.0, 6.0, 6.0, 0.05, 0.5)
    corners = [(0.75, 0.75), (5.25, 0.75), (5.25, 5.25), (0.75, 5.25), (0.75, 0.75), (3.5, 0.75)]
    truth = _drive(corners)
    rng = np.random.default_rng(seed)
    odom = OdometryDrift(OdometryNoiseParams(0.02, 0.02, 0.02, 0.02))
    odom.reset(truth[0])

    def scan(p):
        return np.minimum(cast_scan(index, p[0], p[1], p[2], BEAMS, MAX_RANGE_M), MAX_RANGE_M)

    slam = ScanSlam(params, geometry, MappingParams(), BEAMS, MAX_RANGE_M)
    slam.reset(truth[0], scan(truth[0]))
    at_keyframes = [truth[0]]
    for before, after in zip(truth[:-1], truth[1:], strict=True):
        est_odom = tuple(odom.update(before, after, rng))
        slam.update(est_odom, scan(after))
        if len(slam.keyframe_poses) > len(at_keyframes):
            at_keyframes.append(after)
    end = truth[-1]
    odom_err = math.hypot(odom.estimate[0] - end[0], odom.estimate[1] - end[1])
    d = np.asarray(slam.keyframe_poses)[:, :2] - np.asarray(at_keyframes)[:, :2]
    ate_m = float(np.sqrt(np.mean(np.sum(d**2, axis=1))))
    return slam, odom_err, ate_m


#: A coarse front end (a blurred field, a short local map, no ICP refinement): its drift
#: builds up around the ring, and only a loop closure takes it out.
COARSE = {
    "match_resolution_m": 0.05,
    "likelihood_sigma_m": 0.1,
    "submap_keyframes": 4,
    "refine_max_pair_m": 0.0,
}


@pytest.mark.parametrize("seed", [1, 4])
def test_a_loop_closure_is_found_and_reduces_the_error(seed: int) -> None:
    with_loops, odom_err, ate_m = _run(SlamParams(enabled=True, **COARSE), seed)
    no_loops = SlamParams(enabled=True, loop_search_radius_m=0.0, **COARSE)
    without, _, open_ate_m = _run(no_loops, seed)
    assert with_loops.loop_closures >= 1
    assert without.loop_closures == 0
    assert any(e.robust for e in with_loops.edges)
    assert ate_m < 0.7 * open_ate_m
    assert ate_m < odom_err / 5
    assert not with_loops.lost


def test_the_default_front_end_tracks_the_ring() -> None:
    slam, odom_err, ate_m = _run(SlamParams(enabled=True), seed=3)
    assert ate_m < 0.05 < odom_err
    assert slam.last_score > 0.8


@pytest.mark.parametrize("seed", [3, 5])
def test_icp_refinement_takes_out_the_correlative_lattice_error(seed: int) -> None:
    # Loop closures off: the chain's own error is what is compared.
    params = SlamParams(enabled=True, loop_search_radius_m=0.0)
    _, _, refined_m = _run(params, seed)
    _, _, lattice_m = _run(replace(params, refine_max_pair_m=0.0), seed)
    assert refined_m < 0.5 * lattice_m
    assert refined_m < 0.01


def test_a_closure_the_scan_pins_only_across_a_corridor_is_not_taken() -> None:
    # Up and down a bare corridor twice: every loop candidate's match slides along the axis.
    index = SegmentIndex(np.array([[-1, 0, 13, 0], [-1, 1.4, 13, 1.4]], dtype=np.float64))
    truth = _drive([(0.5, 0.7), (11.5, 0.7), (0.5, 0.7), (11.5, 0.7)])
    geometry = GridGeometry.covering(-1.0, -1.0, 13.0, 2.5, 0.05, 0.5)
    rng = np.random.default_rng(0)
    odom = OdometryDrift(OdometryNoiseParams(0.02, 0.02, 0.02, 0.02))
    odom.reset(truth[0])
    slam = ScanSlam(SlamParams(enabled=True), geometry, MappingParams(), BEAMS, MAX_RANGE_M)

    def scan(p):
        return np.minimum(cast_scan(index, p[0], p[1], p[2], BEAMS, MAX_RANGE_M), MAX_RANGE_M)

    slam.reset(truth[0], scan(truth[0]))
    for before, after in zip(truth[:-1], truth[1:], strict=True):
        slam.update(tuple(odom.update(before, after, rng)), scan(after))
    assert slam.degenerate_matches > 10  # the corridor is bare
    for e in slam.edges:
        if e.robust:  # any closure taken is pinned in both directions
            assert np.sqrt(np.linalg.eigvalsh(e.cov[:2, :2])[-1]) <= slam.params.degenerate_sd_m


def test_a_closure_whose_refined_scan_lies_beside_the_walls_is_not_taken(monkeypatch) -> None:
    # The loop search still finds its candidates; every fit is made to read 5 cm (a match a
    # yaw step off): with the check on none is taken, with it off (0, the default) they are,
    # as they are when ICP is off (nothing refined, nothing to check).
    from semexplore_gym.core.slam import backend

    checked = SlamParams(enabled=True, loop_max_residual_m=0.02)
    taken, _, _ = _run(checked, seed=1)
    assert taken.loop_closures >= 1
    monkeypatch.setattr(backend, "pair_residuals_m", lambda *a, **k: np.full(100, 0.05))
    refused, _, _ = _run(checked, seed=1)
    unchecked, _, _ = _run(SlamParams(enabled=True), seed=1)
    assert refused.loop_closures == 0
    assert unchecked.loop_closures == taken.loop_closures
    lattice, _, _ = _run(replace(checked, **COARSE), seed=1)
    assert lattice.loop_closures >= 1


def test_same_seed_same_map_bit_for_bit() -> None:
    a, _, _ = _run(SlamParams(enabled=True), seed=2)
    b, _, _ = _run(SlamParams(enabled=True), seed=2)
    assert np.array_equal(a.grid.log_odds, b.grid.log_odds)
    assert a.keyframe_poses == b.keyframe_poses


def test_the_back_end_says_it_is_lost_when_matches_keep_failing() -> None:
    params = SlamParams(enabled=True, lost_after_keyframes=3)
    geometry = GridGeometry.covering(-5.0, -5.0, 5.0, 5.0, 0.05, 0.5)
    slam = ScanSlam(params, geometry, MappingParams(), BEAMS, MAX_RANGE_M)
    nothing = np.full(360, MAX_RANGE_M, dtype=np.float32)  # open space: no returns at all
    slam.reset((0.0, 0.0, 0.0), nothing)
    lost = []
    for k in range(1, 6):
        slam.update((0.3 * k, 0.0, 0.0), nothing)
        lost.append(slam.lost)
    assert lost == [False, False, True, True, True]
    # Odometry alone carried the estimate meanwhile.
    assert slam.estimate == pytest.approx((1.5, 0.0, 0.0))


def _kidnapped(params: SlamParams, to: tuple[float, float, float], steps: int = 8):
    """The ring driven to its end, then the robot carried to ``to`` and turned in place
    there; the back end is told only the odometry's new frame. Returns it, and whether it was
    lost after each step there."""
    slam, _, _ = _run(params, seed=3)
    index = SegmentIndex(_ring_segments())
    assert not slam.lost and slam.lost_events == 0
    slam.kidnap(to)
    lost = []
    for k in range(1, steps + 1):
        pose = (to[0], to[1], to[2] + 0.3 * k)
        ranges = cast_scan(index, pose[0], pose[1], pose[2], BEAMS, MAX_RANGE_M)
        slam.update(pose, np.minimum(ranges, MAX_RANGE_M))
        lost.append(slam.lost)
    return slam, lost


def test_a_kidnapped_robot_is_noticed_and_stays_lost() -> None:
    # Carried from the ring's bottom side to its top side, facing the other way.
    slam, lost = _kidnapped(SlamParams(enabled=True), (3.0, 5.25, 0.5))
    assert lost[0] and all(lost)
    assert slam.lost_events == 1


def test_without_the_jump_check_the_kidnap_goes_unnoticed() -> None:
    # The keyframes after the kidnap match each other well: only the jump gives it away.
    slam, lost = _kidnapped(SlamParams(enabled=True, scan_jump_share=1.0), (3.0, 5.25, 0.5))
    assert not any(lost)
    assert slam.lost_events == 0


def test_a_collapse_without_a_jump_is_no_kidnap() -> None:
    # Driven the ring with the collapse floor at its highest: many keyframes score below it
    # on the way, none of them after a jump, and the back end never says it is lost.
    slam, _, ate_m = _run(SlamParams(enabled=True, score_collapse_ratio=1.0), seed=3)
    assert slam.lost_events == 0 and ate_m < 0.05


def _thick_wall_scan(pose: tuple[float, float, float]) -> np.ndarray:
    """A corridor (y 0 to 1.5) beside a room, parted by a 0.1 m thick wall with a 0.8 m door."""
    walls = [
        [-6, 0, 6, 0],
        [-6, 1.5, -0.4, 1.5], [-0.4, 1.5, -0.4, 1.6], [-0.4, 1.6, -6, 1.6],
        [0.4, 1.5, 6, 1.5], [0.4, 1.5, 0.4, 1.6], [0.4, 1.6, 6, 1.6],
    ]  # fmt: skip
    index = SegmentIndex(np.array(walls, dtype=np.float64))
    ranges = cast_scan(index, pose[0], pose[1], pose[2], BEAMS, MAX_RANGE_M)
    return np.minimum(ranges, MAX_RANGE_M)


@pytest.mark.parametrize("room", [(1.0, 2.0, 0.3), (-1.0, 1.9, -0.2), (2.0, 2.1, 0.0)])
def test_a_walls_room_face_is_not_laid_on_its_corridor_face(room) -> None:
    # The first keyframe in the corridor saw the wall's corridor face; the next, in the room
    # (through the door, one long step of exact odometry), sees the room face 0.1 m further.
    # A LiDAR never sees a face from behind: culled, the corridor face cannot pull the scan.
    geometry = GridGeometry.covering(-7.0, -1.0, 7.0, 6.0, 0.05, 0.5)
    errors_m = {}
    for margin_m in (0.05, 0.0):
        params = SlamParams(enabled=True, backface_margin_m=margin_m)
        slam = ScanSlam(params, geometry, MappingParams(), BEAMS, MAX_RANGE_M)
        corridor = (room[0], 0.9, room[2])
        slam.reset(corridor, _thick_wall_scan(corridor))
        estimate = slam.update(room, _thick_wall_scan(room))
        errors_m[margin_m] = math.hypot(estimate[0] - room[0], estimate[1] - room[1])
    assert SlamParams().backface_margin_m == 0.05  # on by default
    assert errors_m[0.05] < 0.01
    assert errors_m[0.0] > 0.05  # without it, one wall thickness off


def _conflicting_map(params: SlamParams) -> tuple[np.ndarray, np.ndarray, tuple[int, int]]:
    """A back end's map after one scan sees a wall at 1.0 m and two see it at 1.1 m (a wall
    mapped from two poses a cell or two apart): its encoded grid and log-odds, and the cell
    of the first wall on the beam straight ahead."""
    geometry = GridGeometry.covering(-2.0, -2.0, 2.0, 2.0, 0.05, 0.0)
    slam = ScanSlam(params, geometry, MappingParams(), BEAMS, MAX_RANGE_M)
    slam.reset((0.0, 0.0, 0.0), np.full(len(BEAMS), 1.02))
    for _ in range(2):
        slam.grid.integrate_scan(0.0, 0.0, 0.0, BEAMS, np.full(len(BEAMS), 1.12), MAX_RANGE_M)
    row, col = (int(v) for v in geometry.world_to_grid(1.02, 0.01))
    return slam.grid.encoded.copy(), slam.grid.log_odds.copy(), (row, col)


def test_known_when_seen_leaves_no_touched_cell_unknown() -> None:
    band, band_lo, cell = _conflicting_map(SlamParams(enabled=True))
    seen, seen_lo, _ = _conflicting_map(SlamParams(enabled=True, known_when_seen=True))
    np.testing.assert_array_equal(band_lo, seen_lo)  # the same evidence, another rule
    # One hit and two misses: the perfect map's band leaves the wall's cell unknown (a
    # frontier beside free cells); Gmapping's rule calls it occupied (hit share 1/3).
    assert band[cell] == UNKNOWN and seen[cell] == OCCUPIED
    touched = band_lo != 0
    assert np.any(touched & (band == UNKNOWN))
    assert not np.any(touched & (seen == UNKNOWN))
    # Cells no beam reached (beyond the walls) stay unknown under both rules.
    assert np.array_equal(band[~touched], seen[~touched])
    assert np.all(seen[~touched] == UNKNOWN)
    # Cells of one kind of evidence only are classified the same under both rules.
    clear = touched & (band != UNKNOWN)
    assert np.array_equal(band[clear], seen[clear])
