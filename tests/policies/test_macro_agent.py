"""A trained macro-action agent as a step policy: same decisions and trajectory as its env id."""

from __future__ import annotations

import json
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest

import semexplore_gym  # noqa: F401  (registers the env ids)
from semexplore_gym.cli import main

CONFIGS = Path(__file__).resolve().parents[2] / "configs" / "agents"
KINDS = {
    "frontier": ("maskable_ppo", "frontier_choice_maze.yml", "SemanticExploreFrontier-v0"),
    "weights": ("ppo", "planner_weights_maze.yml", "SemanticExploreWeights-v0"),
}
WORLD = "maze:seed=3,size_m=4"
LIMIT = ["episode.max_time_s=40"]


@pytest.fixture(autouse=True)
def _one_thread() -> None:
    import torch

    torch.set_num_threads(1)


@pytest.fixture(scope="module")
def trained(tmp_path_factory, tiny_macro_train_args) -> dict[str, Path]:
    import torch

    torch.set_num_threads(1)
    out = {}
    for kind, (algo, config, _) in KINDS.items():
        run = tmp_path_factory.mktemp(kind)
        argv = ["train", "--algo", algo, "--train-config", str(CONFIGS / config), "--out", str(run)]
        assert main([*argv, *tiny_macro_train_args(3)]) == 0
        out[kind] = run / "model.zip"
    return out


@pytest.mark.parametrize("kind", list(KINDS))
def test_policy_replays_the_macro_env_exactly(trained, kind) -> None:
    from semexplore_gym.policies.macro_agent import MacroAgentPolicy
    from semexplore_gym.policies.registry import make_policy

    policy = make_policy(f"sb3:{trained[kind]}")
    assert isinstance(policy, MacroAgentPolicy) and policy.kind == kind

    # the agent inside its own macro env id
    env = gym.make(KINDS[kind][2], world=WORLD, overrides=LIMIT, macro=policy.macro_params)
    obs, info = env.reset(seed=5)
    decisions = []
    while True:
        if kind == "frontier":
            mask = env.get_wrapper_attr("action_masks")()
            a, _ = policy.model.predict(obs, deterministic=True, action_masks=mask)
        else:
            a, _ = policy.model.predict(obs, deterministic=True)
        decisions.append(np.asarray(a).tolist())
        obs, _, terminated, truncated, info = env.step(a)
        if terminated or truncated:
            break
    macro_end = (info["sim_time_s"], info["coverage"], info["path_length_m"])

    # the same agent as a step policy on the base env
    base = gym.make("SemanticExplore-v0", world=WORLD, overrides=LIMIT)
    obs, info = base.reset(seed=5)
    policy.reset(obs, info, seed=5)
    while True:
        a = policy.act(obs, info)
        if policy.done:
            break
        obs, _, terminated, truncated, info = base.step(a)
        if terminated or truncated:
            break
    assert policy.decisions == len(decisions) > 1
    assert (info["sim_time_s"], info["coverage"], info["path_length_m"]) == macro_end
    assert info["path_length_m"] > 1.0


def test_explore_cli_runs_a_macro_agent(trained, capsys) -> None:
    argv = ["explore", "--world", WORLD, "--policy", f"sb3:{trained['weights']}"]
    assert main([*argv, "--max-time-s", "12", "--json", "--no-progress"]) == 0
    result = json.loads(capsys.readouterr().out)
    assert 0.0 < result["coverage"] <= 1.0 and result["collisions"] == 0


def test_not_a_macro_run_and_mismatched_params_are_clear_errors(trained, tmp_path) -> None:
    from semexplore_gym.policies.macro_agent import MacroAgentPolicy, read_macro_run

    lone = tmp_path / "lone" / "model.zip"
    lone.parent.mkdir()
    lone.write_bytes(trained["weights"].read_bytes())
    assert read_macro_run(lone) is None  # no config.yaml beside it
    with pytest.raises(ValueError, match="not a macro-action agent"):
        MacroAgentPolicy(lone)
    with pytest.raises(FileNotFoundError, match="no model file"):
        MacroAgentPolicy(tmp_path / "missing.zip")
    run = read_macro_run(trained["frontier"])
    assert run is not None and run["kind"] == "frontier" and run["algo"] == "maskable_ppo"
    run["macro"]["n_candidates"] = 5
    with pytest.raises(ValueError, match="n_candidates=5"):
        MacroAgentPolicy(trained["frontier"], run=run)
