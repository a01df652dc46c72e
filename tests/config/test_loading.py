"""Bounded YAML reading: deep nesting is refused before the parser recurses into it."""

from __future__ import annotations

import pytest
import yaml

from semexplore_gym.config.loading import MAX_DEPTH, UnsafeInputError, load_yaml_text


def test_deep_flow_nesting_is_refused_before_parsing(monkeypatch) -> None:
    def no_parser(*_a, **_k):
        raise AssertionError("the parser must not see it")

    deep = "robot: " + "[" * 20000 + "1" + "]" * 20000 + "\n"
    with monkeypatch.context() as m:
        m.setattr(yaml, "SafeLoader", no_parser)
        with pytest.raises(UnsafeInputError, match="nested deeper than"):
            load_yaml_text(deep, "c.yaml")
    over = "a: " + "{b: " * (MAX_DEPTH + 1) + "1" + "}" * (MAX_DEPTH + 1)
    with pytest.raises(UnsafeInputError, match="c.yaml: nested deeper than 64"):
        load_yaml_text(over, "c.yaml")


def test_ordinary_nesting_and_brackets_in_strings_load() -> None:
    assert load_yaml_text("a: [[1, 2], {b: [3]}]") == {"a": [[1, 2], {"b": [3]}]}
    assert load_yaml_text("name: 'x[y]{z}'") == {"name": "x[y]{z}"}
