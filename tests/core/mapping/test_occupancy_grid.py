"""Log-odds occupancy mapping on small grids with exact expectations."""

from __future__ import annotations

import math
import pickle

import numpy as np
import pytest

from semexplore_gym.core.grid import FREE, OCCUPIED, UNKNOWN, GridGeometry, parse_ascii_grid
from semexplore_gym.core.mapping.occupancy_grid import MappingParams, OccupancyGrid

P = MappingParams()
L_FREE = np.float32(P.log_odds_free)
L_OCC = np.float32(P.log_odds_occupied)


def unit_grid(height: int = 5, width: int = 8, **kw) -> OccupancyGrid:
    """Cells of 1 m with the lower-left corner at the world origin."""
    return OccupancyGrid(GridGeometry(1.0, 0.0, 0.0, height, width), P, **kw)


def test_single_beam_axis_aligned() -> None:
    og = unit_grid()
    d = og.integrate_scan(0.5, 2.5, 0.0, [0.0], [4.2], 10.0)
    expect = parse_ascii_grid(
        """
        ????????
        ????????
        ....#???
        ????????
        ????????
        """
    )
    np.testing.assert_array_equal(og.encoded, expect)
    assert d == 4 and og.n_free_cells == 4 and og.n_free_in_mask == 4
    assert og.log_odds[2, 4] == L_OCC
    np.testing.assert_array_equal(og.log_odds[2, :4], np.full(4, L_FREE))


def test_single_diagonal_beam_marks_every_crossed_cell() -> None:
    # From (0.5, 0.5) towards (4.5, 2.5): crosses x=1 at y=0.75, y=1 at x=1.5, x=2, x=3,
    # y=2 at x=3.5, x=4; so the cells are (0,0) (0,1) (1,1) (1,2) (1,3) (2,3) and the end (2,4).
    og = unit_grid()
    og.integrate_scan(0.5, 0.5, math.atan2(2.0, 4.0), [0.0], [math.hypot(4.0, 2.0)], 10.0)
    expect = parse_ascii_grid(
        """
        ????????
        ????????
        ???.#???
        ?...????
        ..??????
        """
    )
    np.testing.assert_array_equal(og.encoded, expect)


def test_max_range_and_beyond_mark_no_occupied_cell() -> None:
    og = unit_grid()
    # range == max, range > max and inf all mean "no return": free up to the max range.
    og.integrate_scan(0.5, 2.5, 0.0, [0.0, math.pi / 2, -math.pi / 2], [3.0, 7.0, np.inf], 3.0)
    expect = parse_ascii_grid(
        """
        .???????
        .???????
        ....????
        .???????
        .???????
        """
    )
    np.testing.assert_array_equal(og.encoded, expect)
    assert not (og.encoded == OCCUPIED).any()


def test_invalid_beams_change_nothing() -> None:
    og = unit_grid()
    d = og.integrate_scan(0.5, 2.5, 0.0, [0.0, 1.0, 2.0], [0.0, np.nan, 0.0], 10.0)
    assert d == 0 and og.n_free_cells == 0
    assert not og.log_odds.any()
    assert (og.encoded == UNKNOWN).all()


def test_occupied_wins_and_each_cell_updated_once_per_scan() -> None:
    og = unit_grid()
    # Beam A ends in cell (2, 3); beam B passes through it to (2, 6). Both start in (2, 0).
    # Ten more copies of beam B must not add more free evidence within the same scan.
    beams = np.zeros(12)
    ranges = np.r_[3.2, np.full(11, 6.2)]
    og.integrate_scan(0.5, 2.5, 0.0, beams, ranges, 10.0)
    assert og.log_odds[2, 3] == L_OCC
    assert og.log_odds[2, 6] == L_OCC
    np.testing.assert_array_equal(og.log_odds[2, [0, 1, 2, 4, 5]], np.full(5, L_FREE))
    assert og.encoded[2, 3] == OCCUPIED


