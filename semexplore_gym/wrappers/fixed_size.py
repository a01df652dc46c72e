"""The :class:`FixedSizeMap` wrapper: one observation shape for every world.

``SemanticExplore-v0``'s ``map`` has the shape of each world's grid (164x164 on ``maze1``,
260x260 on a 12 m forest, ...), so worlds cannot share a vector env and a CNN cannot take it.
This wrapper pads (with UNKNOWN) or crops the map to ``map_size`` cells and gives it a leading
channel axis, ready for SB3's ``MultiInputPolicy`` (its NatureCNN takes channel-first uint8
images of at least 36x36)::

    import gymnasium as gym, semexplore_gym
    from semexplore_gym.wrappers import FixedSizeMap
    envs = gym.make_vec(
        "SemanticExplore-v0", num_envs=2, vectorization_mode="sync",
        wrappers=[lambda e: FixedSizeMap(e, map_size=128, anchor="robot")],
    )

Anchors: ``"world"`` keeps the map's centre at the image centre (the whole map when it fits;
the frame does not move, so the robot moves in the image), ``"robot"`` centres the image on the
robot's cell (north-up: the map is not rotated; :class:`EgocentricObservation` is the
heading-up variant). ``pose`` and ``scan`` are passed through; ``info["map_offset_cells"]``
gives the image's ``(row, col)`` origin in the full map, so ``image[r, c] == map[r + dr, c +
dc]`` where both exist.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, SupportsFloat, cast

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from semexplore_gym.core.features.map_window import MAP_ANCHORS, map_window, window_origin

if TYPE_CHECKING:
    from semexplore_gym.envs.semantic_explore import SemanticExploreEnv

ANCHORS = MAP_ANCHORS


class FixedSizeMap(gym.ObservationWrapper, gym.utils.RecordConstructorArgs):
    """Pad or crop the occupancy map to a fixed ``(1, map_size, map_size)`` image.

    Args:
        env: A ``SemanticExplore-v0`` env (observation keys ``map``, ``pose``, ``scan``).
        map_size: Side of the square image in map cells (>= 8).
        anchor: ``"world"`` (centred on the map) or ``"robot"`` (centred on the robot's cell).

    Raises:
        ValueError: a bad ``map_size`` or ``anchor``, or an env without a ``map`` observation.
    """

    def __init__(self, env: gym.Env, map_size: int = 128, anchor: str = "world") -> None:
        gym.utils.RecordConstructorArgs.__init__(self, map_size=map_size, anchor=anchor)
        gym.ObservationWrapper.__init__(self, env)
        if isinstance(map_size, bool) or not isinstance(map_size, int | np.integer):
            raise ValueError(f"map_size must be an integer, got {map_size!r}")
        if not 8 <= int(map_size) <= 4096:
            raise ValueError(f"map_size must be in [8, 4096] cells, got {map_size!r}")
        if anchor not in ANCHORS:
            raise ValueError(f"anchor must be one of {ANCHORS}, got {anchor!r}")
        space = env.observation_space
        if not isinstance(space, spaces.Dict) or "map" not in space.spaces:
            raise ValueError(
                "FixedSizeMap needs a Dict observation with a 'map' key (SemanticExplore-v0)"
            )
        self.map_size = int(map_size)
        self.anchor = anchor
        inner = dict(space.spaces)
        inner["map"] = spaces.Box(0, 255, shape=(1, self.map_size, self.map_size), dtype=np.uint8)
        self.observation_space = spaces.Dict(inner)
        self._offset = (0, 0)

    def _origin(self, grid_shape: tuple[int, int], pose: np.ndarray) -> tuple[int, int]:
        robot_rc = None
        if self.anchor == "robot":
            geometry = cast("SemanticExploreEnv", self.env.unwrapped).map_geometry
            row, col = geometry.world_to_grid(float(pose[0]), float(pose[1]))
            robot_rc = (int(row), int(col))
        return window_origin(grid_shape, self.map_size, self.anchor, robot_rc)

    def observation(self, observation: dict[str, Any]) -> dict[str, Any]:
        grid = observation["map"]
        self._offset = self._origin(grid.shape, observation["pose"])
        out = dict(observation)
        out["map"] = map_window(grid, self._offset, self.map_size)[None]
        return out

    def reset(self, **kwargs: Any) -> tuple[dict[str, Any], dict[str, Any]]:
        obs, info = self.env.reset(**kwargs)
        obs = self.observation(obs)
        return obs, dict(info, map_offset_cells=self._offset)

    def step(self, action: Any) -> tuple[dict[str, Any], SupportsFloat, bool, bool, dict[str, Any]]:
        obs, reward, terminated, truncated, info = self.env.step(action)
        obs = self.observation(obs)
        return obs, reward, terminated, truncated, dict(info, map_offset_cells=self._offset)
