"""Policies whose goals an outside choice makes (frontier student, learned frontier value, the
semantic team) run their expert with ``grid_candidate`` and ``semantic_grid_route`` off; a user
who sets one on gets an error naming the key, not a silent override."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest
from semexplore_gym.policies.expert.params import (
    OUTSIDE_CHOICE_OFF,
    SemanticExpertParams,
    for_outside_choice,
)
from semexplore_gym.policies.registry import make_policy
from semexplore_gym.policies.team import make_team_policy

SPECS = ("frontier-student", "frontier-value")


@pytest.mark.parametrize("policy", SPECS)
def test_defaults_run_with_the_switches_off(policy: str) -> None:
    params = make_policy(policy).params
    for key in OUTSIDE_CHOICE_OFF:
        assert getattr(params, key) is False
    # Saying what the policy does anyway is accepted.
    assert not make_policy(f"{policy}[expert.semantic_grid_route=false]").params.grid_candidate


@pytest.mark.parametrize("policy", SPECS)
@pytest.mark.parametrize("key", sorted(OUTSIDE_CHOICE_OFF))
def test_a_switch_set_on_is_an_error_naming_the_key(policy: str, key: str) -> None:
    with pytest.raises(ValueError, match=rf"{policy} cannot honour expert\.{key}=true") as e:
        make_policy(f"{policy}[expert.{key}=true]")
    assert "\n" not in str(e.value)
    assert OUTSIDE_CHOICE_OFF[key] in str(e.value)  # and why


def test_the_semantic_team_refuses_it_too() -> None:
    assert make_team_policy("semantic").params.expert.grid_candidate is False
    with pytest.raises(ValueError, match=r"expert\.grid_candidate=true"):
        make_team_policy("semantic[expert.grid_candidate=true]")


def test_for_outside_choice_passes_params_it_can_honour() -> None:
    off = SemanticExpertParams(grid_candidate=False, semantic_grid_route=False)
    assert for_outside_choice(off, "x") is off
    with pytest.raises(ValueError, match=r"^x cannot honour expert\.grid_candidate=true"):
        for_outside_choice(SemanticExpertParams(), "x")


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
    assert "error:" in lines[0] and "expert.semantic_grid_route=true" in lines[0]
    assert "Traceback" not in proc.stderr
    assert proc.stdout == ""
