"""Odometry drift model: exact without noise, reproducible and growing with distance with it."""

from __future__ import annotations

import math

import numpy as np
import pytest

from semexplore_gym.core.mapping.odometry import (
    OdometryDrift,
    OdometryNoiseParams,
    compose_motion,
    decompose_motion,
    wrap_angle,
)

NOISY = OdometryNoiseParams(
    rot_from_rot=0.02, rot_from_trans=0.01, trans_from_trans=0.02, trans_from_rot=0.005
)


def random_trajectory(rng: np.random.Generator, n_steps: int) -> np.ndarray:
    """Unicycle poses with random forward/backward speeds and turn rates (0.2 s steps)."""
    poses = [np.array([1.0, -2.0, 0.3])]
    for _ in range(n_steps):
        x, y, th = poses[-1]
        v = rng.uniform(-0.1, 0.22) * 0.2
        w = rng.uniform(-2.0, 2.0) * 0.2
        poses.append(
            np.array(
                [x + v * math.cos(th + w / 2), y + v * math.sin(th + w / 2), wrap_angle(th + w)]
            )
        )
    return np.array(poses)


def drive(params: OdometryNoiseParams, poses: np.ndarray, seed: int) -> np.ndarray:
    drift = OdometryDrift(params)
    rng = np.random.default_rng(seed)
    out = [drift.reset(poses[0])]
    for before, after in zip(poses[:-1], poses[1:], strict=True):
        out.append(drift.update(before, after, rng))
    return np.array(out)


def straight_line(length_m: float, step_m: float = 0.05) -> np.ndarray:
    n = round(length_m / step_m)
    return np.c_[np.arange(n + 1) * step_m, np.zeros(n + 1), np.zeros(n + 1)]


def test_zero_noise_estimate_is_exactly_the_truth() -> None:
    poses = random_trajectory(np.random.default_rng(0), 300)
    np.testing.assert_array_equal(drive(OdometryNoiseParams(), poses, seed=1), poses)


def test_decompose_then_compose_reproduces_the_motion() -> None:
    rng = np.random.default_rng(2)
    for _ in range(200):
        a = rng.uniform([-5, -5, -np.pi], [5, 5, np.pi])
        b = a + rng.uniform([-0.3, -0.3, -1.0], [0.3, 0.3, 1.0])
        got = compose_motion(a, *decompose_motion(a, b))
        np.testing.assert_allclose(got[:2], b[:2], atol=1e-12)
        assert wrap_angle(got[2] - b[2]) == pytest.approx(0.0, abs=1e-12)


def test_decompose_known_motions() -> None:
    # Forward 1 m along a heading of 90 degrees: no rotation.
    rot1, trans, rot2 = decompose_motion((0, 0, math.pi / 2), (0, 1, math.pi / 2))
    assert (rot1, trans, rot2) == pytest.approx((0.0, 1.0, 0.0), abs=1e-15)
    # Backwards 0.5 m: a half-turn rot1 and its undoing in rot2.
    rot1, trans, rot2 = decompose_motion((0, 0, 0), (-0.5, 0, 0))
    assert trans == pytest.approx(0.5) and abs(rot1) == pytest.approx(math.pi)
    assert wrap_angle(rot1 + rot2) == pytest.approx(0.0, abs=1e-15)
    # Turning in place: everything in rot2.
    assert decompose_motion((1, 1, 0.2), (1, 1, 0.7)) == pytest.approx((0.0, 0.0, 0.5))


def test_noise_is_reproducible_for_a_seed_and_differs_between_seeds() -> None:
    poses = random_trajectory(np.random.default_rng(3), 100)
    a = drive(NOISY, poses, seed=7)
    b = drive(NOISY, poses, seed=7)
    c = drive(NOISY, poses, seed=8)
    np.testing.assert_array_equal(a, b)
    assert not np.allclose(a, c)
    assert not np.allclose(a, poses)


def test_drift_spread_grows_with_distance() -> None:
    params = OdometryNoiseParams(trans_from_trans=0.01, rot_from_trans=0.01)
    path = straight_line(4.0)
    errors = np.array(
        [np.hypot(*(drive(params, path, seed)[:, :2] - path[:, :2]).T) for seed in range(200)]
    )
    std_at = {d: errors[:, round(d / 0.05)].std() for d in (0.5, 1.0, 2.0, 4.0)}
    assert std_at[0.5] < std_at[1.0] < std_at[2.0] < std_at[4.0]
    # Heading errors integrate into position, so the spread grows faster than sqrt(distance).
    assert std_at[4.0] > 2.0 * std_at[1.0]


def test_rotation_only_noise_keeps_the_position_exact_while_turning_in_place() -> None:
    params = OdometryNoiseParams(rot_from_rot=0.05)
    yaws = np.cumsum(np.full(40, 0.3))
    poses = np.c_[np.full(41, 2.0), np.full(41, 3.0), np.r_[0.0, yaws]]
    est = drive(params, poses, seed=0)
    np.testing.assert_array_equal(est[:, :2], poses[:, :2])
    assert (
        np.abs([wrap_angle(e - t) for e, t in zip(est[:, 2], poses[:, 2], strict=True)]).max()
        > 1e-3
    )


def test_misuse_raises() -> None:
    drift = OdometryDrift(NOISY)
    with pytest.raises(RuntimeError, match="reset"):
        drift.update((0, 0, 0), (1, 0, 0), np.random.default_rng(0))
    with pytest.raises(RuntimeError, match="reset"):
        _ = drift.estimate
    drift.reset((0, 0, 0))
    with pytest.raises(TypeError, match="Generator"):
        drift.update((0, 0, 0), (1, 0, 0), 42)  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="true_pose_after"):
        drift.update((0, 0, 0), (1, 0), np.random.default_rng(0))
    with pytest.raises(ValueError, match="finite"):
        drift.reset((0, float("nan"), 0))


@pytest.mark.parametrize(
    "field",
    ["rot_from_rot", "rot_from_trans", "trans_from_trans", "trans_from_rot", "min_translation_m"],
)
def test_params_validation_names_the_field(field: str) -> None:
    with pytest.raises(ValueError, match=field):
        OdometryNoiseParams(**{field: -0.1})
    with pytest.raises(ValueError, match=field):
        OdometryNoiseParams(**{field: float("inf")})
