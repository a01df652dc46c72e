"""The env's configuration: one frozen dataclass per concern, composed into :class:`EnvConfig`."""

from __future__ import annotations

import math
import os
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from typing import Any

from semexplore_gym.config import build_params
from semexplore_gym.core.mapping.occupancy_grid import MappingParams
from semexplore_gym.core.mapping.odometry import OdometryNoiseParams
from semexplore_gym.core.slam.params import SlamParams
from semexplore_gym.sim.lidar import LidarParams
from semexplore_gym.sim.robot import PhysicsParams, RobotParams

#: Largest reward weight magnitude: beyond it sums of terms lose precision or overflow.
MAX_REWARD_WEIGHT = 1e6

#: Longest LiDAR range the env accepts: far beyond any real 2D LiDAR (the LDS-01 reaches 3.5 m),
#: and the scan observation's float32 bound must hold it.
MAX_LIDAR_RANGE_M = 1000.0

#: Largest travel per physics substep near walls that keeps wall penetration under 1 cm (the
#: no-penetration promise) with the solver's own slack on top; measured, see tests/fuzz.
MAX_SUBSTEP_TRAVEL_M = 0.005


@dataclass(frozen=True)
class RewardParams:
    """Weights of the named reward terms; ``reward = sum(weight * term)``.

    Terms: ``free_area_change`` = the net change of the map's free area this step (m^2): cells
    newly mapped free minus free cells re-marked occupied, so it is negative on some steps (about
    a quarter of random-action steps, where a wall's edge is re-observed); ``time`` = the control
    period (s); ``collision`` = 1 when a new wall contact began this step.
    """

    free_area_change_weight: float = 1.0
    time_weight: float = -0.01
    collision_weight: float = -1.0

    def __post_init__(self) -> None:
        for name in ("free_area_change_weight", "time_weight", "collision_weight"):
            v = getattr(self, name)
            if not (math.isfinite(v) and abs(v) <= MAX_REWARD_WEIGHT):
                raise ValueError(
                    f"reward.{name} must be a finite number in [-{MAX_REWARD_WEIGHT:g}, "
                    f"{MAX_REWARD_WEIGHT:g}], got {v!r}"
                )


@dataclass(frozen=True)
class EpisodeParams:
    """Timing, start and end of an episode.

    Attributes:
        dt_s: Control period, one LiDAR scan per step (5 Hz like the LDS-01).
        max_time_s: Simulated time after which the episode is truncated.
        coverage_goal: Coverage at which the episode terminates.
        coverage_clearance_margin_m: Coverage counts the free cells the robot's body sweeps
            keeping its centre at least ``robot.radius_m`` plus this from every wall (0.01 m:
            gaps of 0.23 m and wider count for the 0.105 m robot). See
            :func:`~semexplore_gym.envs.coverage_mask.coverage_mask`.
        start_clearance_margin_m: Margin beyond the robot radius for sampled start poses.
        start_pose: ``[x_m, y_m, yaw_rad]`` to start from, or None for the world's own start
            pose, or a pose sampled in free space when the world has none.
        random_start: Sample the start pose even when the world defines one.
    """

    dt_s: float = 0.2
    max_time_s: float = 1200.0
    coverage_goal: float = 0.99
    coverage_clearance_margin_m: float = 0.01
    start_clearance_margin_m: float = 0.1
    start_pose: tuple[float, float, float] | None = None
    random_start: bool = False

    def __post_init__(self) -> None:
        if not (0 < self.dt_s <= 2.0):
            raise ValueError(f"episode.dt_s must be in (0, 2] s, got {self.dt_s!r}")
        if not (0 < self.max_time_s <= 1e7):
            raise ValueError(
                f"episode.max_time_s must be positive and at most 1e7 s, got {self.max_time_s!r}"
            )
        if not (0 < self.coverage_goal <= 1):
            raise ValueError(f"episode.coverage_goal must be in (0, 1], got {self.coverage_goal!r}")
        if not (0 <= self.coverage_clearance_margin_m <= 1.0):
            raise ValueError(
                "episode.coverage_clearance_margin_m must be in [0, 1] m, got "
                f"{self.coverage_clearance_margin_m!r}"
            )
        if not (0 <= self.start_clearance_margin_m <= 10.0):
            raise ValueError(
                f"episode.start_clearance_margin_m must be in [0, 10] m, got {self.start_clearance_margin_m!r}"
            )
        if self.start_pose is not None and not all(math.isfinite(v) for v in self.start_pose):
            raise ValueError(f"episode.start_pose must be finite, got {self.start_pose!r}")


