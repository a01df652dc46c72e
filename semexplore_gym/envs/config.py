"""The env's configuration: one frozen dataclass per concern, composed into :class:`EnvConfig`."""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from semexplore_gym.core.mapping.occupancy_grid import MappingParams
from semexplore_gym.core.mapping.odometry import OdometryNoiseParams
from semexplore_gym.core.params import ConfigError, from_dict, load_yaml, merge_overrides
from semexplore_gym.sim.lidar import LidarParams
from semexplore_gym.sim.robot import PhysicsParams, RobotParams


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


@dataclass(frozen=True)
class EpisodeParams:
    """Timing, start and end of an episode.

    Attributes:
        dt_s: Control period, one LiDAR scan per step (5 Hz like the LDS-01).
        max_time_s: Simulated time after which the episode is truncated.
        coverage_goal: Coverage at which the episode terminates.
        start_clearance_margin_m: Margin beyond the robot radius for sampled start poses.
        start_pose: ``[x_m, y_m, yaw_rad]`` to start from, or None for the world's own start
            pose, or a pose sampled in free space when the world has none.
        random_start: Sample the start pose even when the world defines one.
    """

    dt_s: float = 0.2
    max_time_s: float = 1200.0
    coverage_goal: float = 0.99
    start_clearance_margin_m: float = 0.1
    start_pose: tuple[float, float, float] | None = None
    random_start: bool = False

    def __post_init__(self) -> None:
        if not (0 < self.dt_s <= 2.0):
            raise ValueError(f"episode.dt_s must be in (0, 2] s, got {self.dt_s!r}")
        if not (self.max_time_s > 0 and math.isfinite(self.max_time_s)):
            raise ValueError(f"episode.max_time_s must be positive, got {self.max_time_s!r}")
        if not (0 < self.coverage_goal <= 1):
            raise ValueError(f"episode.coverage_goal must be in (0, 1], got {self.coverage_goal!r}")
        if self.start_clearance_margin_m < 0:
            raise ValueError(
                f"episode.start_clearance_margin_m must be >= 0, got {self.start_clearance_margin_m!r}"
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


#: Config keys renamed since they were published: old dotted path -> new one.
RENAMED_KEYS: dict[str, str] = {
    # "new area" read as m^2 newly mapped, but the term is a net change (it can be negative).
    "reward.new_area_weight": "reward.free_area_change_weight",
}


def _reject_renamed_keys(data: dict[str, Any]) -> None:
    for old, new in RENAMED_KEYS.items():
        section, key = old.split(".")
        if isinstance(data.get(section), dict) and key in data[section]:
            raise ConfigError(
                f"config key {old!r} was renamed {new!r} (the term is the net change of the map's "
                "free area per step, negative when free cells are re-marked occupied); "
                f"use {new}={data[section][key]!r}"
            )


#: Named configurations; ``configs/<name>.yaml`` in the repository holds the same values.
PRESETS: dict[str, dict[str, Any]] = {
    "default": {},
    # The paper's TurtleBot3 limits (section IV): 0.15 m/s and 2 rad/s.
    "paper": {"robot": {"max_linear_speed_mps": 0.15, "max_angular_speed_radps": 2.0}},
}


def load_env_config(
    config: EnvConfig | str | os.PathLike | dict | None = None, overrides: list[str] | None = None
) -> EnvConfig:
    """Resolve ``config`` (None, a preset name, a YAML path, a dict or an EnvConfig) plus overrides.

    Args:
        config: What to start from; a string that is not a preset name is read as a YAML file.
        overrides: ``"section.key=value"`` strings applied on top.

    Raises:
        ConfigError: unknown preset, unknown key (named with its dotted path) or a bad value.
        FileNotFoundError: a config path that does not exist.
    """
    if isinstance(config, EnvConfig) and not overrides:
        return config
    if isinstance(config, EnvConfig):
        from semexplore_gym.core.params import to_dict

        data: dict[str, Any] = to_dict(config)
    elif config is None:
        data = {}
    elif isinstance(config, dict):
        data = config
    elif isinstance(config, (str, os.PathLike)):
        text = str(config)
        if text in PRESETS:
            data = PRESETS[text]
        elif text.endswith((".yaml", ".yml")) or os.sep in text or Path(text).exists():
            data = load_yaml(text)
        else:
            raise ConfigError(
                f"unknown config {text!r}: not a preset ({', '.join(PRESETS)}) nor a .yaml file"
            )
    else:
        raise ConfigError(
            f"config must be None, a preset name, a YAML path, a dict or an EnvConfig; got {type(config).__name__}"
        )
    data = merge_overrides(data, overrides or [])
    _reject_renamed_keys(data)
    return from_dict(EnvConfig, data)
