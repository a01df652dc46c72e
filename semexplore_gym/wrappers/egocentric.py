"""The :class:`EgocentricObservation` wrapper (features computed in :mod:`semexplore_gym.core.features.egocentric`)."""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from semexplore_gym.core.features.egocentric import (  # noqa: F401  (re-exported)
    N_FEATURES,
    EgocentricEncoder,
    EgocentricParams,
    egocentric_features,
    mirror_observations,
)


def egocentric_observation_space(params: EgocentricParams) -> spaces.Dict:
    """The ``Dict`` space of :func:`egocentric_features` outputs for ``params``."""
    c = params.crop_cells
    return spaces.Dict(
        {
            "image": spaces.Box(0, 255, shape=(params.n_channels, c, c), dtype=np.uint8),
            "scan": spaces.Box(0.0, 1.0, shape=(params.n_scan_bins,), dtype=np.float32),
            "features": spaces.Box(0.0, 1.0, shape=(N_FEATURES,), dtype=np.float32),
        }
    )


class EgocentricObservation(gym.ObservationWrapper):
    """Replace the global map observation with a robot-centred, heading-up one.

    Args:
        env: A ``SemanticExplore-v0`` env (or one with the same observation and info).
        crop_cells: Side of the square image in crop cells.
        crop_resolution_m: Metres per crop cell (None: the map resolution).
        n_scan_bins: Angular bins of the pooled scan.
        params: Full parameter set; overrides the three keyword arguments above.
    """

    def __init__(
        self,
        env: gym.Env,
        crop_cells: int = 64,
        crop_resolution_m: float | None = 0.1,
        n_scan_bins: int = 60,
        params: EgocentricParams | None = None,
    ) -> None:
        super().__init__(env)
        self.params = params or EgocentricParams(
            crop_cells=crop_cells, crop_resolution_m=crop_resolution_m, n_scan_bins=n_scan_bins
        )
        self.observation_space = egocentric_observation_space(self.params)
        self._encoder: EgocentricEncoder | None = None
        base = env.unwrapped
        geometry = getattr(base, "map_geometry", None)
        config = getattr(base, "config", None)
        if geometry is not None and config is not None:
            self._encoder = EgocentricEncoder(
                self.params, geometry, config.lidar.max_range_m, config.lidar.n_beams
            )

    def _sync(self, info: dict[str, Any]) -> None:
        # Procedural worlds are redrawn at reset; rebuild only if the map frame really changed.
        if "map_geometry" in info and (self._encoder is None or not self._encoder.matches(info)):
            self._encoder = EgocentricEncoder.from_info(self.params, info)

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[Any, dict[str, Any]]:
        obs, info = self.env.reset(seed=seed, options=options)
        self._sync(info)
        if self._encoder is not None:
            self._encoder.reset()  # a new episode: forget the previous trail
        return self.observation(obs), info

    def step(self, action: Any) -> tuple[Any, float, bool, bool, dict[str, Any]]:
        obs, reward, terminated, truncated, info = self.env.step(action)
        self._sync(info)
        return self.observation(obs), float(reward), terminated, truncated, info

    def observation(self, observation: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
        if self._encoder is None:
            raise RuntimeError("EgocentricObservation: call reset() before step()")
        return self._encoder.encode(observation)
