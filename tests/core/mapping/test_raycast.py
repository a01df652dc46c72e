"""LiDAR ray casting against analytic geometry and an independent brute-force reference."""

from __future__ import annotations

import math
import pickle

import numpy as np
import pytest

from semexplore_gym.core.mapping.raycast import SegmentIndex, cast_rays, cast_scan

SQRT2 = math.sqrt(2.0)


def room(half_m: float = 2.0) -> np.ndarray:
    """Four walls of a square room centred on the origin."""
    h = half_m
    return np.array(
        [[-h, -h, h, -h], [h, -h, h, h], [h, h, -h, h], [-h, h, -h, -h]], dtype=np.float64
    )


def brute_force(
    segments_m: np.ndarray, x: float, y: float, angles: np.ndarray, max_range_m: float
) -> np.ndarray:
    """Every ray against every segment with the textbook parametric intersection."""
    d = np.stack([np.cos(angles), np.sin(angles)], axis=1)[:, None, :]  # (n, 1, 2)
    a = segments_m[None, :, :2] - np.array([x, y])
    e = segments_m[None, :, 2:] - segments_m[None, :, :2]
    den = d[..., 0] * e[..., 1] - d[..., 1] * e[..., 0]
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (a[..., 0] * e[..., 1] - a[..., 1] * e[..., 0]) / den
        u = (a[..., 0] * d[..., 1] - a[..., 1] * d[..., 0]) / den
    ok = (den != 0) & (u >= 0) & (u <= 1) & (t > 0) & (t < max_range_m)
    return np.where(ok, t, np.inf).min(axis=1)


def test_square_room_axis_and_diagonal_beams() -> None:
    index = SegmentIndex(room(2.0))
    angles = np.deg2rad([0.0, 45.0, 90.0, 135.0, 180.0, 225.0, 270.0, 315.0])
    got = cast_rays(index, 0.0, 0.0, angles, 10.0)
    expect = [2.0, 2 * SQRT2, 2.0, 2 * SQRT2, 2.0, 2 * SQRT2, 2.0, 2 * SQRT2]
    np.testing.assert_allclose(got, expect, rtol=0, atol=1e-12)


def test_off_centre_distances_and_yaw() -> None:
    index = SegmentIndex(room(2.0))
    beams = np.deg2rad([0.0, 90.0, 180.0, 270.0])
    # Heading +y: beam 0 looks up (to y=2), beam 90 looks to -x, and so on.
    got = cast_scan(index, 0.5, -1.0, math.pi / 2, beams, 10.0)
    np.testing.assert_allclose(got, [3.0, 2.5, 1.0, 1.5], atol=1e-12)
    # 30 degrees from the +x axis out of (0, 0): wall x=2 at y=2*tan(30deg) < 2
    got = cast_rays(index, 0.0, 0.0, [math.radians(30.0)], 10.0)
    assert got[0] == pytest.approx(2.0 / math.cos(math.radians(30.0)), abs=1e-12)


def test_ray_through_segment_end_point_hits() -> None:
    index = SegmentIndex(np.array([[1.0, 0.0, 1.0, 1.0]]))
    got = cast_rays(index, 0.0, 0.0, [0.0, math.pi / 4], 5.0)
    assert got[0] == pytest.approx(1.0, abs=1e-15)
    assert got[1] == pytest.approx(SQRT2, abs=1e-12)
    # Just past the end point: miss.
    assert cast_rays(index, 0.0, 0.0, [math.pi / 4 + 1e-9], 5.0)[0] == np.inf


def test_collinear_and_parallel_segments_are_not_hit() -> None:
    segs = np.array(
        [
            [1.0, 0.0, 3.0, 0.0],  # collinear with the +x ray
            [1.0, 0.5, 3.0, 0.5],  # parallel, offset
            [-3.0, 0.0, -1.0, 0.0],  # collinear, behind
        ]
    )
    got = cast_rays(SegmentIndex(segs), 0.0, 0.0, [0.0, math.pi], 10.0)
    assert np.all(got == np.inf)


def test_nearest_of_several_and_behind_is_ignored() -> None:
    segs = np.array([[2.0, -1.0, 2.0, 1.0], [1.0, -1.0, 1.0, 1.0], [-0.5, -1.0, -0.5, 1.0]])
    got = cast_rays(SegmentIndex(segs), 0.0, 0.0, [0.0, math.pi, math.pi / 2], 10.0)
    assert got[0] == pytest.approx(1.0, abs=1e-15)
    assert got[1] == pytest.approx(0.5, abs=1e-15)
    assert got[2] == np.inf


def test_max_range_cut() -> None:
    index = SegmentIndex(room(2.0))
    assert cast_rays(index, 0.0, 0.0, [0.0], 1.5)[0] == np.inf
    assert cast_rays(index, 0.0, 0.0, [0.0], 2.5)[0] == pytest.approx(2.0)
    # Corners at 2*sqrt(2) = 2.83 fall outside 2.5 m while the walls straight ahead do not.
    got = cast_rays(index, 0.0, 0.0, [0.0, math.pi / 4], 2.5)
    assert got[0] == pytest.approx(2.0) and got[1] == np.inf
    assert cast_rays(index, 0.0, 0.0, [0.0], np.inf)[0] == pytest.approx(2.0)