def test_clamping_and_evidence_accumulates_across_scans() -> None:
    og = unit_grid()
    og.integrate_scan(0.5, 2.5, 0.0, [0.0], [4.2], 10.0)
    og.integrate_scan(0.5, 2.5, 0.0, [0.0], [4.2], 10.0)
    assert og.log_odds[2, 4] == np.float32(L_OCC + L_OCC)
    for _ in range(30):
        og.integrate_scan(0.5, 2.5, 0.0, [0.0], [4.2], 10.0)
    assert og.log_odds[2, 4] == np.float32(P.log_odds_max)
    np.testing.assert_array_equal(og.log_odds[2, :4], np.full(4, np.float32(P.log_odds_min)))
    # A FREE cell seen once as an end point stays FREE (-4 + 0.85 < -0.2).
    og.integrate_scan(0.5, 2.5, 0.0, [0.0], [2.5], 10.0)
    assert og.encoded[2, 2] == FREE


def test_beams_leaving_or_entering_the_grid() -> None:
    og = unit_grid()
    # The sensor is left of the grid; the beam enters it and ends in (2, 2).
    og.integrate_scan(-2.0, 2.5, 0.0, [0.0], [4.2], 10.0)
    # The sensor is inside; the beam leaves the grid at the top before its end point.
    og.integrate_scan(6.5, 0.5, 0.0, [math.pi / 2], [8.0], 10.0)
    # Nowhere near the grid.
    og.integrate_scan(100.0, 100.0, 0.0, np.linspace(0, 6, 30), np.full(30, 5.0), 10.0)
    # Along the border line itself, and pointing away from the grid.
    og.integrate_scan(0.0, 5.0, 0.0, [0.0, math.pi / 2], [7.9, 2.0], 10.0)
    expect = parse_ascii_grid(
        """
        ??????.?
        ??????.?
        ..#???.?
        ??????.?
        ??????.?
        """
    )
    np.testing.assert_array_equal(og.encoded, expect)


def crossed_cells(
    geom: GridGeometry, x: float, y: float, angle: float, length: float
) -> list[tuple[int, int]]:
    """Reference: cells of the midpoints between consecutive grid-line crossings of the beam."""
    dx, dy = math.cos(angle), math.sin(angle)
    ts = [0.0, length]
    for origin, d, n in ((geom.origin_x_m, dx, geom.width), (geom.origin_y_m, dy, geom.height)):
        if d != 0.0:
            for k in range(n + 1):
                t = (origin + k * geom.resolution_m - (x if origin == geom.origin_x_m else y)) / d
                if 0.0 < t < length:
                    ts.append(t)
    ts = sorted(ts)
    cells = []
    for a, b in zip(ts[:-1], ts[1:], strict=True):
        if b - a < 1e-12:
            continue
        tm = 0.5 * (a + b)
        r, c = geom.world_to_grid(x + tm * dx, y + tm * dy)
        if geom.contains(r, c):
            cells.append((int(r), int(c)))
    return cells


def reference_scan(
    lo: np.ndarray, geom: GridGeometry, pose, beams, ranges, max_range: float
) -> None:
    x, y, yaw = pose
    occ, free = set(), set()
    for b, r in zip(beams, ranges, strict=True):
        if not r > 0:
            continue
        if r < max_range:
            er, ec = geom.world_to_grid(x + r * math.cos(yaw + b), y + r * math.sin(yaw + b))
            if geom.contains(er, ec):
                occ.add((int(er), int(ec)))
        free.update(crossed_cells(geom, x, y, yaw + b, min(r, max_range)))
    for cells, delta in ((occ, L_OCC), (free - occ, L_FREE)):
        if cells:
            idx = tuple(np.array(sorted(cells)).T)
            lo[idx] = np.clip(
                lo[idx] + delta, np.float32(P.log_odds_min), np.float32(P.log_odds_max)
            )


