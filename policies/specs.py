"""Policy specs and their parameters: the one place that reads them.

- A spec string (``"semantic"``, ``"sb3:model.zip"``, ``"semantic[tuned]"``,
  ``"semantic[cost.w_v=0;cost.w_p=0]"``): :func:`parse_spec` splits it into the base spec, a
  table label and dotted parameter overrides; :func:`split_specs` splits a comma-separated
  list of them; :func:`strip_label` drops the bracket. ``make_policy``
  (:mod:`semexplore_gym.policies.registry`) builds the policy from the parts.
- A policy config file (``configs/expert/*.yaml``): :func:`load_policy_config` reads its
  sections, and :meth:`PolicyRunConfig.policy_kwargs` turns its ``params`` plus command-line
  ``key=value`` items into ``make_policy`` keyword arguments.

A policy's parameters are then built like every other parameter set, by
:func:`semexplore_gym.config.build_params`: layers (a mapping with nested or dotted
keys, a YAML file, a parameter object) then ``key=value`` overrides.

An explore/benchmark config file (e.g. ``configs/expert/robust_paper_weights.yaml``) has up to three sections::

    env: paper                  # env config: a preset name, a YAML path or a mapping (optional)
    policy: semantic            # policy spec for make_policy (optional)
    params:                     # the policy's parameter dataclass, nested by field
      cost: {w_v: 4.0, w_p: 0.2, w_i: 0.1}

Unknown keys, in the file or in an override, raise :class:`ConfigError` naming the dotted key.
"""

from __future__ import annotations

import os
import re
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from typing import Any

from semexplore_gym.config import ConfigError, load_yaml, merge_overrides, parse_override


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

    def policy_kwargs(self, overrides: Iterable[str] = ()) -> dict[str, Any]:
        """Keyword arguments for ``make_policy``: ``key.path=value`` items, nested by key path,
        on top of the file's ``params`` (passed as the ``params=`` base layer)."""
        kwargs: dict[str, Any] = merge_overrides(None, overrides)
        if self.params:
            kwargs["params"] = self.params
        return kwargs


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


def split_bracket(spec: str) -> tuple[str, str | None]:
    """``"semantic[x]"`` -> ``("semantic", "x")``; a spec without a trailing bracket -> (spec, None)."""
    spec = spec.strip()
    if spec.endswith("]") and "[" in spec:
        i = spec.rindex("[")
        return spec[:i].strip(), spec[i + 1 : -1].strip()
    return spec, None


def split_specs(text: str) -> list[str]:
    """Split comma-separated policy specs; commas inside ``[...]`` belong to the spec.

    ``"semantic[cost.w_v=0,cost.w_p=0],nearest"`` -> ``["semantic[cost.w_v=0,cost.w_p=0]",
    "nearest"]``.

    Raises:
        ValueError: an unbalanced bracket (the message names the text).
    """
    out: list[str] = []
    depth = 0
    current = ""
    for ch in text or "":
        if ch == "[":
            depth += 1
        elif ch == "]":
            depth -= 1
            if depth < 0:
                raise ValueError(f"policy specs {text!r}: unbalanced brackets (']' without '[')")
        if ch == "," and depth == 0:
            out.append(current)
            current = ""
        else:
            current += ch
    if depth != 0:
        raise ValueError(f"policy specs {text!r}: unbalanced brackets ('[' without ']')")
    out.append(current)
    return [s.strip() for s in out if s.strip()]


def parse_spec(spec: str) -> tuple[str, str | None, dict[str, Any]]:
    """Split a policy spec into ``(base spec, label, parameter overrides)``.

    A trailing bracket is either a label or a set of parameter overrides, never both:

    - ``"semantic[tuned]"``: no ``=`` inside, a label that only names the variant in tables;
    - ``"semantic[cost.w_v=0]"``, ``"semantic[cost.w_v=0;cost.w_p=0]"`` (``;`` or ``,``
      between items): dotted ``key=value`` overrides of the policy's parameters, applied by
      :func:`~semexplore_gym.policies.registry.make_policy` on top of its keyword overrides. The table label is the whole spec.

    Raises:
        ValueError: an empty bracket, a bracket mixing labels and ``key=value`` items, or an
            item that is not ``key=value``; the message names the spec.
    """
    if not isinstance(spec, str) or not spec.strip():
        raise ValueError(f"policy spec must be a non-empty string, got {spec!r}")
    base, inner = split_bracket(spec)
    if inner is None:
        if "[" in spec or "]" in spec:
            raise ValueError(
                f"policy spec {spec!r}: unbalanced brackets; one bracket closes the spec, as in "
                "'semantic[cost.w_v=0]' or 'semantic[my label]'"
            )
        return base, None, {}
    if not inner:
        raise ValueError(f"policy spec {spec!r}: empty brackets; give a label or key=value items")
    if not base:
        raise ValueError(f"policy spec {spec!r}: no policy name before the bracket")
    if "=" not in inner:
        return base, inner, {}
    items = [t.strip() for t in re.split(r"[;,]", inner)]
    overrides: dict[str, Any] = {}
    for item in items:
        if not item or "=" not in item:
            raise ValueError(
                f"policy spec {spec!r}: {item!r} is not key=value; a bracket is either a label "
                "(no '=') or parameter overrides such as [cost.w_v=0;cost.w_p=0], not both"
            )
        try:
            keys, value = parse_override(item)
        except ConfigError as e:
            raise ValueError(f"policy spec {spec!r}: {e}") from None
        key = ".".join(k.strip() for k in keys)
        if not all(k.strip() for k in keys):
            raise ValueError(f"policy spec {spec!r}: {item!r} has an empty key")
        if key in overrides:
            raise ValueError(f"policy spec {spec!r}: {key!r} is set twice")
        overrides[key] = value
    return base, None, overrides


def strip_label(spec: str) -> str:
    """``"semantic[tuned]"`` or ``"semantic[cost.w_v=0]"`` -> ``"semantic"``."""
    return split_bracket(spec)[0]
