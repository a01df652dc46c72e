"""World specs: ``make_world("maze1")``, ``make_world("office:seed=3,size_m=20")``,
``make_world("map.yaml")``, ``make_world("map:tb3-world")``."""

from __future__ import annotations

import dataclasses
import os
from collections.abc import Callable
from pathlib import Path

import numpy as np

from semexplore_gym.core.worlds.catalogue import resolve_map_file
from semexplore_gym.core.worlds.cave import CaveParams, generate_cave
from semexplore_gym.core.worlds.fixed_mazes import make_maze1, make_maze2
from semexplore_gym.core.worlds.forest import ForestParams, generate_forest
from semexplore_gym.core.worlds.grid_maze import MazeParams, generate_maze
from semexplore_gym.core.worlds.houseexpo import load_houseexpo_world
from semexplore_gym.core.worlds.office import OfficeParams, generate_office
from semexplore_gym.core.worlds.ros_map import load_ros_map_world
from semexplore_gym.core.worlds.world import World

_FIXED: dict[str, Callable[[str], World]] = {"maze1": make_maze1, "maze2": make_maze2}
_FAMILIES: dict[str, tuple[type, Callable[..., World]]] = {
    "maze": (MazeParams, generate_maze),
    "office": (OfficeParams, generate_office),
    "cave": (CaveParams, generate_cave),
    "forest": (ForestParams, generate_forest),
}
_ROS_SUFFIXES = (".yaml", ".yml")
_JSON_SUFFIXES = (".json",)
_CATALOGUE_PREFIX = "map:"


def list_world_names() -> list[str]:
    """Every world name ``make_world`` accepts without a file: fixed worlds and procedural families.

    A family name alone (``"office"``) is a valid spec: default parameters, seed from the rng.
    """
    return sorted([*_FIXED, *_FAMILIES])


def world_family_parameters(family: str) -> dict[str, object]:
    """Default parameters of a procedural family, e.g. ``{"seed": 0, "size_m": 20.0, ...}``."""
    if family not in _FAMILIES:
        raise ValueError(
            f"unknown world family {family!r}; families: {', '.join(sorted(_FAMILIES))}"
        )
    return {f.name: f.default for f in dataclasses.fields(_FAMILIES[family][0])}


def _is_file_spec(spec: str | os.PathLike) -> bool:
    if isinstance(spec, os.PathLike):
        return True
    return str(spec).lower().endswith(_ROS_SUFFIXES + _JSON_SUFFIXES)


def parse_world_spec(spec: str) -> tuple[str, dict[str, str]]:
    """Split ``"name:key=value,key=value"`` into the name and the raw (string) parameters.

    Raises:
        ValueError: an empty name, a parameter without ``=``, an empty key or a repeated key.
    """
    if not isinstance(spec, str):
        raise TypeError(f"a world spec must be a str or a path, got {type(spec).__name__}")
    name, sep, rest = spec.strip().partition(":")
    name = name.strip()
    if not name:
        raise ValueError(
            f"world spec {spec!r} has no name; available worlds: {', '.join(list_world_names())}"
        )
    params: dict[str, str] = {}
    if sep and rest.strip():
        for item in rest.split(","):
            key, eq, value = item.partition("=")
            key = key.strip()
            if not eq or not key:
                raise ValueError(
                    f"world spec {spec!r}: parameter {item.strip()!r} is not key=value"
                )
            if key in params:
                raise ValueError(f"world spec {spec!r}: parameter {key!r} given twice")
            params[key] = value.strip()
    return name, params


def _convert(family: str, key: str, raw: str, field_type: object) -> object:
    if field_type in (int, "int"):
        try:
            return int(raw)
        except ValueError:
            raise ValueError(f"{family} parameter {key}={raw!r} must be an integer") from None
    try:
        value = float(raw)
    except ValueError:
        raise ValueError(f"{family} parameter {key}={raw!r} must be a number") from None
    if not np.isfinite(value):
        raise ValueError(f"{family} parameter {key}={raw!r} must be finite")
    return value


def make_world(spec: str | os.PathLike, rng: np.random.Generator | None = None) -> World:
    """Build a world from its spec.

    Spellings:

    - ``"maze1"``, ``"maze2"``: the fixed test mazes (:mod:`.fixed_mazes`).
    - ``"maze:seed=3,size_m=10,corridor_width_m=0.8,braid=0.3"``, ``"office:seed=3,size_m=20"``,
      ``"cave:seed=1,size_m=15"``, ``"forest:seed=1,size_m=12,density=8"``: procedural families; any parameter may be left out (see
      :func:`world_family_parameters` for the defaults). Without ``seed=`` the seed is drawn from
      ``rng``, so an env's RNG makes the world reproducible; with neither, seed 0 is used.
      ``World.metadata["spec"]`` is the fully resolved spec (seed included).
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

    name, raw_params = parse_world_spec(str(spec))
    if name in _FIXED:
        if raw_params:
            raise ValueError(
                f"world {name!r} is fixed and takes no parameters, got {', '.join(raw_params)}"
            )
        return _FIXED[name](name)
    if name not in _FAMILIES:
        raise ValueError(
            f"unknown world {name!r}; available worlds: {', '.join(list_world_names())} "
            "(or a path to a .yaml ROS map or a .json HouseExpo plan, or map:NAME from "
            "'semexplore maps list')"
        )
    params_cls, generate = _FAMILIES[name]
    fields = {f.name: f for f in dataclasses.fields(params_cls)}
    kwargs: dict[str, object] = {}
    for key, raw in raw_params.items():
        if key not in fields:
            raise ValueError(
                f"unknown {name} parameter {key!r}; valid parameters: {', '.join(fields)}"
            )
        kwargs[key] = _convert(name, key, raw, fields[key].type)
    if "seed" not in kwargs:
        kwargs["seed"] = int(rng.integers(0, 2**31 - 1)) if rng is not None else 0
    params = params_cls(**kwargs)
    return generate(params, name=str(spec).strip())
