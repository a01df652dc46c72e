"""World specs, the one entry point for every world: ``make_world("maze1")``,
``make_world("office:seed=3,size_m=20")``, ``make_world("map.yaml")``,
``make_world("map:tb3-world")``. Worlds made by code are
:mod:`semexplore_gym.core.worlds.procedural`; files are read here, in :mod:`.ros_map` and
:mod:`.houseexpo`."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from semexplore_gym.core.worlds.procedural import make_procedural_world
from semexplore_gym.core.worlds.world import World
from semexplore_gym.maps.catalogue import resolve_map_file
from semexplore_gym.maps.houseexpo import load_houseexpo_world
from semexplore_gym.maps.ros_map import load_ros_map_world

_ROS_SUFFIXES = (".yaml", ".yml")
_JSON_SUFFIXES = (".json",)
_CATALOGUE_PREFIX = "map:"


def _is_file_spec(spec: str | os.PathLike) -> bool:
    if isinstance(spec, os.PathLike):
        return True
    return str(spec).lower().endswith(_ROS_SUFFIXES + _JSON_SUFFIXES)


def make_world(spec: str | os.PathLike, rng: np.random.Generator | None = None) -> World:
    """Build a world from its spec.

    Spellings:

    - ``"maze1"``, ``"maze:seed=3,size_m=10"``, ``"office"``, ...: a fixed or procedural world,
      built by :func:`~semexplore_gym.core.worlds.procedural.make_procedural_world` (seeded
      from ``rng`` when the spec gives no ``seed=``).
    - a path ending ``.yaml`` / ``.yml`` (ROS map_server map) or ``.json`` (HouseExpo plan).
    - ``"map:NAME"``: a catalogue map (``semexplore maps list``), read from the directories in
      ``$SEMEXPLORE_MAPS_DIR`` or else the map cache, where ``semexplore maps get NAME`` puts it
      (:mod:`.catalogue`).

    Args:
        spec: The spec string or a path.
        rng: Source of the seed for procedural worlds given without one.

    Raises:
        ValueError: unknown world name or family, unknown or ill-typed or out-of-range
            parameter (the message names it and lists the valid ones), malformed file.
        FileNotFoundError: a map file that does not exist, or a catalogue map not downloaded.
    """
    if isinstance(spec, str) and spec.strip().startswith(_CATALOGUE_PREFIX):
        map_name = spec.strip()[len(_CATALOGUE_PREFIX) :].strip()
        spec, label = resolve_map_file(map_name), f"{_CATALOGUE_PREFIX}{map_name}"
    else:
        label = str(spec)
    if _is_file_spec(spec):
        path = Path(spec)
        if not path.is_file():
            raise FileNotFoundError(f"world file not found: {path}")
        if path.suffix.lower() in _ROS_SUFFIXES:
            return load_ros_map_world(path, name=label)
        if path.suffix.lower() in _JSON_SUFFIXES:
            return load_houseexpo_world(path, name=label)
        raise ValueError(
            f"world file {path} has an unsupported extension; use .yaml/.yml (ROS map) or .json (HouseExpo)"
        )
    return make_procedural_world(str(spec), rng)
