"""The static ``info`` entries of the env: fixed by its config, built once, shared read-only by
every step's ``info`` (the single-robot env and each agent of the multi-robot env)."""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from typing import Any

from semexplore_gym.core.grid import GridGeometry
from semexplore_gym.envs.env_config import EnvConfig


class FrozenInfo(Mapping):
    """A read-only mapping: the static ``info`` entries, built once per env.

    Every step's ``info`` shares the same instances, so nothing is rebuilt per step and no
    caller can change what the next step reports. It is not a ``dict``, so gymnasium's vector
    envs collect it as one object per env instead of one array per field (much cheaper per
    step). ``dict(info["robot"])`` gives a plain, mutable copy.
    """

    __slots__ = ("_d",)

    def __init__(self, entries: Mapping[str, Any]) -> None:
        self._d = dict(entries)

    def __getitem__(self, key: str) -> Any:
        return self._d[key]

    def __iter__(self) -> Iterator[str]:
        return iter(self._d)

    def __len__(self) -> int:
        return len(self._d)

    def __repr__(self) -> str:
        return f"FrozenInfo({self._d!r})"

    def __reduce__(self) -> tuple[Any, ...]:
        return (FrozenInfo, (self._d,))


def static_info_of(config: EnvConfig, geometry: GridGeometry) -> dict[str, Any]:
    """The ``info`` entries fixed by the config (shared read-only mappings), the same for the
    single-robot env and each agent of the multi-robot env."""
    cfg = config
    return {
        "map_geometry": FrozenInfo(geometry.to_dict()),
        "robot": FrozenInfo(
            {
                "radius_m": cfg.robot.radius_m,
                "max_linear_speed_mps": cfg.robot.max_linear_speed_mps,
                "max_angular_speed_radps": cfg.robot.max_angular_speed_radps,
            }
        ),
        "lidar": FrozenInfo(
            {
                "n_beams": cfg.lidar.n_beams,
                "min_range_m": cfg.lidar.min_range_m,
                "max_range_m": cfg.lidar.max_range_m,
                "angle_increment_rad": cfg.lidar.angle_increment_rad,
                "mount_x_m": cfg.lidar.mount_x_m,
                "mount_y_m": cfg.lidar.mount_y_m,
            }
        ),
        "dt_s": cfg.episode.dt_s,
    }
