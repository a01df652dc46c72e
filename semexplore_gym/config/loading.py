"""Bounded loading of YAML / JSON documents.

Every YAML or JSON document the package reads from a user (map yaml, config files, ``--set``
values, HouseExpo JSON) goes through :func:`load_yaml_text` / :func:`load_json_text` or their
file forms. They bound what a small file can turn into:

- the size of the text (``max_bytes``),
- the nesting depth (``max_depth``; a deeper document would otherwise end in a
  ``RecursionError`` inside the parser),
- the number of values *after* alias expansion (``max_nodes``): a few hundred bytes of nested
  ``&a`` / ``*a`` aliases expand to billions of values once copied or printed,
- recursive aliases (a value that contains itself) are refused.

Error messages quote values through :func:`~semexplore_gym.core.validation.short_repr`, so a
huge value never floods stderr.
All errors are :class:`UnsafeInputError` (a ``ValueError``) naming the file or the source.
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from semexplore_gym.core.validation import one_line, short_repr

#: Largest YAML / JSON text read from a config, map yaml or ``--set`` value.
MAX_YAML_BYTES = 1 << 20
#: Largest JSON text (HouseExpo plans are ~10-200 kB).
MAX_JSON_BYTES = 16 << 20
#: Deepest nesting of lists / mappings.
MAX_DEPTH = 64
#: Most values (scalars + containers) a YAML document may hold once aliases are expanded
#: (configs and map yamls hold tens), and a JSON document (a HouseExpo plan: ~3 per vertex).
MAX_YAML_NODES = 100_000
MAX_NODES = 1_000_000


class UnsafeInputError(ValueError):
    """A YAML / JSON document is malformed or beyond the loader's bounds; names its source."""


def _read_text(path: str | os.PathLike, max_bytes: int, what: str) -> str:
    p = Path(path)
    if not p.is_file():
        raise FileNotFoundError(f"{what} not found: {short_repr(str(p), 200)}")
    size = p.stat().st_size
    if size > max_bytes:
        raise UnsafeInputError(
            f"{p}: {size} bytes is more than the {max_bytes}-byte limit for a {what}"
        )
    raw = p.read_bytes()[: max_bytes + 1]
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError as e:
        raise UnsafeInputError(
            f"{p}: not UTF-8 text (byte {e.start}: {short_repr(raw[e.start : e.start + 4])})"
        ) from None


def _check_yaml_nodes(root: yaml.Node, source: str, max_depth: int, max_nodes: int) -> None:
    """Depth and expanded size of a composed YAML node graph; aliases are shared nodes."""
    expanded: dict[int, int] = {}  # id(node) -> values it expands to
    on_path: set[int] = set()

    def visit(node: yaml.Node, depth: int) -> int:
        if depth > max_depth:
            raise UnsafeInputError(f"{source}: nested deeper than {max_depth} levels")
        key = id(node)
        if key in expanded:
            return expanded[key]
        if key in on_path:
            raise UnsafeInputError(f"{source}: recursive alias (a value that contains itself)")
        if isinstance(node, yaml.ScalarNode):
            return 1
        on_path.add(key)
        total = 1
        children = (
            [c for pair in node.value for c in pair]
            if isinstance(node, yaml.MappingNode)
            else node.value
        )
        for child in children:
            total += visit(child, depth + 1)
            if total > max_nodes:
                raise UnsafeInputError(
                    f"{source}: expands to more than {max_nodes} values (alias bomb?)"
                )
        on_path.discard(key)
        expanded[key] = total
        return total

    visit(root, 0)


def _flow_depth(text: str) -> int:
    """The deepest nesting of flow brackets (``[`` ``{``) in ``text``, counted over the raw
    characters (brackets inside quoted strings count too: an upper bound)."""
    b = np.frombuffer(text.encode("utf-8", "surrogatepass"), dtype=np.uint8)
    step = np.isin(b, _OPEN).astype(np.int32) - np.isin(b, _CLOSE).astype(np.int32)
    return int(np.cumsum(step).max(initial=0))


_OPEN = np.frombuffer(b"[{", dtype=np.uint8)
_CLOSE = np.frombuffer(b"]}", dtype=np.uint8)


