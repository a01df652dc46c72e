"""The one config path: frozen parameter dataclasses from layers, with strict key checking.

Every parameter set in the project is a frozen dataclass, and every one is built the same way
(env, policies, macro envs, training): :func:`build_params` merges layers in order (a preset
name, a YAML file, a mapping with nested or dotted keys, a dataclass instance), applies
``a.b=value`` override strings, and fills the dataclass with :func:`from_dict`, which rejects
unknown keys with their dotted path, so a typo in a config file is an error, never a silently
ignored setting. YAML is parsed with ``yaml.safe_load`` only (never evaluated).

Example::

    build_params(SemanticExpertParams, {"cost": {"w_v": 2.0}}, overrides=["cost.w_p=0.5"])
    build_params(EnvConfig, "paper", "my.yaml", overrides=["episode.max_time_s=60"], presets=PRESETS)
"""

from __future__ import annotations

import dataclasses
import os
import types
import typing
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any, TypeVar

from semexplore_gym.config.loading import UnsafeInputError, load_yaml_file, load_yaml_text
from semexplore_gym.config.resources import resolve_config_path
from semexplore_gym.core.validation import short_repr

T = TypeVar("T")


class ConfigError(ValueError):
    """A configuration value or key is invalid; the message names its dotted path."""


def _field_types(cls: type) -> dict[str, Any]:
    return typing.get_type_hints(cls)


def _coerce(value: Any, tp: Any, path: str) -> Any:
    """``value`` checked against the annotation ``tp`` and converted; errors name ``path``."""
    origin = typing.get_origin(tp)
    args = typing.get_args(tp)
    if dataclasses.is_dataclass(tp) and isinstance(tp, type):
        if isinstance(value, tp):
            return value
        if not isinstance(value, Mapping):
            raise ConfigError(
                f"{path}: expected a mapping for {tp.__name__}, got {short_repr(value)}"
            )
        return from_dict(tp, value, _prefix=path)
    if origin in (typing.Union, types.UnionType):
        if value is None and type(None) in args:
            return None
        errors = []
        for a in args:
            if a is type(None):
                continue
            try:
                return _coerce(value, a, path)
            except ConfigError as e:
                errors.append(str(e))
        raise ConfigError(f"{path}: {short_repr(value)} does not fit {tp}")
    if origin is typing.Literal:
        if value not in args:
            raise ConfigError(f"{path}: {short_repr(value)} is not one of {list(args)}")
        return value
    if origin in (tuple, list):
        if not isinstance(value, (list, tuple)):
            raise ConfigError(f"{path}: expected a list, got {short_repr(value)}")
        if origin is tuple and args and args[-1] is not Ellipsis:
            if len(args) != len(value):
                raise ConfigError(f"{path}: expected {len(args)} items, got {len(value)}")
            return tuple(
                _coerce(v, a, f"{path}[{i}]")
                for i, (v, a) in enumerate(zip(value, args, strict=True))
            )
        inner = args[0] if args else Any
        seq = [_coerce(v, inner, f"{path}[{i}]") for i, v in enumerate(value)]
        return tuple(seq) if origin is tuple else seq
    return _coerce_scalar(value, tp, path)


def _coerce_scalar(value: Any, tp: Any, path: str) -> Any:
    """``value`` as the scalar type ``tp`` (bool, int, float, str; strings are parsed)."""
    if tp is Any:
        return value
    if tp is bool:
        if isinstance(value, bool):
            return value
        if isinstance(value, str) and value.lower() in ("true", "false", "1", "0", "yes", "no"):
            return value.lower() in ("true", "1", "yes")
        raise ConfigError(f"{path}: expected true/false, got {short_repr(value)}")
    if tp is int:
        if isinstance(value, bool):
            raise ConfigError(f"{path}: expected an integer, got {short_repr(value)}")
        if isinstance(value, int):
            return value
        if isinstance(value, float) and value.is_integer():
            return int(value)
        if isinstance(value, str):
            try:
                return int(value)
            except ValueError:
                pass
        raise ConfigError(f"{path}: expected an integer, got {short_repr(value)}")
    if tp is float:
        if isinstance(value, bool):
            raise ConfigError(f"{path}: expected a number, got {short_repr(value)}")
        if isinstance(value, (int, float)):
            return float(value)
        if isinstance(value, str):
            try:
                return float(value)
            except ValueError:
                pass
        raise ConfigError(f"{path}: expected a number, got {short_repr(value)}")
    if tp is str:
        if isinstance(value, str):
            return value
        raise ConfigError(f"{path}: expected a string, got {short_repr(value)}")
    return value