def test_matches_reference_on_random_scans_with_counters() -> None:
    rng = np.random.default_rng(0)
    geom = GridGeometry(0.25, -0.6, 0.35, 14, 18)
    mask = rng.random(geom.shape) < 0.6
    og = OccupancyGrid(geom, P, count_mask=mask)
    ref = np.zeros(geom.shape, dtype=np.float32)
    total = 0
    for _ in range(300):  # more than 255 scans: the per-scan stamps wrap around
        pose = (rng.uniform(-1.5, 4.5), rng.uniform(-0.5, 4.5), rng.uniform(-np.pi, np.pi))
        n = int(rng.integers(1, 12))
        beams = rng.uniform(-np.pi, np.pi, n)
        ranges = rng.uniform(0.0, 3.0, n)
        ranges[rng.random(n) < 0.15] = 0.0
        ranges[rng.random(n) < 0.15] = np.nan
        ranges[rng.random(n) < 0.15] = np.inf
        total += og.integrate_scan(*pose, beams, ranges, 2.0)
        reference_scan(ref, geom, pose, beams, ranges, 2.0)
    np.testing.assert_array_equal(og.log_odds, ref)
    enc = og.encoded
    expect = np.where(
        ref < np.float32(P.free_threshold),
        FREE,
        np.where(ref > np.float32(P.occupied_threshold), OCCUPIED, UNKNOWN),
    )
    np.testing.assert_array_equal(enc, expect)
    assert og.n_free_cells == int((enc == FREE).sum()) == total
    assert og.n_free_in_mask == int(((enc == FREE) & mask).sum())
    assert og.n_mask_cells == int(mask.sum())
    assert og.free_area_m2 == pytest.approx(og.n_free_cells * 0.0625)


def test_encoded_matches_thresholds_after_many_dense_scans() -> None:
    rng = np.random.default_rng(1)
    params = MappingParams(resolution_m=0.1, log_odds_free=-0.3, log_odds_occupied=0.5)
    og = OccupancyGrid(params.grid_geometry((0.0, 0.0, 6.0, 4.0)), params)
    beams = np.arange(90) * (2 * np.pi / 90)
    for _ in range(80):
        og.integrate_scan(
            *rng.uniform([0, 0, -4], [6, 4, 4]), beams, rng.uniform(0.0, 4.0, 90), 3.5
        )
    lo = og.log_odds
    expect = np.where(
        lo < np.float32(params.free_threshold),
        FREE,
        np.where(lo > np.float32(params.occupied_threshold), OCCUPIED, UNKNOWN),
    )
    np.testing.assert_array_equal(og.encoded, expect)
    assert og.n_free_cells == int((og.encoded == FREE).sum())
    assert (lo >= params.log_odds_min).all() and (lo <= params.log_odds_max).all()


def test_reset_pickle_and_read_only_views() -> None:
    og = unit_grid()
    og.integrate_scan(0.5, 2.5, 0.0, [0.0], [4.2], 10.0)
    clone = pickle.loads(pickle.dumps(og))
    np.testing.assert_array_equal(clone.encoded, og.encoded)
    assert clone.n_free_cells == og.n_free_cells
    assert clone.integrate_scan(0.5, 0.5, 0.0, [math.pi / 2], [3.5], 10.0) == og.integrate_scan(
        0.5, 0.5, 0.0, [math.pi / 2], [3.5], 10.0
    )
    np.testing.assert_array_equal(clone.log_odds, og.log_odds)
    with pytest.raises(ValueError):
        og.encoded[0, 0] = FREE
    copy = og.encoded_copy()
    copy[0, 0] = 7
    assert og.encoded[0, 0] != 7
    og.reset()
    assert og.n_free_cells == 0 and og.n_free_in_mask == 0
    assert (og.encoded == UNKNOWN).all() and not og.log_odds.any()


def test_count_mask_counts_only_masked_cells() -> None:
    mask = np.zeros((5, 8), dtype=bool)
    mask[2, 1:3] = True
    og = unit_grid(count_mask=mask)
    og.integrate_scan(0.5, 2.5, 0.0, [0.0], [4.2], 10.0)
    assert og.n_free_cells == 4 and og.n_free_in_mask == 2
    assert mask.flags.writeable  # the caller's array is copied, not frozen
    mask[2, 3] = True
    assert og.n_mask_cells == 2


def test_grid_geometry_from_params() -> None:
    geom = MappingParams(resolution_m=0.1, margin_m=0.5).grid_geometry((0.0, 0.0, 2.0, 1.0))
    assert (geom.origin_x_m, geom.origin_y_m, geom.height, geom.width) == (-0.5, -0.5, 20, 30)


