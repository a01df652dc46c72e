"""Odometry drift: a noisy pose estimate for testing planners under imperfect SLAM.

The model is the odometry motion model of Thrun, Burgard and Fox, *Probabilistic
Robotics* (2005), section 5.4. The true motion between two poses
``(x, y, theta) -> (x', y', theta')`` is decomposed into a first rotation, a translation and
a second rotation::

    trans = hypot(x' - x, y' - y)                       [m]
    rot1  = atan2(y' - y, x' - x) - theta               [rad]
    rot2  = theta' - theta - rot1                       [rad]

Each part is perturbed by zero-mean Gaussian noise whose *variance* grows with the motion::

    rot1_hat  = rot1  + N(0, a1 * rot1^2 + a2 * trans^2)
    trans_hat = trans + N(0, a3 * trans^2 + a4 * (rot1^2 + rot2^2))
    rot2_hat  = rot2  + N(0, a1 * rot2^2 + a2 * trans^2)

and the noisy motion is composed onto the *estimated* pose, so the error accumulates like a
real wheel-odometry or scan-matching drift::

    x_hat'     = x_hat + trans_hat * cos(theta_hat + rot1_hat)
    y_hat'     = y_hat + trans_hat * sin(theta_hat + rot1_hat)
    theta_hat' = theta_hat + rot1_hat + rot2_hat

Units of the alphas: ``a1`` (rot from rot) rad^2/rad^2, ``a2`` (rot from trans) rad^2/m^2,
``a3`` (trans from trans) m^2/m^2, ``a4`` (trans from rot) m^2/rad^2. All zero gives perfect
odometry.

Two details keep the noise physical, as in ROS AMCL's implementation of the same model: a
backward step counts as a small rotation (the rotation noise uses the angle to the nearer of
forward and backward), and for a step shorter than ``min_translation_m`` (turning in place)
``rot1`` counts as zero in the noise, since its direction is meaningless.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

import numpy as np
import numpy.typing as npt

from semexplore_gym.core.grid import wrap_angle_rad as wrap_angle


@dataclass(frozen=True)
class OdometryNoiseParams:
    """Noise of the odometry motion model (see the module docstring).

    Attributes:
        rot_from_rot: ``a1``, rotation variance per squared rotation (rad^2/rad^2).
        rot_from_trans: ``a2``, rotation variance per squared translation (rad^2/m^2).
        trans_from_trans: ``a3``, translation variance per squared translation (m^2/m^2).
        trans_from_rot: ``a4``, translation variance per squared rotation (m^2/rad^2).
        min_translation_m: Steps shorter than this count as turning in place for the noise.
    """

    rot_from_rot: float = 0.0
    rot_from_trans: float = 0.0
    trans_from_trans: float = 0.0
    trans_from_rot: float = 0.0
    min_translation_m: float = 0.01

    def __post_init__(self) -> None:
        for f in fields(self):
            v = getattr(self, f.name)
            if (
                isinstance(v, bool)
                or not isinstance(v, (int, float))
                or not math.isfinite(v)
                or v < 0
            ):
                raise ValueError(
                    f"OdometryNoiseParams.{f.name} must be a finite number >= 0, got {v!r}"
                )
            # Beyond these a single step's noise is metres or many turns: not odometry.
            hi = 1.0 if f.name == "min_translation_m" else 10.0
            if v > hi:
                raise ValueError(f"odometry.{f.name} must be <= {hi:g}, got {v!r}")

    @property
    def is_perfect(self) -> bool:
        """True when every alpha is zero (the estimate is the true pose)."""
        return (
            self.rot_from_rot
            == self.rot_from_trans
            == self.trans_from_trans
            == self.trans_from_rot
            == 0.0
        )


def decompose_motion(
    pose_before: npt.ArrayLike, pose_after: npt.ArrayLike
) -> tuple[float, float, float]:
    """Split the motion between two poses ``(x_m, y_m, yaw_rad)`` into ``(rot1_rad, trans_m, rot2_rad)``.

    For a pure rotation (zero translation) ``rot1`` is 0 and ``rot2`` carries the turn.
    """
    return _decompose(_pose(pose_before, "pose_before"), _pose(pose_after, "pose_after"))


def _decompose(
    before: tuple[float, float, float], after: tuple[float, float, float]
) -> tuple[float, float, float]:
    x0, y0, th0 = before
    x1, y1, th1 = after
    dx = x1 - x0
    dy = y1 - y0
    trans = math.hypot(dx, dy)
    rot1 = wrap_angle(math.atan2(dy, dx) - th0) if trans > 0.0 else 0.0
    rot2 = wrap_angle(th1 - th0 - rot1)
    return rot1, trans, rot2


def compose_motion(
    pose: npt.ArrayLike, rot1_rad: float, trans_m: float, rot2_rad: float
) -> tuple[float, float, float]:
    """Apply a ``(rot1, trans, rot2)`` motion to a pose; the yaw is wrapped to ``[-pi, pi)``."""
    x, y, th = _pose(pose, "pose")
    heading = th + rot1_rad
    return (
        x + trans_m * math.cos(heading),
        y + trans_m * math.sin(heading),
        wrap_angle(heading + rot2_rad),
    )


class OdometryDrift:
    """Tracks a drifting pose estimate next to the true pose.

    Call :meth:`reset` with the true start pose, then :meth:`update` after every motion
    step with the true poses before and after it; it returns the new estimate.

    Args:
        params: The noise model. With all alphas zero the estimate is exactly the true pose
            and no random numbers are drawn.
    """

    def __init__(self, params: OdometryNoiseParams | None = None) -> None:
        params = OdometryNoiseParams() if params is None else params
        if not isinstance(params, OdometryNoiseParams):
            raise TypeError(f"params must be OdometryNoiseParams, got {type(params).__name__}")
        self.params = params
        self._estimate: tuple[float, float, float] | None = None

    @property
    def estimate(self) -> np.ndarray:
        """The current estimated pose ``(x_m, y_m, yaw_rad)``."""
        if self._estimate is None:
            raise RuntimeError("OdometryDrift.reset(true_pose) must be called first")
        return np.array(self._estimate, dtype=np.float64)

    def reset(self, true_pose: npt.ArrayLike) -> np.ndarray:
        """Start a new episode: the estimate equals ``true_pose``. Returns the estimate."""
        self._estimate = _pose(true_pose, "true_pose")
        return self.estimate

    def update(
        self,
        true_pose_before: npt.ArrayLike,
        true_pose_after: npt.ArrayLike,
        rng: np.random.Generator,
    ) -> np.ndarray:
        """Advance the estimate by the noisy version of one true motion step.

        Args:
            true_pose_before: True ``(x_m, y_m, yaw_rad)`` at the start of the step.
            true_pose_after: True ``(x_m, y_m, yaw_rad)`` at the end of the step.
            rng: Source of the noise (three normal draws per step unless noise-free).

        Returns:
            The new estimated pose ``(x_m, y_m, yaw_rad)`` as a float64 array.
        """
        if self._estimate is None:
            raise RuntimeError("OdometryDrift.reset(true_pose) must be called before update()")
        before = _pose(true_pose_before, "true_pose_before")
        after = _pose(true_pose_after, "true_pose_after")
        if self.params.is_perfect:
            # The estimate started at the truth and nothing perturbs it.
            self._estimate = after
            return self.estimate
        if not isinstance(rng, np.random.Generator):
            raise TypeError(f"rng must be a numpy.random.Generator, got {type(rng).__name__}")
        rot1, trans, rot2 = _decompose(before, after)
        p = self.params
        if trans < p.min_translation_m:
            n_rot1 = 0.0
            n_rot2 = wrap_angle(rot1 + rot2)
        else:
            # Driving backwards is a small rotation plus a translation, not a half turn.
            n_rot1 = min(abs(rot1), math.pi - abs(rot1))
            n_rot2 = min(abs(rot2), math.pi - abs(rot2))
        std_rot1 = math.sqrt(p.rot_from_rot * n_rot1**2 + p.rot_from_trans * trans**2)
        std_trans = math.sqrt(
            p.trans_from_trans * trans**2 + p.trans_from_rot * (n_rot1**2 + n_rot2**2)
        )
        std_rot2 = math.sqrt(p.rot_from_rot * n_rot2**2 + p.rot_from_trans * trans**2)
        e1, et, e2 = rng.standard_normal(3)
        self._estimate = compose_motion(
            self._estimate, rot1 + std_rot1 * e1, trans + std_trans * et, rot2 + std_rot2 * e2
        )
        return self.estimate


def _pose(pose: npt.ArrayLike, name: str) -> tuple[float, float, float]:
    if (
        isinstance(pose, tuple)
        and len(pose) == 3
        and all(isinstance(v, float) and math.isfinite(v) for v in pose)
    ):
        return pose  # the fast path for our own tuples
    a = np.asarray(pose, dtype=np.float64)
    if a.shape != (3,):
        raise ValueError(f"{name} must be (x_m, y_m, yaw_rad), got shape {a.shape}")
    if not np.isfinite(a).all():
        raise ValueError(f"{name} must be finite, got {a.tolist()}")
    return (float(a[0]), float(a[1]), float(a[2]))
