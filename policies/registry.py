"""Build any policy from a short spec string: ``make_policy("semantic", **overrides)``.

Specs: ``"semantic"`` (the scripted expert), ``"frontier"`` (ROS frontier_exploration
baseline), ``"nearest"`` (Yamauchi's nearest frontier), ``"random"``, ``"sb3:<model.zip>"`` (a trained
agent). A spec may carry an argument after a colon. Keyword overrides set fields of the policy's
parameter dataclass, nested (``cost={"w_v": 2}``) or dotted (``**{"cost.w_v": 2}``); ``params=``
gives a whole parameter object or mapping to start from.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from policies.base import Policy
from policies.config import build_params, nest_dotted

Factory = Callable[[str, dict[str, Any]], Policy]


def _semantic(arg: str, overrides: dict[str, Any]) -> Policy:
    from policies.semantic_expert import SemanticExpertParams, SemanticExpertPolicy
    from semexplore_gym.core.params import to_dict

    segmenter = overrides.pop("segmenter", None)
    base = overrides.pop("params", None)
    if arg:
        raise ValueError(f"policy 'semantic' takes no argument, got 'semantic:{arg}'")
    data = to_dict(base) if isinstance(base, SemanticExpertParams) else nest_dotted(base or {})
    for key, value in nest_dotted(overrides).items():
        if isinstance(value, dict) and isinstance(data.get(key), dict):
            data[key] = {**data[key], **value}
        else:
            data[key] = value
    return SemanticExpertPolicy(build_params(SemanticExpertParams, data), segmenter=segmenter)


def _frontier_baseline(kind: str, arg: str, overrides: dict[str, Any]) -> Policy:
    from policies.frontier import (
        FrontierExplorationParams,
        FrontierExplorationPolicy,
        NearestFrontierParams,
        NearestFrontierPolicy,
    )
    from semexplore_gym.core.params import to_dict

    cls, policy_cls = (
        (FrontierExplorationParams, FrontierExplorationPolicy)
        if kind == "frontier"
        else (NearestFrontierParams, NearestFrontierPolicy)
    )
    if arg:
        raise ValueError(f"policy {kind!r} takes no argument, got '{kind}:{arg}'")
    base = overrides.pop("params", None)
    data = to_dict(base) if isinstance(base, cls) else nest_dotted(base or {})
    for key, value in nest_dotted(overrides).items():
        if isinstance(value, dict) and isinstance(data.get(key), dict):
            data[key] = {**data[key], **value}
        else:
            data[key] = value
    params: Any = build_params(cls, data)
    return policy_cls(params)


def _frontier(arg: str, overrides: dict[str, Any]) -> Policy:
    return _frontier_baseline("frontier", arg, overrides)


def _nearest(arg: str, overrides: dict[str, Any]) -> Policy:
    return _frontier_baseline("nearest", arg, overrides)


def _random(arg: str, overrides: dict[str, Any]) -> Policy:
    from policies.random_policy import RandomPolicy

    if arg or overrides:
        raise ValueError(
            f"policy 'random' takes no argument or parameters, got {arg!r} and {sorted(overrides)}"
        )
    return RandomPolicy()


def _sb3(arg: str, overrides: dict[str, Any]) -> Policy:
    from policies.sb3_policy import SB3Policy

    if not arg:
        raise ValueError("policy 'sb3' needs a model path: 'sb3:path/to/model.zip'")
    overrides.pop("params", None)
    return SB3Policy(arg, **overrides)


def policy_factories() -> dict[str, Factory]:
    """The known policy names and their factories ``(argument, overrides) -> Policy``."""
    return {
        "semantic": _semantic,
        "frontier": _frontier,
        "nearest": _nearest,
        "random": _random,
        "sb3": _sb3,
    }


def strip_label(spec: str) -> str:
    """``"semantic[tuned]"`` -> ``"semantic"``; a spec without a label is returned stripped."""
    spec = spec.strip()
    if spec.endswith("]") and "[" in spec:
        spec = spec[: spec.rindex("[")].strip()
    return spec


def make_policy(spec: str, **overrides: Any) -> Policy:
    """Create a policy from ``spec`` (``"name"`` or ``"name:argument"``).

    A trailing ``[label]`` (``"semantic[tuned]"``) only names a variant in benchmark tables;
    it is stripped before the policy is built (the variant comes from ``overrides``).

    Raises:
        ValueError: unknown name, a bad argument, or a bad parameter override (``ConfigError``
            names the dotted key).
    """
    if not isinstance(spec, str) or not spec.strip():
        raise ValueError(f"policy spec must be a non-empty string, got {spec!r}")
    spec = strip_label(spec)
    name, _, arg = spec.partition(":")
    factories = policy_factories()
    if name not in factories:
        raise ValueError(
            f"unknown policy {spec!r}; known: {', '.join(sorted(factories))} (sb3 as 'sb3:path.zip')"
        )
    return factories[name](arg, dict(overrides))
