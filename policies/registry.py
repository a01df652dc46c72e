"""Build any policy from a short spec string: ``make_policy("semantic", **overrides)``.

Specs: ``"semantic"`` (the scripted expert, its newest version), ``"semantic-v2"``,
``"semantic-v3"`` (its named versions, :mod:`semexplore_gym.policies.expert.versions`),
``"semantic-paper"``  (the paper's method alone,
every addition of ours off), ``"frontier-value"`` (the expert choosing frontiers by a learned
value, :mod:`semexplore_gym.policies.learned_frontier_value`), ``"frontier-student"`` (the expert's
navigation choosing among every frontier by a score learned from the oracle,
``frontier-student:runs/NAME/model.yaml``; :mod:`semexplore_gym.policies.frontier_student`), ``"frontier"`` (ROS frontier_exploration
baseline), ``"nearest"`` (Yamauchi's nearest frontier), ``"random"``, ``"oracle"`` (privileged:
reads the true world, a yardstick for benchmarks, :mod:`semexplore_gym.policies.oracle`), ``"sb3:<model.zip>"`` (a
trained agent: an egocentric BC/DAgger/PPO model, or a frontier-choice / planner-weights macro
agent with the expert driving), ``"py:<module or file.py>:<Name>"`` (your own
:class:`~semexplore_gym.policies.base.Policy` subclass or factory, so ``semexplore benchmark`` can compare it
with the built-in ones). A spec may carry an argument after a colon. Keyword overrides set
fields of the policy's parameter dataclass, nested (``cost={"w_v": 2}``) or dotted
(``**{"cost.w_v": 2}``); ``params=`` gives the layer to start from (a parameter object, a
mapping or a YAML file), all merged by :func:`semexplore_gym.config.build_params`.
Spec strings and their brackets are parsed by :mod:`semexplore_gym.policies.specs`.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from types import ModuleType
from typing import Any

from semexplore_gym.policies.base import Policy
from semexplore_gym.policies.specs import parse_spec

from semexplore_gym.config import build_params

Factory = Callable[[str, dict[str, Any]], Policy]


def _expert_like(
    name: str,
    arg: str,
    overrides: dict[str, Any],
    policy_cls: Any,
    *layers: Any,
    **kwargs: Any,
) -> Policy:
    """A semantic-expert-family policy: ``policy_cls(params, segmenter=..., **kwargs)`` with
    its params built from ``layers``, the caller's ``params`` and the overrides."""
    segmenter = overrides.pop("segmenter", None)
    base = overrides.pop("params", None)
    if arg:
        raise ValueError(f"policy {name!r} takes no argument, got '{name}:{arg}'")
    return policy_cls(build_params(*layers, base, overrides), segmenter=segmenter, **kwargs)


def _expert_recipe(name: str, recipe: Any) -> Factory:
    """The factory of an expert made from ``recipe`` (:mod:`semexplore_gym.policies.expert.
    recipes`): its parameter values below the caller's params. The argument may name a YAML
    file of parameter values (``semantic:configs/expert/optuna_weights.yaml``), a layer
    between the recipe's values and the caller's."""

    def factory(arg: str, overrides: dict[str, Any]) -> Policy:
        from semexplore_gym.policies.expert.expert import (
            SemanticExpertParams,
            SemanticExpertPolicy,
        )

        layers: list[Any] = [SemanticExpertParams, dict(recipe.params) or None]
        if arg:
            if not arg.endswith((".yaml", ".yml")):
                raise ValueError(
                    f"policy {name!r} takes no argument but a parameter file (.yaml), "
                    f"got '{name}:{arg}'"
                )
            layers.append(arg)
        return _expert_like(name, "", overrides, SemanticExpertPolicy, *layers, recipe=recipe)

    return factory


def _frontier_value(arg: str, overrides: dict[str, Any]) -> Policy:
    """The expert choosing frontiers by a learned value (:mod:`semexplore_gym.policies.learned_frontier_value`)."""
    from semexplore_gym.policies.learned_frontier_value import (
        FrontierValueParams,
        FrontierValuePolicy,
    )

    layers = (FrontierValueParams,)
    return _expert_like("frontier-value", arg, overrides, FrontierValuePolicy, *layers)


def _frontier_student(arg: str, overrides: dict[str, Any]) -> Policy:
    """The expert's navigation choosing among every frontier by a learned score
    (:mod:`semexplore_gym.policies.frontier_student`)."""
    from semexplore_gym.policies.frontier_student import (
        FrontierStudentParams,
        FrontierStudentPolicy,
    )

    if arg:  # frontier-student:runs/NAME/model.yaml, a trained model
        if not os.path.isfile(arg):
            raise ValueError(f"policy 'frontier-student:{arg}': no such model file")
        if overrides.get("params") is not None:
            raise ValueError(
                f"policy 'frontier-student:{arg}': give the model file or params, not both"
            )
        overrides["params"] = arg
    layers = (FrontierStudentParams,)
    return _expert_like("frontier-student", "", overrides, FrontierStudentPolicy, *layers)


