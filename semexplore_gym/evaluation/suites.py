"""Named, versioned benchmark suites: a YAML file lists the worlds, runs and time limits.

A suite is data (``configs/suites/NAME.yaml``; add your own file there or pass a path)::

    name: caves
    version: 1
    description: Procedural caves from 8 m to 30 m.
    runs: 2                 # seeds per (world, policy): each seed draws a start pose
    random_start: true
    time_per_m2_s: 6.0      # per-world time limit: this x the world's free area ...
    min_time_s: 600.0       # ... but at least this (or give a fixed max_time_s instead)
    worlds:
      - cave:seed=400,size_m=8,min_passage_m=0.5
      - {world: map:intel_lab, max_time_s: 3000}   # a per-world limit overrides the rule

``semexplore benchmark --suite caves --policies semantic,nearest --out runs/caves`` runs it. The
family of a world (its spelling before ``:``, or the file name of a map) groups the summary.
"""

from __future__ import annotations

import os
import sys
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml

from semexplore_gym.config.loading import UnsafeInputError, load_yaml_file
from semexplore_gym.config.resources import configs_dir, resolve_config_path
from semexplore_gym.core.validation import short_repr
from semexplore_gym.evaluation.errors import PARAM, ParameterError

#: Where named suites live (the shipped ``configs/suites``: in the wheel or the checkout), unless
#: ``SEMEXPLORE_SUITES_DIR`` names another directory.
SUITES_DIR = configs_dir() / "suites"

_KEYS = {
    "name",
    "version",
    "description",
    "runs",
    "random_start",
    "max_time_s",
    "time_per_m2_s",
    "min_time_s",
    "worlds",
}
_MAX_WORLDS = 10_000


@dataclass(frozen=True)
class SuiteWorld:
    """One world of a suite, with its own time limit if it sets one."""

    world: str
    max_time_s: float | None = None


@dataclass(frozen=True)
class Suite:
    """A benchmark suite (see the module docstring for the YAML fields)."""

    name: str
    version: int
    worlds: tuple[SuiteWorld, ...]
    description: str = ""
    runs: int = 1
    random_start: bool = True
    max_time_s: float | None = None
    time_per_m2_s: float | None = None
    min_time_s: float = 0.0
    source: str = field(default="", compare=False)

    def to_dict(self) -> dict[str, Any]:
        """The YAML mapping of this suite (``load_suite(save_suite(s))`` gives ``s`` back)."""
        out: dict[str, Any] = {
            "name": self.name,
            "version": self.version,
            "description": self.description,
            "runs": self.runs,
            "random_start": self.random_start,
        }
        if self.max_time_s is not None:
            out["max_time_s"] = self.max_time_s
        if self.time_per_m2_s is not None:
            out["time_per_m2_s"] = self.time_per_m2_s
            out["min_time_s"] = self.min_time_s
        out["worlds"] = [
            w.world if w.max_time_s is None else {"world": w.world, "max_time_s": w.max_time_s}
            for w in self.worlds
        ]
        return out


def list_suites(directory: str | os.PathLike | None = None) -> list[str]:
    """Names of the suites in ``directory`` (default: :data:`SUITES_DIR` or the env var)."""
    d = Path(directory or os.environ.get("SEMEXPLORE_SUITES_DIR") or SUITES_DIR)
    return sorted(p.stem for p in d.glob("*.yaml")) if d.is_dir() else []


def _number(data: dict[str, Any], key: str, src: str, *, minimum: float) -> float | None:
    v = data.get(key)
    if v is None:
        return None
    if isinstance(v, bool) or not isinstance(v, int | float) or not v == v or v < minimum:
        raise ValueError(f"suite {src}: {key} must be a number >= {minimum}, got {v!r}")
    if v == float("inf"):
        raise ValueError(f"suite {src}: {key} must be finite, got {v!r}")
    return float(v)


def _world(item: Any, src: str, i: int) -> SuiteWorld:
    if isinstance(item, str) and item.strip():
        return SuiteWorld(item.strip())
    if isinstance(item, dict) and set(item) <= {"world", "max_time_s"} and "world" in item:
        w = item["world"]
        if not isinstance(w, str) or not w.strip():
            raise ValueError(f"suite {src}: worlds[{i}].world must be a world spelling, got {w!r}")
        return SuiteWorld(w.strip(), _number(item, "max_time_s", f"{src} worlds[{i}]", minimum=1.0))
    raise ValueError(
        f"suite {src}: worlds[{i}] must be a world spelling or {{world: ..., max_time_s: ...}}, "
        f"got {str(item)[:80]!r}"
    )


