"""Policy config files and overrides: YAML -> parameter dataclasses with dotted-key errors."""

from __future__ import annotations

from pathlib import Path

import pytest

from policies.config import ConfigError, build_params, load_policy_config, nest_dotted
from policies.semantic_expert import SemanticExpertParams

REPO = Path(__file__).resolve().parents[2]


def test_paper_config_holds_the_paper_values():
    cfg = load_policy_config(REPO / "configs" / "expert" / "paper.yaml")
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
        SemanticExpertParams, {"cost": {"w_v": 1.0}}, ["cost.w_p=0.5", "replan_period_s=4"]
    )
    assert (p.cost.w_v, p.cost.w_p, p.replan_period_s) == (1.0, 0.5, 4.0)
    with pytest.raises(ConfigError, match="potential_field.f_q"):
        build_params(SemanticExpertParams, {}, ["potential_field.f_q=1"])
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


def test_nest_dotted_merges_levels():
    assert nest_dotted({"a.b": 1, "a": {"c": 2}, "d": 3}) == {"a": {"b": 1, "c": 2}, "d": 3}