def _frontier_baseline(kind: str, arg: str, overrides: dict[str, Any]) -> Policy:
    from semexplore_gym.policies.frontier_baselines import (
        FrontierExplorationParams,
        FrontierExplorationPolicy,
        NearestFrontierParams,
        NearestFrontierPolicy,
    )

    cls, policy_cls = (
        (FrontierExplorationParams, FrontierExplorationPolicy)
        if kind == "frontier"
        else (NearestFrontierParams, NearestFrontierPolicy)
    )
    if arg:
        raise ValueError(f"policy {kind!r} takes no argument, got '{kind}:{arg}'")
    params: Any = build_params(cls, overrides.pop("params", None), overrides)
    return policy_cls(params)


def _frontier(arg: str, overrides: dict[str, Any]) -> Policy:
    return _frontier_baseline("frontier", arg, overrides)


def _nearest(arg: str, overrides: dict[str, Any]) -> Policy:
    return _frontier_baseline("nearest", arg, overrides)


def _random(arg: str, overrides: dict[str, Any]) -> Policy:
    from semexplore_gym.policies.random_policy import RandomPolicy

    if arg or overrides:
        raise ValueError(
            f"policy 'random' takes no argument or parameters, got {arg!r} and {sorted(overrides)}"
        )
    return RandomPolicy()


def _oracle(arg: str, overrides: dict[str, Any]) -> Policy:
    """The privileged full-knowledge explorer (:mod:`semexplore_gym.policies.oracle`)."""
    from semexplore_gym.policies.oracle import OracleParams, OraclePolicy

    from semexplore_gym.core.coverage_tour.tour import require_solver

    try:
        require_solver()
    except ImportError as e:
        raise ValueError(str(e)) from None
    if arg:
        raise ValueError(f"policy 'oracle' takes no argument, got 'oracle:{arg}'")
    return OraclePolicy(build_params(OracleParams, overrides.pop("params", None), overrides))


def _sb3(arg: str, overrides: dict[str, Any]) -> Policy:
    if not arg:
        raise ValueError("policy 'sb3' needs a model path: 'sb3:path/to/model.zip'")
    overrides.pop("params", None)
    from semexplore_gym.policies.macro_agent import MacroAgentPolicy, read_macro_run

    # A model trained on a macro-action env id decides frontiers or weights; the expert drives.
    try:
        run = read_macro_run(arg)
        if run is not None:
            return MacroAgentPolicy(arg, run=run, **overrides)
        from semexplore_gym.policies.sb3_policy import SB3Policy

        return SB3Policy(arg, **overrides)
    except (ValueError, FileNotFoundError, ImportError):
        raise
    except Exception as e:  # noqa: BLE001 - a corrupt zip fails in zipfile, pickle, torch, ...
        raise ValueError(
            f"policy 'sb3:{arg}': cannot load the model ({type(e).__name__}: {str(e)[:200]})"
        ) from None


def _pretrained(arg: str, overrides: dict[str, Any]) -> Policy:
    """``pretrained:NAME``: a model shipped in :mod:`semexplore_gym.policies.pretrained` (``semexplore pretrained``)."""
    from semexplore_gym.policies.pretrained import get_pretrained

    model = get_pretrained(arg)
    if model.policy:  # a policy of its own reads the file (option-ppo)
        policy = policy_factories()[model.policy](str(model.model_path), overrides)
    elif model.model_path.suffix == ".yaml":
        # A learned frontier value or a frontier student: weights on top of the expert's
        # navigation (no torch needed); a student's file has a ``model`` section.
        from semexplore_gym.config.loading import load_yaml_file

        data = load_yaml_file(model.model_path, f"pretrained model {arg!r}") or {}
        factory = _frontier_student if "model" in data else _frontier_value
        policy = factory("", {"params": model.model_path, **overrides})
    else:
        policy = _sb3(str(model.model_path), overrides)
    policy.name = model.spec
    return policy


def _option_ppo(arg: str, overrides: dict[str, Any]) -> Policy:
    """``option-ppo:MODEL.zip``: the frontier student choosing by the option actor
    (:mod:`semexplore_gym.policies.option_ppo`; torch and sb3-contrib needed)."""
    from semexplore_gym.policies.option_ppo import OptionPPOPolicy

    if not arg or not os.path.isfile(arg):
        raise ValueError(f"policy 'option-ppo:{arg}': no such model file")
    if overrides:
        raise ValueError(f"policy 'option-ppo:{arg}' takes no parameters, got {sorted(overrides)}")
    return OptionPPOPolicy(arg)


