"""Policy configuration files: the sections of ``configs/expert/*.yaml``.

A policy's parameters are built like every other parameter set, by
:func:`semexplore_gym.core.params.build_params` (re-exported here): layers (a mapping with
nested or dotted keys, a YAML file, a parameter object) then ``key=value`` overrides.

An explore/benchmark config file (e.g. ``configs/expert/paper.yaml``) has up to three sections::

    env: paper                  # env config: a preset name, a YAML path or a mapping (optional)
    policy: semantic            # policy spec for make_policy (optional)
    params:                     # the policy's parameter dataclass, nested by field
      cost: {w_v: 4.0, w_p: 0.2, w_i: 0.1}

Unknown keys, in the file or in an override, raise :class:`ConfigError` naming the dotted key.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

from semexplore_gym.core.params import ConfigError, build_params, load_yaml

__all__ = ["ConfigError", "PolicyRunConfig", "build_params", "load_policy_config"]


@dataclass(frozen=True)
class PolicyRunConfig:
    """The sections of a policy config file.

    Attributes:
        env: Env config for ``gym.make(..., config=env)``: None, a preset name, a path or a mapping.
        policy: Policy spec (``"semantic"``, ...) or None to leave the choice to the caller.
        params: Nested mapping of the policy's parameter dataclass fields.
    """

    env: Any = None
    policy: str | None = None
    params: dict[str, Any] = field(default_factory=dict)


def load_policy_config(source: str | os.PathLike | Mapping[str, Any] | None) -> PolicyRunConfig:
    """Read a policy config file (or mapping); sections other than env/policy/params are errors."""
    if source is None:
        return PolicyRunConfig()
    data = dict(source) if isinstance(source, Mapping) else load_yaml(source)
    where = "" if isinstance(source, Mapping) else f" in {str(source)!r}"
    allowed = {f.name for f in PolicyRunConfig.__dataclass_fields__.values()}
    for key in data:
        if key not in allowed:
            raise ConfigError(
                f"unknown config key {key!r}{where}; valid keys here: {', '.join(sorted(allowed))}"
            )
    params = data.get("params") or {}
    if not isinstance(params, Mapping):
        raise ConfigError(f"params{where}: expected a mapping, got {params!r}")
    policy = data.get("policy")
    if policy is not None and not isinstance(policy, str):
        raise ConfigError(f"policy{where}: expected a string, got {policy!r}")
    return PolicyRunConfig(env=data.get("env"), policy=policy, params=dict(params))