def from_dict(cls: type[T], data: Mapping[str, Any] | None, _prefix: str = "") -> T:
    """Build dataclass ``cls`` from a (nested) mapping; missing keys keep their defaults.

    A dataclass may name keys it no longer has in a class attribute ``removed_config_keys``
    (key -> what gives that behaviour now): such a key is an error that says so.

    Raises:
        ConfigError: on an unknown key (named by its dotted path) or a value of the wrong type.
    """
    if data is None:
        return cls()
    if not isinstance(data, Mapping):
        raise ConfigError(f"{_prefix or cls.__name__}: expected a mapping, got {short_repr(data)}")
    hints = _field_types(cls)
    names = [f.name for f in dataclasses.fields(cls) if f.init]  # type: ignore[arg-type]
    kwargs: dict[str, Any] = {}
    for key, value in data.items():
        path = f"{_prefix}.{key}" if _prefix else str(key)
        if key not in names:
            gone = getattr(cls, "removed_config_keys", {}).get(key)
            if gone is not None:
                raise ConfigError(f"config key {short_repr(path)} was removed: {gone}")
            raise ConfigError(
                f"unknown config key {short_repr(path)}; valid keys here: {', '.join(sorted(names))}"
            )
        kwargs[key] = _coerce(value, hints[key], path)
    try:
        return cls(**kwargs)
    except ConfigError:
        raise
    except (ValueError, TypeError) as e:
        raise ConfigError(f"{_prefix or cls.__name__}: {e}") from e


def to_dict(obj: Any) -> Any:
    """Plain-dict (YAML-safe) form of a dataclass tree."""
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        return {f.name: to_dict(getattr(obj, f.name)) for f in dataclasses.fields(obj)}
    if isinstance(obj, (list, tuple)):
        return [to_dict(v) for v in obj]
    return obj


def parse_override(text: str) -> tuple[list[str], Any]:
    """Split ``"a.b=value"`` into (["a", "b"], parsed value); the value is read as YAML scalar."""
    if "=" not in text:
        raise ConfigError(f"override {short_repr(text)} must look like key.path=value")
    key, raw = text.split("=", 1)
    key = key.strip()
    if not key:
        raise ConfigError(f"override {short_repr(text)} has an empty key")
    try:
        value = (
            load_yaml_text(raw, f"override {short_repr(key)}", max_bytes=64 << 10)
            if raw.strip()
            else ""
        )
    except UnsafeInputError as e:
        raise ConfigError(str(e)) from None
    return key.split("."), value


def nest_dotted(data: Mapping[str, Any]) -> dict[str, Any]:
    """``{"a.b": 1, "a": {"c": 2}, "d": 3}`` -> ``{"a": {"b": 1, "c": 2}, "d": 3}``.

    Dotted keys nest and mappings merge key by key, later keys winning; the result shares no
    dict or list with ``data``.
    """
    out: dict[str, Any] = {}
    _merge_into(out, data)
    return out


def _merge_into(node: dict[str, Any], layer: Mapping[str, Any]) -> None:
    """Merge ``layer`` into ``node`` in place: dotted keys nest, mappings merge, others replace."""
    for key, value in layer.items():
        *parents, leaf = str(key).split(".")
        target = node
        for name in parents:
            target = _child_dict(target, name)
        if isinstance(value, Mapping):
            _merge_into(_child_dict(target, leaf), value)
        else:
            target[leaf] = _deepcopy(value)


def _child_dict(node: dict[str, Any], key: str) -> dict[str, Any]:
    """``node[key]`` as a dict to merge into: a dataclass there becomes its fields, a scalar {}."""
    child = node.get(key)
    if dataclasses.is_dataclass(child) and not isinstance(child, type):
        child = to_dict(child)
    if not isinstance(child, dict):
        child = {}
    node[key] = child
    return child


def merge_overrides(data: Mapping[str, Any] | None, overrides: Iterable[str]) -> dict[str, Any]:
    """Return nested ``data`` (dotted keys nested) with ``key.path=value`` overrides applied.

    An override replaces the value at its key path (a mapping value replaces, not merges).
    """
    if isinstance(overrides, str):
        raise ConfigError(f"overrides must be a list of key.path=value strings, not {overrides!r}")
    out = nest_dotted(data or {})
    for text in overrides:
        keys, value = parse_override(text)
        node = out
        for k in keys[:-1]:
            node = _child_dict(node, k)
        node[keys[-1]] = value
    return out