def test_sensor_on_a_wall_reads_zero() -> None:
    index = SegmentIndex(room(2.0))
    angles = np.linspace(0, 2 * np.pi, 16, endpoint=False)
    np.testing.assert_array_equal(cast_rays(index, 2.0, 0.5, angles, 5.0), np.zeros(16))
    np.testing.assert_array_equal(
        cast_rays(index, 2.0, 2.0, angles, 5.0), np.zeros(16)
    )  # on a corner
    # A hair inside the room the sensor sees again.
    assert cast_rays(index, 2.0 - 1e-9, 0.5, [math.pi], 5.0)[0] == pytest.approx(
        4.0 - 1e-9, abs=1e-12
    )


def test_zero_length_segment_is_never_hit() -> None:
    index = SegmentIndex(np.array([[1.0, 0.0, 1.0, 0.0]]))
    assert cast_rays(index, 0.0, 0.0, [0.0], 5.0)[0] == np.inf


def test_empty_world_and_far_sensor_see_nothing() -> None:
    assert np.all(
        cast_rays(SegmentIndex(np.zeros((0, 4))), 0.0, 0.0, np.linspace(0, 6, 7), 5.0) == np.inf
    )
    index = SegmentIndex(room(2.0))
    assert np.all(cast_rays(index, 100.0, -50.0, np.linspace(0, 6, 7), 5.0) == np.inf)
    # Far outside the bucket grid but looking at the room from 10 m away.
    assert cast_rays(index, -12.0, 0.0, [0.0], 20.0)[0] == pytest.approx(10.0)


def test_no_angles_gives_empty_result() -> None:
    assert cast_rays(SegmentIndex(room()), 0.0, 0.0, np.zeros(0), 5.0).shape == (0,)


@pytest.mark.parametrize("n_segments", [5, 60, 600])
def test_matches_brute_force_on_random_worlds(n_segments: int) -> None:
    rng = np.random.default_rng(n_segments)
    start = rng.uniform(0, 12, (n_segments, 2))
    length = rng.uniform(0.05, 3.0, n_segments)
    angle = rng.uniform(0, 2 * np.pi, n_segments)
    segs = np.c_[start, start + np.c_[length * np.cos(angle), length * np.sin(angle)]]
    index = SegmentIndex(segs)
    for _ in range(12):
        x, y = rng.uniform(-1, 13, 2)
        max_range = rng.uniform(0.5, 8.0)
        angles = rng.uniform(-10, 10, 200)  # unordered, unwrapped
        got = cast_rays(index, x, y, angles, max_range)
        ref = brute_force(segs, x, y, angles, max_range)
        np.testing.assert_array_equal(np.isinf(got), np.isinf(ref))
        np.testing.assert_allclose(got[np.isfinite(ref)], ref[np.isfinite(ref)], rtol=0, atol=1e-9)


def test_cast_scan_equals_cast_rays_with_absolute_angles() -> None:
    rng = np.random.default_rng(3)
    segs = rng.uniform(0, 8, (80, 4))
    index = SegmentIndex(segs)
    beams = np.arange(360) * (2 * np.pi / 360)
    out = np.empty(360)
    got = cast_scan(index, 4.0, 4.0, 0.7, beams, 3.5, out=out)
    assert got is out
    np.testing.assert_array_equal(got, cast_rays(index, 4.0, 4.0, beams + 0.7, 3.5))


def test_buckets_list_every_segment_where_it_passes() -> None:
    rng = np.random.default_rng(5)
    segs = np.r_[rng.uniform(0, 20, (200, 4)), [[0.0, 0.0, 20.0, 0.0], [3.0, 3.0, 3.0, 3.0]]]
    index = SegmentIndex(segs, cell_size_m=0.7)
    assert index.cell_size_m == 0.7
    for i, (x0, y0, x1, y1) in enumerate(segs):
        t = np.linspace(0, 1, 200)
        col = np.floor((x0 + t * (x1 - x0) - index.origin_x_m) / index.cell_size_m).astype(int)
        row = np.floor((y0 + t * (y1 - y0) - index.origin_y_m) / index.cell_size_m).astype(int)
        for k in set((row * index.n_cols + col).tolist()):
            listed = index.bucket_items[index.bucket_start[k] : index.bucket_start[k + 1]]
            assert i in listed, f"segment {i} missing from bucket {k}"


def test_bucket_size_adapts_to_world() -> None:
    tiny = SegmentIndex(np.array([[0.0, 0.0, 0.1, 0.0]]))
    assert tiny.n_rows * tiny.n_cols == 1
    dense = SegmentIndex(np.random.default_rng(0).uniform(0, 50, (10_000, 4)))
    assert 0.5 <= dense.cell_size_m <= 1.0
    huge = SegmentIndex(np.array([[0.0, 0.0, 1.0, 0.0], [5000.0, 5000.0, 5001.0, 5000.0]]))
    assert huge.n_rows * huge.n_cols <= 1.1 * 2**20
    assert cast_rays(huge, 5000.5, 4999.0, [math.pi / 2], 3.5)[0] == pytest.approx(1.0)


