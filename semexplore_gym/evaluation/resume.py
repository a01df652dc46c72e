"""Resuming a benchmark: the settings that make rows comparable, kept next to ``runs.csv``.

Adding worlds, seeds or policies to an output directory resumes it; changing a mission's time
limit, the env config, a policy's overrides or a suite's version is refused, so that one
``runs.csv`` never mixes missions run under different settings.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from semexplore_gym.core.validation import short_repr
from semexplore_gym.evaluation.errors import PARAM, ParameterError
from semexplore_gym.evaluation.tasks import Task

FINGERPRINT_FILE = "fingerprint.json"


def _canon(value: Any) -> Any:
    return json.loads(json.dumps(value, sort_keys=True, default=str))


def run_fingerprint(
    tasks: Sequence[Task], suites: Sequence[dict[str, Any]] | None = None
) -> dict[str, Any]:
    """What makes rows comparable beyond (world, policy, seed): the time limit, the env config,
    each policy's overrides and the suites run. Stored next to ``runs.csv``, checked on resume.

    When every mission shares one time limit and env config they are stored once
    (``max_time_s``, ``env_config``); a suite's per-world limits go to ``world_settings``.
    """
    from semexplore_gym.config import to_dict

    per_world: dict[str, Any] = {}
    for t in tasks:
        s = _canon(
            {
                "max_time_s": t.max_time_s,
                "env_config": to_dict(t.env_config) if t.env_config is not None else None,
            }
        )
        if per_world.setdefault(t.world, s) != s:
            raise ValueError(
                f"world {short_repr(t.world)} is listed with two time limits or env configs"
            )
    shared = {json.dumps(v, sort_keys=True) for v in per_world.values()}
    fp: dict[str, Any] = {}
    if len(shared) == 1:
        fp.update(json.loads(next(iter(shared))))
    elif shared:
        fp["world_settings"] = {w: per_world[w] for w in sorted(per_world)}
    overrides: dict[str, Any] = {}
    for t in tasks:
        o = _canon(t.policy_overrides)
        if overrides.setdefault(t.policy, o) != o:
            raise ValueError(f"policy {short_repr(t.policy)} is listed with two sets of overrides")
    fp["policy_overrides"] = {k: overrides[k] for k in sorted(overrides)}
    if suites:
        fp["suites"] = [_canon(dict(s)) for s in suites]
    return fp


def _settings_of(fp: dict[str, Any], world: str) -> dict[str, Any] | None:
    """The (max_time_s, env_config) a fingerprint records for ``world``, or None if unknown."""
    if "world_settings" in fp:
        return fp["world_settings"].get(world)
    return {"max_time_s": fp.get("max_time_s"), "env_config": fp.get("env_config")}


def check_fingerprint(out_dir: Path, fingerprint: dict[str, Any], has_rows: bool) -> None:
    """Store ``fingerprint`` in ``out_dir``, or refuse to resume rows made with other settings.

    Adding worlds, seeds or policies to a run is fine; changing ``max_time_s``, the env config,
    the overrides of a policy that already has rows, or a suite's version is not.
    """
    path = out_dir / FINGERPRINT_FILE
    old: dict[str, Any] | None = None
    if has_rows and path.exists():
        try:
            old = json.loads(path.read_text())
        except (ValueError, OSError):
            old = {}
    if old is not None:
        changed: list[tuple[str, Any, Any]] = []
        if "world_settings" not in old and "world_settings" not in fingerprint:
            changed += [
                (k, old.get(k), fingerprint.get(k))
                for k in ("max_time_s", "env_config")
                if old.get(k) != fingerprint.get(k)
            ]
        else:
            worlds = sorted(fingerprint.get("world_settings") or {}) or sorted(
                old.get("world_settings") or {}
            )
            for w in worlds:
                a, b = _settings_of(old, w), _settings_of(fingerprint, w)
                if a is None or b is None:
                    continue
                changed += [
                    (f"{k} of {w}", a.get(k), b.get(k))
                    for k in ("max_time_s", "env_config")
                    if a.get(k) != b.get(k)
                ]
        old_over = old.get("policy_overrides") or {}
        new_over = fingerprint["policy_overrides"]
        changed += [
            (f"overrides of {p}", old_over[p], new_over[p])
            for p in sorted(set(old_over) & set(new_over))
            if old_over[p] != new_over[p]
        ]
        old_suites = {s.get("name"): s for s in old.get("suites") or []}
        for s in fingerprint.get("suites") or []:
            o = old_suites.get(s.get("name"))
            if o is not None and o != s:
                changed.append((f"suite {s.get('name')}", o, s))
        if changed:
            detail = ", ".join(
                f"{k}: {short_repr(a, 60)} -> {short_repr(b, 60)}" for k, a, b in changed
            )
            raise ParameterError(
                "out_dir",
                f"{out_dir} holds missions run with different settings ({detail}); "
                f"rerun with the same settings to resume, or use a new output directory ({PARAM})",
            )
        merged = dict(fingerprint, policy_overrides={**old_over, **new_over})
        if "world_settings" in old and "world_settings" in fingerprint:
            merged["world_settings"] = {**old["world_settings"], **fingerprint["world_settings"]}
        if old.get("suites") or fingerprint.get("suites"):
            names = {
                s.get("name"): s
                for s in [*(old.get("suites") or []), *(fingerprint.get("suites") or [])]
            }
            merged["suites"] = list(names.values())
        fingerprint = merged
    path.write_text(json.dumps(fingerprint, indent=2, sort_keys=True))
