"""Strict config loading: unknown keys and bad values are named by their dotted path."""

from __future__ import annotations

from dataclasses import dataclass, field

import pytest

from semexplore_gym.config import (
    ConfigError,
    build_params,
    from_dict,
    load_yaml,
    merge_overrides,
    nest_dotted,
    to_dict,
)


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


def test_nest_dotted_merges_levels() -> None:
    assert nest_dotted({"a.b": 1, "a": {"c": 2}, "d": 3}) == {"a": {"b": 1, "c": 2}, "d": 3}
    data = {"a": {"b": [1, 2]}}
    out = nest_dotted(data)
    out["a"]["b"].append(3)
    assert data == {"a": {"b": [1, 2]}}


def test_build_params_merges_layers_in_order(tmp_path) -> None:
    path = tmp_path / "c.yaml"
    path.write_text("inner:\n  n: 7\n  flag: true\nname: from_yaml\n")
    presets = {"fast": Outer(Inner(speed_mps=5.0)), "named": {"name": "preset"}}
    cfg = build_params(
        Outer,
        "fast",  # preset (a dataclass): every field
        str(path),  # YAML: n, flag and name
        {"inner.speed_mps": 6, "inner": {"pose": [1, 2, 3]}},  # dotted and nested keys merge
        None,  # skipped
        overrides=["name=last", "inner.n=8"],
        presets=presets,
    )
    assert cfg == Outer(Inner(6.0, 8, True, (1.0, 2.0, 3.0)), "last")
    assert build_params(Outer, "named", presets=presets) == Outer(name="preset")
    assert build_params(Outer) == Outer()
    same = Outer(Inner(2.0))
    assert build_params(Outer, same) is same
    # a dataclass value is a layer too: a later mapping merges into its fields
    merged = build_params(Outer, {"inner": Inner(n=4)}, {"inner": {"flag": True}})
    assert merged == Outer(Inner(n=4, flag=True))


def test_build_params_errors_name_what_is_wrong(tmp_path) -> None:
    with pytest.raises(ConfigError, match=r"'inner\.sped_mps'"):
        build_params(Outer, {"inner.sped_mps": 1})
    with pytest.raises(ConfigError, match=r"'inner\.sped_mps'"):
        build_params(Outer, overrides=["inner.sped_mps=1"])
    with pytest.raises(ConfigError, match="not a preset"):
        build_params(Outer, "fastest", presets={"fast": {}})
    with pytest.raises(FileNotFoundError, match="nope.yaml"):
        build_params(Outer, tmp_path / "nope.yaml")
    with pytest.raises(ConfigError, match="config layer"):
        build_params(Outer, 3)
    with pytest.raises(ConfigError, match="key.path=value"):
        build_params(Outer, overrides="name=x")