def suite_from_dict(data: Any, source: str = "<dict>") -> Suite:
    """Validate a suite mapping; errors name the file and the bad key or value."""
    if not isinstance(data, dict):
        raise ValueError(f"suite {source}: must be a mapping, got {type(data).__name__}")
    unknown = sorted(set(map(str, data)) - _KEYS)
    if unknown:
        raise ValueError(f"suite {source}: unknown key(s) {unknown}; valid: {sorted(_KEYS)}")
    name = data.get("name")
    if not isinstance(name, str) or not name.strip():
        raise ValueError(f"suite {source}: 'name' must be a non-empty string, got {name!r}")
    version = data.get("version", 1)
    if isinstance(version, bool) or not isinstance(version, int) or version < 1:
        raise ValueError(f"suite {source}: version must be an integer >= 1, got {version!r}")
    runs = data.get("runs", 1)
    if isinstance(runs, bool) or not isinstance(runs, int) or not 1 <= runs <= 1000:
        raise ValueError(f"suite {source}: runs must be an integer in [1, 1000], got {runs!r}")
    worlds = data.get("worlds")
    if not isinstance(worlds, list) or not worlds:
        raise ValueError(f"suite {source}: 'worlds' must be a non-empty list")
    if len(worlds) > _MAX_WORLDS:
        raise ValueError(f"suite {source}: {len(worlds)} worlds; at most {_MAX_WORLDS}")
    random_start = data.get("random_start", True)
    if not isinstance(random_start, bool):
        raise ValueError(
            f"suite {source}: random_start must be true or false, got {random_start!r}"
        )
    fixed = _number(data, "max_time_s", source, minimum=1.0)
    per_m2 = _number(data, "time_per_m2_s", source, minimum=0.0)
    if fixed is not None and per_m2 is not None:
        raise ValueError(f"suite {source}: give max_time_s or time_per_m2_s, not both")
    return Suite(
        name=name.strip(),
        version=version,
        worlds=tuple(_world(w, source, i) for i, w in enumerate(worlds)),
        description=str(data.get("description", "")),
        runs=runs,
        random_start=random_start,
        max_time_s=fixed,
        time_per_m2_s=per_m2,
        min_time_s=_number(data, "min_time_s", source, minimum=0.0) or 0.0,
        source=source,
    )


def read_named_yaml(
    text: str, kind: str, directory: Path, known: Callable[[], Sequence[str]]
) -> tuple[Any, str]:
    """A ``kind`` file (suite, split) by name in ``directory`` or by path, read with the
    project's bounded YAML loader. Returns ``(data, path)``.

    Raises:
        FileNotFoundError: no such name (the message lists ``known()``) or file.
        ValueError: over 1 MB, or not valid YAML (the message names the file).
    """
    path = resolve_config_path(text)
    if not (text.endswith((".yaml", ".yml")) or path.is_file()):
        path = directory / f"{text}.yaml"
        if not path.is_file():
            names = ", ".join(known()) or "none"
            raise FileNotFoundError(
                f"unknown {kind} {text!r}; known {kind}s: {names} (or a .yaml path)"
            )
    if not path.is_file():
        raise FileNotFoundError(f"{kind} file not found: {text!r}")
    if path.stat().st_size > 1_000_000:
        raise ValueError(f"{kind} file {text!r} is over 1 MB")
    try:
        return load_yaml_file(path, f"{kind} file"), str(path)
    except (UnsafeInputError, UnicodeDecodeError) as e:
        first = str(e).splitlines()[0][:200] if str(e) else type(e).__name__
        raise ValueError(f"{kind} file {text!r} is not valid YAML: {first}") from None


def load_suite(name_or_path: str | os.PathLike) -> Suite:
    """A suite by name (a file in the suites directory) or by path to a YAML file.

    Raises:
        FileNotFoundError: no such suite; the message lists the known names.
        ValueError: a malformed suite (the message names the file and the key).
    """
    text = str(name_or_path)
    d = Path(os.environ.get("SEMEXPLORE_SUITES_DIR") or SUITES_DIR)
    data, path = read_named_yaml(text, "suite", d, lambda: list_suites(d))
    return suite_from_dict(data, source=str(path))


def save_suite(suite: Suite, path: str | os.PathLike) -> Path:
    """Write ``suite`` as YAML (round-trips through :func:`load_suite`)."""
    p = Path(path)
    p.write_text(yaml.safe_dump(suite.to_dict(), sort_keys=False, width=100), encoding="utf-8")
    return p


def world_family(world: str) -> str:
    """The family a world belongs to in a summary: ``maze``, ``office``, ..., ``dungeon`` for
    DungeonMaps, ``real maps`` for the other catalogue maps (``map:NAME``), or the file name of
    a map given by path."""
    if world.lower().endswith((".yaml", ".yml", ".json")):
        return Path(world).stem
    if world.lower().endswith(".png") or world.startswith("map:dungeon-"):
        return "dungeon"
    name = world.partition(":")[0]
    if name == "map":
        return "real maps"
    return "paper mazes" if name in ("maze1", "maze2") else name