def _deepcopy(d: Any) -> Any:
    if isinstance(d, dict):
        return {k: _deepcopy(v) for k, v in d.items()}
    if isinstance(d, list):
        return [_deepcopy(v) for v in d]
    return d


def _layer_data(layer: Any, presets: Mapping[str, Any] | None) -> Mapping[str, Any]:
    """The mapping a :func:`build_params` layer stands for (see there)."""
    if isinstance(layer, (str, os.PathLike)):
        text = os.fspath(layer)
        if presets is not None and text in presets:
            return _layer_data(presets[text], None)
        if text.endswith((".yaml", ".yml")) or os.sep in text or Path(text).exists():
            return load_yaml(text)
        raise ConfigError(
            f"unknown config {text!r}: not a preset ({', '.join(presets or ()) or 'none'}) nor a .yaml file"
        )
    if dataclasses.is_dataclass(layer) and not isinstance(layer, type):
        return to_dict(layer)
    if isinstance(layer, Mapping):
        return layer
    raise ConfigError(
        "a config layer must be None, a preset name, a YAML path, a mapping or a parameter "
        f"dataclass; got {type(layer).__name__}"
    )


def build_params(
    cls: type[T],
    *layers: Any,
    overrides: Iterable[str] = (),
    presets: Mapping[str, Any] | None = None,
    renamed: Mapping[str, tuple[str, str]] | None = None,
) -> T:
    """Build the frozen parameter dataclass ``cls``: layers merged in order, then overrides.

    The one config path of the project (env, policies, macro envs, training configs).

    Args:
        cls: The parameter dataclass to build; fields no layer sets keep their defaults.
        *layers: Each one of: None (skipped); a preset name (a key of ``presets``); a YAML
            file (a path ending in ``.yaml``/``.yml``, containing a separator or existing);
            a mapping with nested and/or dotted keys (``{"cost": {"w_v": 2}}``,
            ``{"cost.w_v": 2}``); a dataclass instance (all its fields). Later layers win key
            by key: mappings merge, any other value replaces.
        overrides: ``"a.b=value"`` strings applied last (the value read as a YAML scalar).
        presets: Named layers (dataclass instances or mappings) that a string may name.
        renamed: Published keys that were renamed, old dotted path -> (new one, why): using
            an old key is an error naming the new one and the reason.

    Returns:
        The ``cls`` instance; a lone layer that already is one, without overrides, as is.

    Raises:
        ConfigError: unknown preset, unknown key (named by its dotted path), bad value.
        FileNotFoundError: a YAML path that does not exist.
    """
    given = [layer for layer in layers if layer is not None]
    if len(given) == 1 and type(given[0]) is cls and not overrides:
        return given[0]
    merged: dict[str, Any] = {}
    for layer in given:
        _merge_into(merged, _layer_data(layer, presets))
    merged = merge_overrides(merged, overrides)
    for old, (new, why) in (renamed or {}).items():
        node: Any = merged
        for part in old.split("."):
            node = node.get(part, _MISSING) if isinstance(node, Mapping) else _MISSING
        if node is not _MISSING:
            raise ConfigError(
                f"config key {old!r} was renamed {new!r} ({why}); use {new}={short_repr(node)}"
            )
    return from_dict(cls, merged)


_MISSING = object()


def load_yaml(path: str | os.PathLike) -> dict[str, Any]:
    """Read a YAML mapping with ``safe_load``; clear errors for a missing or malformed file.

    ``configs/...`` paths that do not exist here are the shipped ones
    (:func:`~semexplore_gym.config.resources.resolve_config_path`)."""
    p = resolve_config_path(path)
    if not p.is_file():
        raise FileNotFoundError(f"config file not found: {short_repr(str(p), 200)}")
    try:
        data = load_yaml_file(p, "config file")
    except UnsafeInputError as e:
        raise ConfigError(str(e)) from None
    if data is None:
        return {}
    if not isinstance(data, dict):
        raise ConfigError(
            f"{str(p)!r} must contain a mapping at top level, got {type(data).__name__}"
        )
    return data