def test_index_pickles_and_is_read_only() -> None:
    index = SegmentIndex(room(2.0))
    clone = pickle.loads(pickle.dumps(index))
    angles = np.linspace(0, 6, 50)
    np.testing.assert_array_equal(
        cast_rays(clone, 0.3, 0.1, angles, 5.0), cast_rays(index, 0.3, 0.1, angles, 5.0)
    )
    with pytest.raises(ValueError):
        clone.segments_m[0, 0] = 1.0
    with pytest.raises(ValueError):
        index.bucket_items[0] = 1


@pytest.mark.parametrize(
    ("segments", "match"),
    [
        (np.zeros((3, 3)), "shape"),
        (np.array([[0.0, 0.0, np.nan, 1.0]]), "row 0"),
        (np.zeros(5), "shape"),
    ],
)
def test_bad_segments_raise(segments: np.ndarray, match: str) -> None:
    with pytest.raises(ValueError, match=match):
        SegmentIndex(segments)


def test_bad_cell_size_raises() -> None:
    with pytest.raises(ValueError, match="cell_size_m"):
        SegmentIndex(room(), cell_size_m=0.0)


def test_bad_queries_raise() -> None:
    index = SegmentIndex(room())
    with pytest.raises(ValueError, match="position"):
        cast_rays(index, float("nan"), 0.0, [0.0], 3.0)
    with pytest.raises(ValueError, match="yaw_rad"):
        cast_scan(index, 0.0, 0.0, float("inf"), [0.0], 3.0)
    with pytest.raises(ValueError, match="max_range_m"):
        cast_rays(index, 0.0, 0.0, [0.0], 0.0)
    with pytest.raises(ValueError, match="1-D"):
        cast_rays(index, 0.0, 0.0, np.zeros((2, 2)), 3.0)
    with pytest.raises(ValueError, match="NaN or inf"):
        cast_scan(index, 0.0, 0.0, 0.0, [0.0, np.nan], 3.0)
    with pytest.raises(ValueError, match="out"):
        cast_rays(index, 0.0, 0.0, [0.0, 1.0], 3.0, out=np.empty(3))
    with pytest.raises(TypeError, match="SegmentIndex"):
        cast_rays(room(), 0.0, 0.0, [0.0], 3.0)  # type: ignore[arg-type]


def same_formula_every_segment(
    segments_m: np.ndarray, x: float, y: float, angles: np.ndarray, max_range_m: float
) -> np.ndarray:
    """The caster's own float operations, applied to every segment (no buckets, no bins)."""
    a = segments_m[:, :2] - np.array([x, y])
    b = segments_m[:, 2:] - np.array([x, y])
    cross = a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]
    out = np.full(angles.shape[0], np.inf)
    for j, th in enumerate(angles):
        dx, dy = math.cos(th), math.sin(th)  # libm, as the compiled caster
        ca = dx * a[:, 1] - dy * a[:, 0]
        cb = dx * b[:, 1] - dy * b[:, 0]
        den = cb - ca
        with np.errstate(divide="ignore", invalid="ignore"):
            t = cross / den
        ok = (ca * cb <= 0.0) & (den != 0.0) & (t > 0.0) & (t < max_range_m)
        if ok.any():
            out[j] = t[ok].min()
    return out


def test_angular_bins_never_drop_the_nearest_wall_bit_for_bit() -> None:
    # A raster-like world: many tiny axis-aligned segments (as ROS maps give), rays through
    # their end points and along grid lines, where a too-tight bin would lose a hit.
    rng = np.random.default_rng(17)
    cells = rng.integers(0, 80, size=(700, 2)) * 0.05
    horiz = np.c_[cells, cells + [0.05, 0.0]]
    vert = np.c_[cells[:350], cells[:350] + [0.0, 0.05]]
    segs = np.concatenate([horiz, vert])
    index = SegmentIndex(segs)
    ends = np.concatenate([segs[:, :2], segs[:, 2:]])
    for k in range(60):
        if k % 2:
            x, y = ends[rng.integers(len(ends))] + rng.choice([0.025, -0.025, 1e-9], 2)
        else:
            x, y = rng.uniform(0.0, 4.0, 2)
        if np.any(np.all(np.isclose(segs[:, :2], [x, y], atol=0), axis=1)):
            continue
        base = rng.choice([0.0, math.pi / 4, math.pi / 2, rng.uniform(-4, 4)])
        angles = base + np.arange(360) * (2 * math.pi / 360)
        got = cast_rays(index, float(x), float(y), angles, 3.5)
        if (got == 0).all():
            continue  # the sensor lies on a wall
        ref = same_formula_every_segment(segs, float(x), float(y), angles, 3.5)
        np.testing.assert_array_equal(got, ref)
