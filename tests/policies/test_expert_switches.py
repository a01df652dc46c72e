"""The expert's params hold at most eight on/off switches, each a user's choice: old
behaviours live in old recipes (``policies/expert/recipes.py``), not in switches of today's
expert, and a removed switch is an error naming the version without it."""

from __future__ import annotations

import dataclasses

import pytest
from semexplore_gym.policies.expert.params import REMOVED_SWITCHES, SemanticExpertParams
from semexplore_gym.policies.registry import make_policy

#: The most on/off switches the expert's params may hold (nested groups included).
MAX_SWITCHES = 8
#: Today's switches, each documented in docs/policies.md ("How the default expert works").
SWITCHES = {
    "narrow_passages",
    "goal_commitment",
    "local_min_escape",
    "stuck_recovery",
    "potential_field.braking_guard",
    "segmentation.keep_debug",
}


def bool_leaves(obj: object, prefix: str = "") -> list[str]:
    """The dotted names of the bool leaves of a dataclass tree."""
    out = []
    for f in dataclasses.fields(obj):  # type: ignore[arg-type]
        value = getattr(obj, f.name)
        if dataclasses.is_dataclass(value):
            out += bool_leaves(value, f"{prefix}{f.name}.")
        elif isinstance(value, bool):
            out.append(prefix + f.name)
    return out


def test_at_most_eight_switches_remain() -> None:
    leaves = bool_leaves(SemanticExpertParams())
    assert len(leaves) <= MAX_SWITCHES, leaves
    assert set(leaves) == SWITCHES  # a new switch is documented here and in the docs first


def test_each_switch_is_documented_on_the_experts_page() -> None:
    from pathlib import Path

    page = (Path(__file__).resolve().parents[2] / "docs" / "policies.md").read_text()
    for name in SWITCHES:
        assert f"| `{name}` |" in page, name


@pytest.mark.parametrize("key", sorted(REMOVED_SWITCHES))
def test_a_removed_switch_is_an_error_naming_the_version_without_it(key: str) -> None:
    assert key not in bool_leaves(SemanticExpertParams())
    for spec in (f"semantic[{key}=false]", f"semantic-v2[{key}=true]"):
        with pytest.raises(ValueError, match=rf"config key '{key}' was removed") as e:
            make_policy(spec)
        message = str(e.value)
        assert "\n" not in message
        assert "semantic-v2" in message or "semantic-paper" in message


def test_a_removed_switch_in_a_policy_config_is_an_error_too(tmp_path, capsys) -> None:
    from semexplore_gym.cli import main

    cfg = tmp_path / "old.yaml"
    cfg.write_text("policy: semantic\nparams:\n  grid_fallback: false\n")
    argv = ["explore", "--world", "maze:seed=0,size_m=3", "--policy-config", str(cfg)]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "error: config key 'grid_fallback' was removed" in err[0]
    assert "semantic-paper" in err[0]


@pytest.mark.parametrize("spec", ["semantic", "semantic-v2", "semantic-paper", "frontier-value"])
def test_an_expert_with_its_recipe_pickles(spec: str) -> None:
    import pickle

    pol = make_policy(spec)
    back = pickle.loads(pickle.dumps(pol))
    assert repr(back.recipe) == repr(pol.recipe)
    assert [s.name for s in back.plan_sources] == [s.name for s in pol.plan_sources]