def _user_module(arg: str, source: str) -> ModuleType:
    """The module of a ``py:`` spec: ``source`` is a ``.py`` file (run once per path) or a
    dotted module name on ``sys.path``; its failures become ValueErrors naming the spec."""
    import hashlib
    import importlib
    import importlib.util
    import sys
    from pathlib import Path

    if not source.endswith(".py"):
        try:
            return importlib.import_module(source)
        except ModuleNotFoundError as e:
            raise ValueError(
                f"policy 'py:{arg}': cannot import module {source!r} ({e}); is it on PYTHONPATH?"
            ) from None
        except (Exception, SystemExit) as e:  # noqa: BLE001 - the user's module failed
            raise ValueError(
                f"policy 'py:{arg}': importing {source!r} raised {type(e).__name__}: {str(e)[:200]}"
            ) from None
    path = Path(source).resolve()
    if not path.is_file():
        raise FileNotFoundError(f"policy 'py:{arg}': no such file {path}")
    digest = hashlib.sha1(str(path).encode()).hexdigest()[:12]
    mod_name = f"_semexplore_user_policy_{path.stem}_{digest}"
    module = sys.modules.get(mod_name)
    if module is None:
        spec = importlib.util.spec_from_file_location(mod_name, path)
        assert spec is not None and spec.loader is not None
        module = importlib.util.module_from_spec(spec)
        sys.modules[mod_name] = module
        try:
            spec.loader.exec_module(module)
        except BaseException as e:
            del sys.modules[mod_name]
            if isinstance(e, (Exception, SystemExit)):
                raise ValueError(
                    f"policy 'py:{arg}': running {path.name} raised {type(e).__name__}: "
                    f"{str(e)[:200]}"
                ) from None
            raise
    return module


def _python(arg: str, overrides: dict[str, Any]) -> Policy:
    """``py:MODULE:NAME`` or ``py:path/to/file.py:NAME``: a user's own policy.

    ``NAME`` is a :class:`~semexplore_gym.policies.base.Policy` subclass or a factory function returning a
    policy; the overrides are passed to it as keyword arguments.
    """
    source, sep, attr = arg.rpartition(":")
    if not sep or not source or not attr:
        raise ValueError(
            f"policy 'py:{arg}' must name a module or .py file and an object: "
            "'py:my_package.planner:MyPolicy' or 'py:path/to/planner.py:MyPolicy'"
        )
    module = _user_module(arg, source)
    if not hasattr(module, attr):
        raise ValueError(f"policy 'py:{arg}': module {source!r} has no attribute {attr!r}")
    target = getattr(module, attr)
    if not callable(target):
        raise ValueError(
            f"policy 'py:{arg}': {attr!r} is a {type(target).__name__}, not a class or function"
        )
    try:
        policy = target(**overrides)
    except (Exception, SystemExit) as e:  # noqa: BLE001 - SystemExit: py:sys:exit must not exit 0
        raise ValueError(
            f"policy 'py:{arg}': {attr}() raised {type(e).__name__}: {str(e)[:200]}"
        ) from None
    if not isinstance(policy, Policy):
        raise ValueError(
            f"policy 'py:{arg}': {attr}() returned a {type(policy).__name__}, "
            "not a semexplore_gym.policies.base.Policy"
        )
    return policy


def policy_factories() -> dict[str, Factory]:
    """The known policy names and their factories ``(argument, overrides) -> Policy``."""
    from semexplore_gym.policies.expert.recipes import PAPER_METHOD
    from semexplore_gym.policies.expert.versions import (
        EXPERT_VERSIONS,
        NEWEST_ALIAS,
        version_recipe,
    )

    return {
        NEWEST_ALIAS: _expert_recipe(NEWEST_ALIAS, version_recipe(NEWEST_ALIAS)),
        **{name: _expert_recipe(name, v.recipe) for name, v in EXPERT_VERSIONS.items()},
        "semantic-paper": _expert_recipe("semantic-paper", PAPER_METHOD),
        "frontier-value": _frontier_value,
        "frontier-student": _frontier_student,
        "option-ppo": _option_ppo,
        "frontier": _frontier,
        "nearest": _nearest,
        "random": _random,
        "oracle": _oracle,
        "sb3": _sb3,
        "pretrained": _pretrained,
        "py": _python,
    }


def make_policy(spec: str, **overrides: Any) -> Policy:
    """Create a policy from ``spec`` (``"name"``, ``"name:argument"``, either with a bracket).

    A trailing ``[label]`` (``"semantic[tuned]"``) only names a variant in benchmark tables;
    a trailing ``[key=value;...]`` (``"semantic[cost.w_v=0]"``) sets parameters, on top of
    ``overrides`` (see :func:`~semexplore_gym.policies.specs.parse_spec`).

    Raises:
        ValueError: unknown name, a bad argument or bracket, or a bad parameter override
            (the message names the spec and the dotted key).
    """
    if not isinstance(spec, str) or not spec.strip():
        raise ValueError(f"policy spec must be a non-empty string, got {spec!r}")
    base, _, bracket = parse_spec(spec)
    name, _, arg = base.partition(":")
    factories = policy_factories()
    if name not in factories:
        raise ValueError(
            f"unknown policy {spec!r}; known: {', '.join(sorted(factories))} "
            "(sb3 as 'sb3:path.zip', your own as 'py:module:Class' or 'py:file.py:Class')"
        )
    if not bracket:
        return factories[name](arg, dict(overrides))
    # Dotted keys after the keyword layer: build_params lets later keys win.
    merged = {**overrides, **bracket}
    try:
        return factories[name](arg, merged)
    except ValueError as e:
        raise ValueError(f"policy spec {spec!r}: {e}") from None
