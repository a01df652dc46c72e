"""Strict config loading: unknown keys and bad values are named by their dotted path."""

from __future__ import annotations

from dataclasses import dataclass, field

import pytest

from semexplore_gym.core.params import ConfigError, from_dict, load_yaml, merge_overrides, to_dict


@dataclass(frozen=True)
class Inner:
    speed_mps: float = 1.0
    n: int = 3
    flag: bool = False
    pose: tuple[float, float, float] | None = None


@dataclass(frozen=True)
class Outer:
    inner: Inner = field(default_factory=Inner)
    name: str = "x"


def test_defaults_and_nested_values() -> None:
    cfg = from_dict(Outer, {"inner": {"speed_mps": 2, "n": "5", "flag": "true", "pose": [1, 2, 3]}})
    assert cfg == Outer(Inner(2.0, 5, True, (1.0, 2.0, 3.0)))
    assert from_dict(Outer, None) == Outer()
    assert from_dict(Outer, to_dict(cfg)) == cfg


def test_unknown_key_is_named_with_its_path() -> None:
    with pytest.raises(ConfigError, match=r"'inner\.sped_mps'.*speed_mps"):
        from_dict(Outer, {"inner": {"sped_mps": 1}})


@pytest.mark.parametrize("value", ["fast", [1], True])
def test_wrong_type_is_named(value) -> None:
    with pytest.raises(ConfigError, match=r"inner\.speed_mps"):
        from_dict(Outer, {"inner": {"speed_mps": value}})


def test_overrides_parse_yaml_scalars() -> None:
    data = merge_overrides(
        {"inner": {"n": 1}}, ["inner.speed_mps=0.5", "inner.flag=true", "name=abc"]
    )
    assert from_dict(Outer, data) == Outer(Inner(0.5, 1, True), "abc")
    with pytest.raises(ConfigError, match="key.path=value"):
        merge_overrides({}, ["novalue"])


def test_load_yaml_errors(tmp_path) -> None:
    with pytest.raises(FileNotFoundError, match="nope.yaml"):
        load_yaml(tmp_path / "nope.yaml")
    bad = tmp_path / "bad.yaml"
    bad.write_text("a: [1, 2\n")
    with pytest.raises(ConfigError, match="bad.yaml"):
        load_yaml(bad)
    lst = tmp_path / "list.yaml"
    lst.write_text("- 1\n- 2\n")
    with pytest.raises(ConfigError, match="mapping"):
        load_yaml(lst)
