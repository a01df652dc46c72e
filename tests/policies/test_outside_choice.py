"""Policies whose goals an outside choice makes (the expert driver, the frontier student, the
learned frontier value, the semantic team) run the outside-choice recipe: the semantic source
along the map's paths and without the grid's nearest frontier. A key or recipe they cannot
honour is an error naming it, not a silent override."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest
from semexplore_gym.policies.expert.driver import ExpertDriver
from semexplore_gym.policies.expert.recipes import (
    OUTSIDE_CHOICE,
    SEMANTIC_V2,
    SEMANTIC_V3,
    for_outside_choice,
)
from semexplore_gym.policies.registry import make_policy
from semexplore_gym.policies.team import make_team_policy

SPECS = ("frontier-student", "frontier-value")
#: The parts of today's semantic source an outside choice cannot honour, by their old keys.
REFUSED = ("grid_candidate", "semantic_grid_route")


def _off(recipe: object) -> bool:
    src = getattr(recipe, "semantic_source", None)
    return src is not None and not src.grid_candidate and not src.grid_route


@pytest.mark.parametrize("policy", SPECS)
def test_defaults_run_the_outside_choice_recipe(policy: str) -> None:
    pol = make_policy(policy)
    assert _off(pol.recipe) and pol.recipe.name == "outside-choice"
    assert [s.name for s in pol.plan_sources if s.name != "student"] == list(
        SEMANTIC_V3.source_names
    )


@pytest.mark.parametrize("policy", SPECS)
@pytest.mark.parametrize("key", REFUSED)
def test_a_switch_set_is_an_error_naming_the_key(policy: str, key: str) -> None:
    for value in ("true", "false"):
        with pytest.raises(ValueError, match=rf"config key 'expert\.{key}' was removed") as e:
            make_policy(f"{policy}[expert.{key}={value}]")
        assert "\n" not in str(e.value)


def test_the_semantic_team_refuses_it_too() -> None:
    team = make_team_policy("semantic")
    assert team.params.expert == make_policy("semantic").params
    with pytest.raises(ValueError, match=r"'expert\.grid_candidate' was removed"):
        make_team_policy("semantic[expert.grid_candidate=true]")


def test_the_team_members_run_the_outside_choice_recipe() -> None:
    from semexplore_gym.policies.team.semantic_team import _ExpertMember

    team = make_team_policy("semantic")
    assert _ExpertMember(team, 0, team.params.expert).recipe is OUTSIDE_CHOICE


def test_the_expert_driver_refuses_a_recipe_it_cannot_honour() -> None:
    assert ExpertDriver().recipe is OUTSIDE_CHOICE
    with pytest.raises(
        ValueError, match=r"expert driver cannot honour recipe 'semantic-v3'.*grid_"
    ):
        ExpertDriver(recipe=SEMANTIC_V3)
    # The 0.2.0 expert drove the map's paths without the grid candidate: the driver can run it.
    assert ExpertDriver(recipe=SEMANTIC_V2).recipe is SEMANTIC_V2


def test_for_outside_choice_passes_recipes_it_can_honour() -> None:
    assert for_outside_choice(OUTSIDE_CHOICE, "x") is OUTSIDE_CHOICE
    with pytest.raises(ValueError, match=r"^x cannot honour recipe 'semantic-v3'"):
        for_outside_choice(SEMANTIC_V3, "x")


def test_the_cli_prints_one_line_and_exits_2() -> None:
    spec = "frontier-student[expert.semantic_grid_route=true]"
    env = {**os.environ, "PYTHONPATH": str(Path(__file__).resolve().parents[2])}
    proc = subprocess.run(
        [sys.executable, "-m", "semexplore_gym.cli", "explore", "--policy", spec, "--json"],
        capture_output=True,
        text=True,
        env=env,
        timeout=120,
    )
    assert proc.returncode == 2
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1, proc.stderr
    assert "error:" in lines[0] and "'expert.semantic_grid_route' was removed" in lines[0]
    assert "semantic-v2" in lines[0]
    assert "Traceback" not in proc.stderr
    assert proc.stdout == ""