@dataclass(frozen=True)
class EnvConfig:
    """Everything that defines a SemanticExplore env apart from the world."""

    robot: RobotParams = field(default_factory=RobotParams)
    physics: PhysicsParams = field(default_factory=PhysicsParams)
    lidar: LidarParams = field(default_factory=LidarParams)
    mapping: MappingParams = field(default_factory=MappingParams)
    odometry: OdometryNoiseParams = field(default_factory=OdometryNoiseParams)
    reward: RewardParams = field(default_factory=RewardParams)
    episode: EpisodeParams = field(default_factory=EpisodeParams)
    slam: SlamParams = field(default_factory=SlamParams)

    def __post_init__(self) -> None:
        if not self.lidar.max_range_m <= MAX_LIDAR_RANGE_M:
            raise ValueError(
                f"lidar.max_range_m must be at most {MAX_LIDAR_RANGE_M:g} m, got "
                f"{self.lidar.max_range_m!r}"
            )
        # Substeps per control step are ceil(speed * dt / max_substep_travel_m), capped at
        # max_substeps; past the cap each substep travels further and the robot can sink into
        # (or pass) a wall. Refuse such combinations instead of silently capping.
        travel_m = self.robot.max_linear_speed_mps * self.episode.dt_s
        needed = math.ceil(travel_m / MAX_SUBSTEP_TRAVEL_M - 1e-9)
        pp = self.physics
        used = min(pp.max_substeps, max(1, math.ceil(travel_m / pp.max_substep_travel_m)))
        if used < needed:
            raise ValueError(
                f"robot.max_linear_speed_mps={self.robot.max_linear_speed_mps:g} x "
                f"episode.dt_s={self.episode.dt_s:g} = {travel_m:.3g} m per step needs at least "
                f"{needed} physics substeps of <= {MAX_SUBSTEP_TRAVEL_M:g} m to keep wall "
                f"penetration under 0.01 m, but physics.max_substeps={pp.max_substeps} and "
                f"physics.max_substep_travel_m={pp.max_substep_travel_m:g} give {used}; raise "
                "physics.max_substeps (or lower max_substep_travel_m, the speed or dt_s)"
            )
        if self.robot.radius_m <= 2.0 * self.physics.max_substep_travel_m:
            raise ValueError(
                f"robot.radius_m={self.robot.radius_m:g} must exceed twice "
                f"physics.max_substep_travel_m={self.physics.max_substep_travel_m:g}"
            )


#: Config keys renamed since they were published: old dotted path -> (new one, why).
RENAMED_KEYS: dict[str, tuple[str, str]] = {
    "reward.new_area_weight": (
        "reward.free_area_change_weight",
        "the term is the net change of the map's free area per step, negative when free cells "
        "are re-marked occupied",
    ),
}


#: Named configurations, the layers ``config="<name>"`` stands for. ``configs/<name>.yaml`` in
#: the repository holds the same values (tests/envs/test_env_config.py compares them).
PRESETS: dict[str, EnvConfig] = {
    "default": EnvConfig(),
    # The paper's TurtleBot3 limits (section IV): 0.15 m/s and 2 rad/s.
    "paper": EnvConfig(robot=RobotParams(max_linear_speed_mps=0.15, max_angular_speed_radps=2.0)),
    # SLAM in the loop: odometry drift at 0.02 on all four alphas, the map and pose from SLAM.
    "slam": EnvConfig(
        odometry=OdometryNoiseParams(0.02, 0.02, 0.02, 0.02), slam=SlamParams(enabled=True)
    ),
}


def load_env_config(
    config: EnvConfig | str | os.PathLike | Mapping[str, Any] | None = None,
    overrides: Iterable[str] | None = None,
) -> EnvConfig:
    """Resolve ``config`` (None, a preset name, a YAML path, a mapping or an EnvConfig) plus overrides.

    :func:`~semexplore_gym.config.build_params` with the env's :data:`PRESETS`.

    Args:
        config: What to start from; a string that is not a preset name is read as a YAML file.
        overrides: ``"section.key=value"`` strings applied on top.

    Raises:
        ConfigError: unknown preset, unknown key (named with its dotted path) or a bad value.
        FileNotFoundError: a config path that does not exist.
    """
    return build_params(
        EnvConfig, config, overrides=overrides or (), presets=PRESETS, renamed=RENAMED_KEYS
    )
