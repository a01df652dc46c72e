"""Run a trained SB3 model (PPO, or a policy saved by BC/DAgger) as a :class:`Policy`.

A model may have been trained on any of ``SemanticExplore-v0``'s observation variants; the
policy tells them apart by the model's observation space and computes that observation from
the raw one (a policy cannot import the wrappers, so it uses the same ``core`` functions):

========================  ==============================================  ====================
variant                   model observation space                         runs on
========================  ==============================================  ====================
``egocentric``            ``image`` (C, crop, crop), ``scan``,            any world
                          ``features`` (``EgocentricObservation``)
``fixed_size``            ``map`` (1, S, S), ``pose``, ``scan``           any world
                          (``FixedSizeMap``; pass ``map_anchor="robot"``
                          for a robot-anchored model)
``raw``                   ``map`` (H, W), ``pose``, ``scan``              worlds whose map is
                          (the env's own Dict)                            H x W cells
========================  ==============================================  ====================

Anything else (a flat vector: a macro-action agent without its ``config.yaml``, or a
``FlattenObservation`` model) fails at load with a message saying which wrapper the model needs.
"""

from __future__ import annotations

import os
import time
from pathlib import Path
from typing import Any

import numpy as np
from semexplore_gym.policies.base import Policy, StepStats
from semexplore_gym.policies.sb3_model import learner_action, load_model

from semexplore_gym.config.extras import require_extra
from semexplore_gym.core.features.egocentric import EgocentricEncoder, EgocentricParams
from semexplore_gym.core.features.map_window import MAP_ANCHORS, map_window, window_origin
from semexplore_gym.core.grid import GridGeometry

#: Observation variants an SB3 model can be trained on (see the module docstring).
OBSERVATION_VARIANTS: tuple[str, ...] = ("egocentric", "fixed_size", "raw")

_EGOCENTRIC_KEYS = frozenset({"image", "scan", "features"})
_RAW_KEYS = frozenset({"map", "pose", "scan"})
_FIXED_SIZE_HINT = (
    "wrap the env in semexplore_gym.wrappers.FixedSizeMap(env, map_size=S) for a map of the "
    "same shape on every world"
)


def observation_variant(space: Any, params: EgocentricParams, where: str = "model") -> str:
    """Which observation variant (:data:`OBSERVATION_VARIANTS`) a model's observation space is.

    Args:
        space: The model's ``observation_space``.
        params: The egocentric parameters recorded in the model zip (or the defaults).
        where: Names the model in error messages.

    Raises:
        ValueError: the space is none of the variants; the message names the wrapper the model
            needs (or the one it cannot be run without).
    """
    shapes = getattr(space, "spaces", None)
    if not isinstance(shapes, dict):
        shape = tuple(getattr(space, "shape", None) or ())
        raise ValueError(
            f"{where} observes a flat vector {shape}, not a SemanticExplore-v0 Dict. A "
            "macro-action agent (the FrontierChoice / PlannerWeights wrappers, env ids "
            "SemanticExploreFrontier-v0 / SemanticExploreWeights-v0) runs through 'sb3:' only "
            "beside the config.yaml that 'semexplore train' writes next to model.zip; a "
            "FlattenObservation model cannot run: train on the Dict (MultiInputPolicy) of "
            "EgocentricObservation or FixedSizeMap instead"
        )
    keys = frozenset(shapes)
    if keys == _EGOCENTRIC_KEYS:
        image = tuple(shapes["image"].shape)
        c = params.crop_cells
        if image != (params.n_channels, c, c) or tuple(shapes["scan"].shape) != (
            params.n_scan_bins,
        ):
            raise ValueError(
                f"{where} was trained on EgocentricObservation with image {image} and scan "
                f"{tuple(shapes['scan'].shape)}, but its recorded egocentric parameters give "
                f"{(params.n_channels, c, c)} and ({params.n_scan_bins},); a model trained "
                "outside 'semexplore train' must be tagged with its EgocentricParams "
                "(semexplore_gym.training.learner.tag_model_zip)"
            )
        return "egocentric"
    if keys == _RAW_KEYS:
        map_shape = tuple(shapes["map"].shape)
        if len(map_shape) == 3 and map_shape[0] == 1 and map_shape[1] == map_shape[2]:
            return "fixed_size"
        if len(map_shape) == 2:
            return "raw"
        raise ValueError(
            f"{where} observes a map of shape {map_shape}: neither the raw (H, W) map nor "
            f"FixedSizeMap's (1, S, S); {_FIXED_SIZE_HINT}"
        )
    raise ValueError(
        f"{where} observes keys {sorted(keys)}, none of SemanticExplore-v0's variants: "
        f"{sorted(_RAW_KEYS)} (the raw env, or the FixedSizeMap wrapper) or "
        f"{sorted(_EGOCENTRIC_KEYS)} (the EgocentricObservation wrapper)"
    )


