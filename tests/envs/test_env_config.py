"""The env's config path: presets, YAML files and overrides, and configs/*.yaml vs the presets."""

from __future__ import annotations

from pathlib import Path

import pytest

from semexplore_gym.config import ConfigError, build_params
from semexplore_gym.envs.env_config import PRESETS, EnvConfig, load_env_config

CONFIGS = Path(__file__).resolve().parents[2] / "configs"


@pytest.mark.parametrize("name", sorted(PRESETS))
def test_configs_yaml_equals_the_preset(name: str) -> None:
    """configs/<preset>.yaml holds the preset's values; loaded by the one config path."""
    assert build_params(EnvConfig, CONFIGS / f"{name}.yaml") == PRESETS[name]
    assert load_env_config(str(CONFIGS / f"{name}.yaml")) == load_env_config(name)


def test_paper_preset_is_the_papers_turtlebot() -> None:
    robot = PRESETS["paper"].robot
    assert (robot.max_linear_speed_mps, robot.max_angular_speed_radps) == (0.15, 2.0)
    assert PRESETS["paper"].lidar == EnvConfig().lidar


def test_layers_then_overrides() -> None:
    cfg = load_env_config("paper", ["episode.max_time_s=60", "lidar.n_beams=180"])
    assert cfg.robot == PRESETS["paper"].robot
    assert (cfg.episode.max_time_s, cfg.lidar.n_beams) == (60.0, 180)
    assert load_env_config(cfg) is cfg
    assert load_env_config(cfg, ["episode.max_time_s=30"]).episode.max_time_s == 30.0
    assert load_env_config({"episode.dt_s": 0.1}).episode.dt_s == 0.1
    assert load_env_config() == EnvConfig()


def test_unknown_preset_and_key_are_named() -> None:
    with pytest.raises(ConfigError, match="not a preset"):
        load_env_config("papr")
    with pytest.raises(ConfigError, match="lidar.n_beamz"):
        load_env_config(overrides=["lidar.n_beamz=3"])