def world_time_limit_s(suite: Suite, entry: SuiteWorld, free_area_m2: float | None) -> float | None:
    """The mission time limit of ``entry``: its own, the suite's fixed one, or the area rule."""
    if entry.max_time_s is not None:
        return entry.max_time_s
    if suite.max_time_s is not None:
        return suite.max_time_s
    if suite.time_per_m2_s is not None and free_area_m2 is not None:
        return max(suite.min_time_s, suite.time_per_m2_s * free_area_m2)
    return None


def _warn_repeated_missions(suite_name: str, n_worlds: int) -> None:
    print(
        f"warning: suite {suite_name}: fixed start poses: every seed repeats the same "
        f"mission on {n_worlds} world(s) without seed=*; the summary will say "
        "'no variation'",
        file=sys.stderr,
    )


def _mission_env_config(
    env_config: Any, random_start: bool, limit: float | None, env_overrides: Sequence[str]
) -> Any:
    """The env config of a suite world's missions."""
    from semexplore_gym.envs.env_config import load_env_config

    # The env's own limit must not cut the mission short; the user's overrides win.
    overrides = [f"episode.random_start={'true' if random_start else 'false'}"]
    if limit is not None:
        overrides.append(f"episode.max_time_s={limit!r}")
    overrides += list(env_overrides)
    return load_env_config(env_config, overrides)


def suite_tasks(
    names: Sequence[str | Suite],
    policies: Sequence[str],
    seeds_for: Callable[[int], list[int]],
    *,
    max_time_s: float | None = None,
    fixed_start: bool = False,
    env_config: Any = None,
    env_overrides: Sequence[str] = (),
) -> tuple[list[Any], list[dict[str, Any]], list[str]]:
    """The benchmark tasks of the suites ``names``: every world with its suite's time limit,
    runs and start poses, for every policy.

    Args:
        names: suite names (``configs/suites``), YAML paths or suites (a split's part).
        policies: policy specs.
        seeds_for: the seeds to run, given a suite's ``runs``.
        max_time_s: replaces every suite's time limits when given.
        fixed_start: start every mission at the world's fixed pose (warns when seeds repeat).
        env_config: env config preset or YAML the suite's overrides apply to.
        env_overrides: ``SECTION.KEY=VALUE`` env overrides (win over the suite's).

    Returns:
        (tasks, ``[{"name", "version", "source", "random_start"}]`` per suite, every world in
        order).

    Raises:
        ParameterError: an unknown or repeated suite, a world in two suites, a world that
            cannot be built; each message names ``names`` and the value (the command line
            puts its flag in its place).
    """
    from semexplore_gym.evaluation.tasks import expand_tasks
    from semexplore_gym.maps import make_world

    if not names:
        raise ParameterError("names", f"{PARAM} is empty")
    tasks: list[Any] = []
    records: list[dict[str, Any]] = []
    all_worlds: list[str] = []
    for name in names:
        try:
            suite = name if isinstance(name, Suite) else load_suite(name)
        except FileNotFoundError as e:
            raise ParameterError("names", f"{PARAM} {short_repr(name)}: {e}") from None
        if any(r["name"] == suite.name for r in records):
            raise ParameterError("names", f"{PARAM} lists suite {suite.name!r} twice")
        source = suite.source if isinstance(name, Suite) else str(name)
        seeds = seeds_for(suite.runs)
        random_start = suite.random_start and not fixed_start
        record = {"name": suite.name, "version": suite.version, "source": source}
        records.append({**record, "random_start": random_start})
        repeated = [w.world for w in suite.worlds if "seed=*" not in w.world]
        if not random_start and len(seeds) > 1 and repeated:
            _warn_repeated_missions(suite.name, len(repeated))
        for entry in suite.worlds:
            if entry.world in all_worlds:
                raise ParameterError(
                    "names",
                    f"{PARAM}: world {short_repr(entry.world)} is in two suites; each world "
                    "must appear once (a repeat would count the same missions twice)",
                )
            all_worlds.append(entry.world)
            try:
                world = make_world(entry.world.replace("seed=*", f"seed={seeds[0]}"))
            except (ValueError, FileNotFoundError) as e:
                raise ParameterError(
                    "names", f"{PARAM} {suite.name}: world {entry.world!r}: {e}"
                ) from None
            if max_time_s is not None:
                limit: float | None = max_time_s
            else:
                area_m2 = float(world.free_mask.sum()) * world.free_geometry.resolution_m**2
                limit = world_time_limit_s(suite, entry, area_m2)
            config = _mission_env_config(env_config, random_start, limit, env_overrides)
            tasks += expand_tasks(
                [entry.world], policies, seeds, max_time_s=limit, env_config=config
            )
    return tasks, records, all_worlds
