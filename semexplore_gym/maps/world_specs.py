"""World specs, the one entry point for every world: ``make_world("maze1")``,
``make_world("office:seed=3,size_m=20")``, ``make_world("map.yaml")``,
``make_world("map:tb3-world")``, ``make_world("map:dungeon-test-img-9900")``. Worlds made by
code are :mod:`semexplore_gym.core.worlds.procedural`; files are read here, in :mod:`.ros_map`,
:mod:`.houseexpo` and :mod:`.dungeon_maps`."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from semexplore_gym.core.worlds.procedural import make_procedural_world
from semexplore_gym.core.worlds.world import World
from semexplore_gym.maps.catalogue import resolve_map_file
from semexplore_gym.maps.dungeon_maps import DUNGEON_M_PER_PX, load_dungeon_map_world
from semexplore_gym.maps.houseexpo import load_houseexpo_world
from semexplore_gym.maps.ros_map import load_ros_map_world

_ROS_SUFFIXES = (".yaml", ".yml")
_JSON_SUFFIXES = (".json",)
_PNG_SUFFIXES = (".png",)
_CATALOGUE_PREFIX = "map:"
#: Options a ``map:NAME,key=value`` spec may give (DungeonMaps only).
_MAP_OPTIONS = ("m_per_px",)


def _is_file_spec(spec: str | os.PathLike) -> bool:
    if isinstance(spec, os.PathLike):
        return True
    return str(spec).lower().endswith(_ROS_SUFFIXES + _JSON_SUFFIXES + _PNG_SUFFIXES)


def _map_options(spec: str) -> tuple[str, dict[str, float]]:
    """``"NAME,m_per_px=0.05"`` -> ``("NAME", {"m_per_px": 0.05})`` (names hold no comma)."""
    name, *items = (part.strip() for part in spec.split(","))
    options: dict[str, float] = {}
    for item in items:
        key, eq, value = item.partition("=")
        if not eq or key.strip() not in _MAP_OPTIONS:
            raise ValueError(
                f"map:{name}: unknown option {item!r}; a map takes {', '.join(_MAP_OPTIONS)}="
                "VALUE (DungeonMaps only)"
            )
        try:
            options[key.strip()] = float(value)
        except ValueError:
            raise ValueError(f"map:{name}: {key.strip()} must be a number, got {value!r}") from None
    return name, options


def make_world(spec: str | os.PathLike, rng: np.random.Generator | None = None) -> World:
    """Build a world from its spec.

    Spellings:

    - ``"maze1"``, ``"maze:seed=3,size_m=10"``, ``"office"``, ...: a fixed or procedural world,
      built by :func:`~semexplore_gym.core.worlds.procedural.make_procedural_world` (seeded
      from ``rng`` when the spec gives no ``seed=``).
    - a path ending ``.yaml`` / ``.yml`` (ROS map_server map) or ``.json`` (HouseExpo plan).
    - a path ending ``.png``: a DungeonMaps image (:mod:`.dungeon_maps`, 0.04375 m per pixel).
    - ``"map:NAME"``: a catalogue map (``semexplore maps list``), read from the directories in
      ``$SEMEXPLORE_MAPS_DIR`` or else the map cache, where ``semexplore maps get NAME`` puts it
      (:mod:`.catalogue`). A DungeonMaps entry takes its scale as an option:
      ``"map:dungeon-test-img-9900,m_per_px=0.05"``.

    Args:
        spec: The spec string or a path.
        rng: Source of the seed for procedural worlds given without one.

    Raises:
        ValueError: unknown world name or family, unknown or ill-typed or out-of-range
            parameter (the message names it and lists the valid ones), malformed file.
        FileNotFoundError: a map file that does not exist, or a catalogue map not downloaded.
    """
    options: dict[str, float] = {}
    if isinstance(spec, str) and spec.strip().startswith(_CATALOGUE_PREFIX):
        rest = spec.strip()[len(_CATALOGUE_PREFIX) :]
        map_name, options = _map_options(rest)
        label = _CATALOGUE_PREFIX + ",".join(part.strip() for part in rest.split(","))
        spec = resolve_map_file(map_name)
        if options and Path(spec).suffix.lower() not in _PNG_SUFFIXES:
            raise ValueError(f"map:{map_name} takes no options (only DungeonMaps take m_per_px)")
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
        if path.suffix.lower() in _PNG_SUFFIXES:
            return load_dungeon_map_world(
                path, name=label, m_per_px=options.get("m_per_px", DUNGEON_M_PER_PX)
            )
        raise ValueError(
            f"world file {path} has an unsupported extension; use .yaml/.yml (ROS map), .json "
            "(HouseExpo) or .png (DungeonMaps)"
        )
    return make_procedural_world(str(spec), rng)
