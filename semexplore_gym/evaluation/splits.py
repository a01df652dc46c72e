"""Learning splits: fixed, versioned train / validation / test worlds per family, as data.

A split file (``configs/splits/NAME.yaml``, or a path) is a suite with three world lists::

    name: mazes
    version: 1
    description: Procedural grid mazes from 6 m to 30 m, perfect and braided.
    rule: no test world is ever used for training or model selection
    runs: 2                 # as a suite: seeds per (world, policy), start poses, time limits
    random_start: true
    time_per_m2_s: 20.0
    min_time_s: 600.0
    train: [maze:seed=61000,size_m=6, ...]
    validation: [...]
    test: [...]

**The rule**: no test world is ever used for training or model selection (early stopping,
hyperparameters, choosing among designs). Train on ``train``, select on ``validation``, report
once on ``test``. ``semexplore benchmark --split mazes:test`` evaluates any policy on one part;
:func:`split_suite` turns a part into a :class:`~semexplore_gym.evaluation.suites.Suite` named
``mazes-test``, so the benchmark, its resuming and its regret outputs are the suites' own.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from semexplore_gym.config.resources import configs_dir
from semexplore_gym.evaluation.suites import Suite, read_named_yaml, suite_from_dict

#: Where named splits live (the shipped ``configs/splits``), unless ``SEMEXPLORE_SPLITS_DIR``
#: names another directory.
SPLITS_DIR = configs_dir() / "splits"
#: The three parts of a split, in order.
PARTS = ("train", "validation", "test")
#: What every split file must say, word for word, under ``rule``.
RULE = "no test world is ever used for training or model selection"
_SUITE_KEYS = ("runs", "random_start", "max_time_s", "time_per_m2_s", "min_time_s")


@dataclass(frozen=True)
class Split:
    """A learning split: one family's worlds in three disjoint parts (see the module docstring).

    Attributes:
        name: Split name (``mazes``, ``dungeon``, ...).
        version: Bumped whenever a world changes.
        parts: ``{"train": (...), "validation": (...), "test": (...)}`` world spellings.
        suite_fields: The suite keys the parts share (runs, start poses, time limits).
        description: One line.
        source: The file it was read from.
    """

    name: str
    version: int
    parts: dict[str, tuple[str, ...]]
    suite_fields: dict[str, Any]
    description: str = ""
    source: str = ""

    def suite(self, part: str) -> Suite:
        """Part ``part`` as a suite named ``NAME-PART`` (the benchmark's unit)."""
        if part not in PARTS:
            raise ValueError(f"split {self.name}: no part {part!r}; parts: {', '.join(PARTS)}")
        data = {
            "name": f"{self.name}-{part}",
            "version": self.version,
            "description": f"{self.description} ({part} part of split {self.name!r})",
            **self.suite_fields,
            "worlds": list(self.parts[part]),
        }
        return suite_from_dict(data, source=f"{self.source}:{part}")


def _splits_dir() -> Path:
    return Path(os.environ.get("SEMEXPLORE_SPLITS_DIR") or SPLITS_DIR)


def list_splits() -> list[str]:
    """Names of the splits in the splits directory."""
    d = _splits_dir()
    return sorted(p.stem for p in d.glob("*.yaml")) if d.is_dir() else []


def _read(name_or_path: str) -> tuple[Any, str]:
    return read_named_yaml(name_or_path, "split", _splits_dir(), list_splits)


def load_split(name_or_path: str | os.PathLike) -> Split:
    """A split by name (``configs/splits/NAME.yaml``) or path.

    Raises:
        FileNotFoundError: no such split (the message lists the known ones).
        ValueError: a malformed split: unknown keys, a part missing or empty, a world in two
            parts or twice in one, no ``rule``.
    """
    data, source = _read(str(name_or_path))
    if not isinstance(data, dict):
        raise ValueError(f"split {source}: must be a mapping")
    keys = {"name", "version", "description", "rule", *PARTS, *_SUITE_KEYS}
    unknown = sorted(set(map(str, data)) - keys)
    if unknown:
        raise ValueError(f"split {source}: unknown key(s) {unknown}; valid: {sorted(keys)}")
    if data.get("rule") != RULE:
        raise ValueError(f"split {source}: 'rule' must read: {RULE}")
    parts: dict[str, tuple[str, ...]] = {}
    seen: dict[str, str] = {}
    for part in PARTS:
        worlds = data.get(part)
        if not isinstance(worlds, list) or not worlds:
            raise ValueError(f"split {source}: {part!r} must be a non-empty list of worlds")
        for w in worlds:
            if not isinstance(w, str) or not w.strip():
                raise ValueError(f"split {source}: {part}: {w!r} is not a world spelling")
            if w.strip() in seen:
                raise ValueError(
                    f"split {source}: world {w.strip()!r} is in {seen[w.strip()]!r} and {part!r}"
                )
            seen[w.strip()] = part
        parts[part] = tuple(w.strip() for w in worlds)
    split = Split(
        name=str(data.get("name", "")).strip(),
        version=data.get("version", 1),
        parts=parts,
        suite_fields={k: data[k] for k in _SUITE_KEYS if k in data},
        description=str(data.get("description", "")),
        source=source,
    )
    for part in PARTS:
        split.suite(part)  # the suite checks name, version, runs and time limits
    return split


def split_suite(spec: str) -> Suite:
    """``"NAME:PART"`` (``mazes:test``; a path may stand for NAME) as a suite.

    Raises:
        ValueError: no ``:PART``, an unknown part, a malformed split.
        FileNotFoundError: no such split.
    """
    name, sep, part = str(spec).strip().rpartition(":")
    if not sep or not name:
        raise ValueError(
            f"split {spec!r}: write NAME:PART, e.g. mazes:test (parts: {', '.join(PARTS)})"
        )
    return load_split(name).suite(part.strip())