def test_bad_scan_inputs_raise_and_leave_the_map_unchanged() -> None:
    og = unit_grid()
    with pytest.raises(ValueError, match="equal length"):
        og.integrate_scan(0.5, 2.5, 0.0, [0.0, 1.0], [1.0], 10.0)
    with pytest.raises(ValueError, match="pose"):
        og.integrate_scan(float("nan"), 2.5, 0.0, [0.0], [1.0], 10.0)
    with pytest.raises(ValueError, match="pose"):
        og.integrate_scan(0.5, 2.5, float("inf"), [0.0], [1.0], 10.0)
    with pytest.raises(ValueError, match="max_range_m"):
        og.integrate_scan(0.5, 2.5, 0.0, [0.0], [1.0], 0.0)
    with pytest.raises(ValueError, match=r"ranges_m\[1\]"):
        og.integrate_scan(0.5, 2.5, 0.0, [0.0, 1.0], [1.0, -0.5], 10.0)
    with pytest.raises(ValueError, match=r"beam_angles_rad\[0\]"):
        og.integrate_scan(0.5, 2.5, 0.0, [np.nan], [1.0], 10.0)
    assert og.n_free_cells == 0 and not og.log_odds.any()


def test_bad_construction_raises() -> None:
    geom = GridGeometry(1.0, 0.0, 0.0, 5, 8)
    with pytest.raises(ValueError, match="shape"):
        OccupancyGrid(geom, P, count_mask=np.ones((4, 8), dtype=bool))
    with pytest.raises(TypeError, match="bool"):
        OccupancyGrid(geom, P, count_mask=np.ones((5, 8)))
    with pytest.raises(TypeError, match="GridGeometry"):
        OccupancyGrid((1.0, 0.0, 0.0, 5, 8), P)  # type: ignore[arg-type]


@pytest.mark.parametrize(
    ("field", "value"),
    [
        ("resolution_m", 0.0),
        ("margin_m", -1.0),
        ("log_odds_free", 0.4),
        ("log_odds_occupied", -0.1),
        ("log_odds_min", 1.0),
        ("free_threshold", 0.3),
        ("occupied_threshold", 5.0),
        ("log_odds_max", float("nan")),
    ],
)
def test_mapping_params_validation_names_the_field(field: str, value: float) -> None:
    with pytest.raises(ValueError, match=field):
        MappingParams(**{field: value})


def test_keep_encoded_in_moves_the_map_into_a_buffer() -> None:
    og = unit_grid()
    og.integrate_scan(0.5, 2.5, 0.0, [0.0], [4.2], 10.0)
    before = og.encoded  # a live view of the grid's array so far
    rows = np.zeros((2, 5, 8), dtype=np.uint8)
    og.keep_encoded_in(rows[1])
    np.testing.assert_array_equal(rows[1], before)  # the current cells, copied once
    og.keep_encoded_in(rows[1])  # already there: nothing happens
    og.integrate_scan(0.5, 0.5, 0.0, [0.0], [3.2], 10.0)
    # Later updates land in the buffer only; the old array stays as it was.
    ref = unit_grid()
    ref.integrate_scan(0.5, 2.5, 0.0, [0.0], [4.2], 10.0)
    frozen = ref.encoded.copy()
    ref.integrate_scan(0.5, 0.5, 0.0, [0.0], [3.2], 10.0)
    np.testing.assert_array_equal(rows[1], ref.encoded)
    np.testing.assert_array_equal(og.encoded, ref.encoded)
    np.testing.assert_array_equal(before, frozen)
    assert not rows[0].any() and og.n_free_cells == ref.n_free_cells


@pytest.mark.parametrize(
    "buffer",
    [
        np.zeros((5, 9), dtype=np.uint8),
        np.zeros((5, 8), dtype=np.int16),
        np.zeros((8, 5), dtype=np.uint8).T,
        [[0] * 8] * 5,
    ],
)
def test_keep_encoded_in_refuses_other_buffers(buffer) -> None:
    og = unit_grid()
    with pytest.raises(ValueError, match=r"writable C-contiguous uint8 array of shape \(5, 8\)"):
        og.keep_encoded_in(buffer)
    ro = np.zeros((5, 8), dtype=np.uint8)
    ro.flags.writeable = False
    with pytest.raises(ValueError, match="got ndarray of dtype uint8 and shape"):
        og.keep_encoded_in(ro)
