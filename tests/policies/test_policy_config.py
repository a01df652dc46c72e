"""Policy config files and overrides: YAML -> parameter dataclasses with dotted-key errors."""

from __future__ import annotations

from pathlib import Path

import pytest
from semexplore_gym.policies.expert.expert import SemanticExpertParams
from semexplore_gym.policies.registry import make_policy
from semexplore_gym.policies.specs import load_policy_config

from semexplore_gym.config import ConfigError, build_params
from semexplore_gym.core.features.macro import WEIGHT_RANGES
from semexplore_gym.core.planning.graph_search import FrontierCostWeights
from semexplore_gym.core.planning.potential_field import PotentialFieldParams

REPO = Path(__file__).resolve().parents[2]


def test_paper_config_holds_the_paper_values():
    cfg = load_policy_config(REPO / "configs" / "expert" / "robust_paper_weights.yaml")
    assert cfg.env == "paper" and cfg.policy == "semantic"
    p = build_params(SemanticExpertParams, cfg.params)
    assert (p.cost.w_v, p.cost.w_p, p.cost.w_i) == (4.0, 0.2, 0.1)
    assert (p.potential_field.f_g, p.potential_field.f_o, p.potential_field.f_l) == (
        30.0,
        0.065,
        1.5,
    )
    # The paper's values are also the defaults.
    d = SemanticExpertParams()
    assert (d.cost, d.potential_field.f_g, d.potential_field.f_o, d.potential_field.f_l) == (
        p.cost,
        30.0,
        0.065,
        1.5,
    )


def test_overrides_and_unknown_keys_name_the_dotted_path(tmp_path):
    p = build_params(
        SemanticExpertParams,
        {"cost": {"w_v": 1.0}},
        overrides=["cost.w_p=0.5", "replan_period_s=4"],
    )
    assert (p.cost.w_v, p.cost.w_p, p.replan_period_s) == (1.0, 0.5, 4.0)
    with pytest.raises(ConfigError, match="potential_field.f_q"):
        build_params(SemanticExpertParams, {}, overrides=["potential_field.f_q=1"])
    with pytest.raises(ConfigError, match="cost.w_v"):
        build_params(SemanticExpertParams, {"cost": {"w_v": "fast"}})
    with pytest.raises(ConfigError, match="replan_period_s"):
        build_params(SemanticExpertParams, {"replan_period_s": 0})
    bad = tmp_path / "bad.yaml"
    bad.write_text("env: paper\nweights: {}\n")
    with pytest.raises(ConfigError, match="weights"):
        load_policy_config(bad)
    with pytest.raises(FileNotFoundError):
        load_policy_config(tmp_path / "missing.yaml")


def test_paper_yaml_is_the_paper_preset():
    """configs/expert/robust_paper_weights.yaml restates the defaults, which are the paper's values."""
    cfg = load_policy_config(REPO / "configs" / "expert" / "robust_paper_weights.yaml")
    paper = SemanticExpertParams()
    assert build_params(SemanticExpertParams, cfg.params) == paper
    assert paper.cost == FrontierCostWeights() and paper.potential_field == PotentialFieldParams()
    # Every value the file sets is the default's, so it cannot drift from the code silently.
    for section, values in cfg.params.items():
        for key, value in values.items():
            assert getattr(getattr(paper, section), key) == value, f"{section}.{key}"
    # The weights action's centre (action 0) is the paper's cost weights.
    w = paper.cost
    assert tuple(mid for _, mid, _ in WEIGHT_RANGES) == (w.w_v, w.w_p, w.w_i)


def test_make_policy_layers_params_then_keyword_overrides():
    base = SemanticExpertParams(cost=FrontierCostWeights(w_v=1.0), replan_period_s=3.0)
    p = make_policy("semantic", params=base, **{"cost.w_p": 0.5}, cost={"w_i": 0.3}).params
    assert (p.cost.w_v, p.cost.w_p, p.cost.w_i, p.replan_period_s) == (1.0, 0.5, 0.3, 3.0)
    q = make_policy("semantic", params={"cost.w_v": 2.0}, cost=FrontierCostWeights(w_p=0.4))
    assert q.params.cost == FrontierCostWeights(w_p=0.4)
    assert make_policy("semantic", params=base).params == base
    with pytest.raises(ConfigError, match="cost.w_q"):
        make_policy("semantic", **{"cost.w_q": 1.0})


def test_policy_kwargs_put_set_items_on_the_files_params():
    cfg = load_policy_config(REPO / "configs" / "expert" / "robust_paper_weights.yaml")
    kwargs = cfg.policy_kwargs(["cost.w_v=2.5", "cost.w_p=0.5"])
    assert kwargs == {"cost": {"w_v": 2.5, "w_p": 0.5}, "params": cfg.params}
    assert make_policy("semantic", **kwargs).params.cost.w_v == 2.5
    assert load_policy_config(None).policy_kwargs() == {}