class SB3Policy(Policy):
    """A learned agent: the model's observation variant of the raw observation -> SB3 -> action.

    An egocentric model's zip records the egocentric parameters it was trained with (written by
    ``semexplore train``), so the same features are computed here from the raw observation.
    Models of the other variants (module docstring) run too, or fail at load with a message
    naming the wrapper they need.

    Args:
        model_path: A model zip from ``semexplore train`` (PPO zip or BC/DAgger policy zip).
        deterministic: Use the mean action (True) or sample from the policy (False).
        device: torch device.
        num_threads: ``torch.set_num_threads`` value applied when the model loads (process-wide);
            None leaves torch's setting alone. One thread is the default because a batch-one
            forward pass of these small nets runs about 5-10x faster single-threaded on a busy
            2-core machine than with torch's default of one thread per core.
        map_anchor: For a ``fixed_size`` model: the ``FixedSizeMap`` anchor it was trained with
            (``"world"``, the wrapper's default, or ``"robot"``); the model zip does not record it.

    Raises:
        ValueError: the model's observation is none of the variants (the message names the
            wrapper it needs), or, at ``reset``, a ``raw`` model meets a world of another size.
    """

    name = "sb3"

    def __init__(
        self,
        model_path: str | os.PathLike,
        deterministic: bool = True,
        device: str = "cpu",
        num_threads: int | None = 1,
        map_anchor: str = "world",
    ) -> None:
        super().__init__()
        require_extra("rl", f"the trained model {str(model_path)!r}", "torch", "stable_baselines3")
        if map_anchor not in MAP_ANCHORS:
            raise ValueError(f"map_anchor must be one of {MAP_ANCHORS}, got {map_anchor!r}")
        if num_threads is not None:
            if not isinstance(num_threads, int) or num_threads < 1:
                raise ValueError(
                    f"num_threads must be a positive integer or None, got {num_threads!r}"
                )
            import torch as th

            th.set_num_threads(num_threads)

        self.model_path = Path(model_path)
        self.deterministic = bool(deterministic)
        self.policy, self.params = load_model(self.model_path, device=device)
        self.name = f"sb3:{self.model_path.name}"
        self.variant = observation_variant(
            self.policy.observation_space, self.params, f"model {str(self.model_path)!r}"
        )
        self.map_anchor = map_anchor
        self._encoder: EgocentricEncoder | None = None
        self._geometry: GridGeometry | None = None
        self._geometry_info: Any = None  # the info mapping _geometry was built from

    def reset(
        self, obs: dict[str, np.ndarray], info: dict[str, Any], seed: int | None = None
    ) -> None:
        super().reset(obs, info, seed=seed)
        if self.variant == "egocentric":
            self._encoder = EgocentricEncoder.from_info(self.params, info)
        else:
            self._check_raw(obs, info)
        if not self.deterministic:
            import torch as th

            # Sampling draws from torch's global generator; seed it from the episode seed.
            th.manual_seed(int(self.rng.integers(0, 2**31 - 1)))

    def act(self, obs: dict[str, np.ndarray], info: dict[str, Any]) -> np.ndarray:
        t0 = time.perf_counter()
        features = self._features(obs, info)
        t1 = time.perf_counter()
        action = learner_action(self.policy, features, deterministic=self.deterministic)
        t2 = time.perf_counter()
        self.last_stats = StepStats(
            map_generation_ms=(t1 - t0) * 1e3, local_planning_ms=(t2 - t1) * 1e3
        )
        return action

    def _features(self, obs: dict[str, np.ndarray], info: dict[str, Any]) -> dict[str, np.ndarray]:
        """The model's observation computed from the raw one."""
        if self.variant == "egocentric":
            if self._encoder is None or (
                "map_geometry" in info and not self._encoder.matches(info)
            ):
                self._encoder = EgocentricEncoder.from_info(self.params, info)
            return self._encoder.encode(obs)
        if self._geometry is None or info.get("map_geometry") is not self._geometry_info:
            self._check_raw(obs, info)
        if self.variant == "raw":
            return {"map": obs["map"], "pose": obs["pose"], "scan": obs["scan"]}
        size = int(self.policy.observation_space.spaces["map"].shape[1])
        robot_rc = None
        if self.map_anchor == "robot":
            assert self._geometry is not None
            row, col = self._geometry.world_to_grid(float(obs["pose"][0]), float(obs["pose"][1]))
            robot_rc = (int(row), int(col))
        origin = window_origin(obs["map"].shape, size, self.map_anchor, robot_rc)
        return {
            "map": map_window(obs["map"], origin, size)[None],
            "pose": obs["pose"],
            "scan": obs["scan"],
        }

    def _check_raw(self, obs: dict[str, np.ndarray], info: dict[str, Any]) -> None:
        """Raise a ValueError when a raw / fixed-size model cannot take this world's observation."""
        self._geometry_info = info.get("map_geometry")
        if self._geometry_info is not None:
            self._geometry = GridGeometry.from_dict(self._geometry_info)
        elif self.variant == "fixed_size" and self.map_anchor == "robot":
            raise ValueError(
                "info lacks 'map_geometry'; pass the info dict returned by the env's reset/step"
            )
        spaces = self.policy.observation_space.spaces
        want_scan = tuple(spaces["scan"].shape)
        if tuple(np.shape(obs["scan"])) != want_scan:
            raise ValueError(
                f"{self.name} was trained with a {want_scan[0]}-beam LiDAR; this env's scan has "
                f"{np.shape(obs['scan'])[0]} beams (set lidar.n_beams={want_scan[0]})"
            )
        want_map = tuple(spaces["map"].shape)
        if self.variant == "raw" and tuple(np.shape(obs["map"])) != want_map:
            raise ValueError(
                f"{self.name} was trained on the raw observation of a {want_map[0]}x"
                f"{want_map[1]}-cell map and runs only on worlds of that size; this world's map "
                f"is {np.shape(obs['map'])[0]}x{np.shape(obs['map'])[1]} cells: {_FIXED_SIZE_HINT}"
            )