def load_yaml_text(
    text: str,
    source: str = "<yaml>",
    *,
    max_bytes: int = MAX_YAML_BYTES,
    max_depth: int = MAX_DEPTH,
    max_nodes: int = MAX_YAML_NODES,
) -> Any:
    """``yaml.safe_load`` with bounds on size, depth and alias expansion.

    Raises:
        UnsafeInputError: malformed YAML or a bound exceeded; the message names ``source``.
    """
    if len(text) > max_bytes:
        raise UnsafeInputError(
            f"{source}: {len(text)} characters is more than the {max_bytes} limit"
        )
    if _flow_depth(text) > max_depth:
        # Refused before the parser recurses into it (which, near a memory limit, can fail as
        # a SystemError or MemoryError rather than a RecursionError).
        raise UnsafeInputError(f"{source}: nested deeper than {max_depth} levels")
    try:
        loader = yaml.SafeLoader(text)
    except yaml.YAMLError as e:  # the reader refuses control characters at once
        raise UnsafeInputError(f"{source}: malformed YAML: {one_line(str(e))}") from None
    try:
        try:
            node = loader.get_single_node()
        except (RecursionError, SystemError, MemoryError):
            raise UnsafeInputError(f"{source}: nested too deeply") from None
        except yaml.YAMLError as e:
            raise UnsafeInputError(f"{source}: malformed YAML: {one_line(str(e))}") from None
        if node is None:
            return None
        _check_yaml_nodes(node, source, max_depth, max_nodes)
        try:
            return loader.construct_document(node)
        except (RecursionError, SystemError, MemoryError):
            raise UnsafeInputError(f"{source}: nested too deeply") from None
        except (yaml.YAMLError, TypeError, ValueError, OverflowError) as e:
            # e.g. an unhashable mapping key ({[1]: 2}) or a timestamp out of range
            raise UnsafeInputError(f"{source}: bad YAML value: {one_line(str(e))}") from None
    finally:
        loader.dispose()


def load_yaml_file(path: str | os.PathLike, what: str = "YAML file", **bounds: int) -> Any:
    """:func:`load_yaml_text` of a UTF-8 file; FileNotFoundError names the file."""
    max_bytes = bounds.pop("max_bytes", MAX_YAML_BYTES)
    text = _read_text(path, max_bytes, what)
    return load_yaml_text(text, str(path), max_bytes=max_bytes, **bounds)


def _check_json_value(value: Any, source: str, max_depth: int, max_nodes: int) -> None:
    stack: list[tuple[Any, int]] = [(value, 0)]
    n = 0
    while stack:
        v, depth = stack.pop()
        n += 1
        if n > max_nodes:
            raise UnsafeInputError(f"{source}: more than {max_nodes} values")
        if depth > max_depth:
            raise UnsafeInputError(f"{source}: nested deeper than {max_depth} levels")
        if isinstance(v, dict):
            stack.extend((c, depth + 1) for c in v.values())
        elif isinstance(v, list):
            stack.extend((c, depth + 1) for c in v)


def _json_constant(name: str) -> float:
    raise ValueError(f"{name} is not a JSON number")


def load_json_text(
    text: str,
    source: str = "<json>",
    *,
    max_bytes: int = MAX_JSON_BYTES,
    max_depth: int = MAX_DEPTH,
    max_nodes: int = MAX_NODES,
) -> Any:
    """``json.loads`` with bounds on size, depth and value count; NaN / Infinity refused.

    Raises:
        UnsafeInputError: malformed JSON or a bound exceeded; the message names ``source``.
    """
    if len(text) > max_bytes:
        raise UnsafeInputError(
            f"{source}: {len(text)} characters is more than the {max_bytes} limit"
        )
    # A cheap pre-check: json's decoder recurses once per bracket.
    depth = 0
    in_str = esc = False
    for ch in text:
        if in_str:
            if esc:
                esc = False
            elif ch == "\\":
                esc = True
            elif ch == '"':
                in_str = False
        elif ch == '"':
            in_str = True
        elif ch in "[{":
            depth += 1
            if depth > max_depth:
                raise UnsafeInputError(f"{source}: nested deeper than {max_depth} levels")
        elif ch in "]}":
            depth -= 1
    try:
        value = json.loads(text, parse_constant=_json_constant)
    except RecursionError:
        raise UnsafeInputError(f"{source}: nested too deeply") from None
    except ValueError as e:  # JSONDecodeError is a ValueError
        raise UnsafeInputError(f"{source}: malformed JSON: {one_line(str(e))}") from None
    _check_json_value(value, source, max_depth, max_nodes)
    return value


def load_json_file(path: str | os.PathLike, what: str = "JSON file", **bounds: int) -> Any:
    """:func:`load_json_text` of a UTF-8 file; FileNotFoundError names the file."""
    max_bytes = bounds.pop("max_bytes", MAX_JSON_BYTES)
    text = _read_text(path, max_bytes, what)
    return load_json_text(text, str(path), max_bytes=max_bytes, **bounds)
