"""Worlds made by code, named by a spec string: the fixed mazes (``"maze1"``, ``"maze2"``) and
the procedural families (``"office:seed=3,size_m=20"``, ``"cave"``, ...).

:func:`make_procedural_world` builds them; worlds read from files (ROS maps, HouseExpo plans,
catalogue maps) and the one entry point for every spec, ``make_world``, are in
:mod:`semexplore_gym.maps`."""

from __future__ import annotations

import dataclasses
from collections.abc import Callable

import numpy as np

from semexplore_gym.core.worlds.cave import CaveParams, generate_cave
from semexplore_gym.core.worlds.fixed_mazes import make_maze1, make_maze2
from semexplore_gym.core.worlds.forest import ForestParams, generate_forest
from semexplore_gym.core.worlds.grid_maze import MazeParams, generate_maze
from semexplore_gym.core.worlds.noise_cave import NoiseCaveParams, generate_noise_cave
from semexplore_gym.core.worlds.office import OfficeParams, generate_office
from semexplore_gym.core.worlds.world import World

_FIXED: dict[str, Callable[[str], World]] = {"maze1": make_maze1, "maze2": make_maze2}
_FAMILIES: dict[str, tuple[type, Callable[..., World]]] = {
    "maze": (MazeParams, generate_maze),
    "office": (OfficeParams, generate_office),
    "cave": (CaveParams, generate_cave),
    "forest": (ForestParams, generate_forest),
    "noisecave": (NoiseCaveParams, generate_noise_cave),
}


def list_world_names() -> list[str]:
    """Every world name accepted without a file: fixed worlds and procedural families.

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


def make_procedural_world(spec: str, rng: np.random.Generator | None = None) -> World:
    """Build a fixed or procedural world from its spec string.

    Spellings:

    - ``"maze1"``, ``"maze2"``: the fixed test mazes (:mod:`.fixed_mazes`).
    - ``"maze:seed=3,size_m=10,corridor_width_m=0.8,braid=0.3"``, ``"office:seed=3,size_m=20"``,
      ``"cave:seed=1,size_m=15"``, ``"forest:seed=1,size_m=12,density=8"``,
      ``"noisecave:seed=1,size_m=12,threshold=0.44"``: procedural
      families; any parameter may be left out (see :func:`world_family_parameters` for the
      defaults). Without ``seed=`` the seed is drawn from ``rng``, so an env's RNG makes the
      world reproducible; with neither, seed 0 is used. ``World.metadata["spec"]`` is the fully
      resolved spec (seed included).

    Args:
        spec: The spec string.
        rng: Source of the seed for procedural worlds given without one.

    Raises:
        ValueError: unknown world name or family, unknown or ill-typed or out-of-range
            parameter (the message names it and lists the valid ones).
    """
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
