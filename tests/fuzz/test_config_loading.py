"""Bounded YAML / JSON loading and bounded printing (issue #18, items 1 and 7)."""

from __future__ import annotations

import time

import pytest

from semexplore_gym.cli import main
from semexplore_gym.config import ConfigError, load_yaml, merge_overrides, parse_override
from semexplore_gym.config.loading import (
    UnsafeInputError,
    load_json_file,
    load_json_text,
    load_yaml_file,
    load_yaml_text,
)
from semexplore_gym.core.validation import short_repr


def alias_bomb(levels: int = 9, width: int = 9, key: str = "image") -> str:
    lines = ["l0: &l0 [" + ", ".join(['"lol"'] * width) + "]"]
    for i in range(1, levels):
        lines.append(f"l{i}: &l{i} [" + ", ".join([f"*l{i - 1}"] * width) + "]")
    return "\n".join(lines) + f"\n{key}: *l{levels - 1}\n"


def test_alias_bomb_is_refused_fast() -> None:
    text = alias_bomb()
    assert len(text) < 600
    t0 = time.perf_counter()
    with pytest.raises(UnsafeInputError, match="expands to more than"):
        load_yaml_text(text, "bomb.yaml")
    assert time.perf_counter() - t0 < 2.0


def test_shared_aliases_within_bounds_still_load() -> None:
    data = load_yaml_text("a: &a [1, 2]\nb: *a\nc: *a\n")
    assert data == {"a": [1, 2], "b": [1, 2], "c": [1, 2]}


@pytest.mark.parametrize(
    "text,fragment",
    [
        ("x: " + "[" * 5000 + "]" * 5000, "nested"),
        ("x: " + "[" * 70 + "]" * 70, "nested deeper than 64"),
        ("a: &a [*a]", "recursive alias"),
        ("x: !!python/object/apply:os.system ['echo hi']", "bad YAML value"),
        ("? [1]\n: 2\n", "bad YAML value"),
        ("a: [1, 2", "malformed YAML"),
        ("t: 2001-13-45", "month must be in 1..12"),
    ],
)
def test_bad_yaml_gets_one_short_line(text: str, fragment: str) -> None:
    with pytest.raises(UnsafeInputError, match=fragment) as info:
        load_yaml_text(text, "cfg.yaml")
    msg = str(info.value)
    assert msg.startswith("cfg.yaml: ") and "\n" not in msg and len(msg) < 400


def test_file_size_and_encoding_are_checked(tmp_path) -> None:
    big = tmp_path / "big.yaml"
    big.write_bytes(b"#" + b"x" * (2 << 20))
    with pytest.raises(UnsafeInputError, match=r"big.yaml: \d+ bytes is more than"):
        load_yaml_file(big)
    latin = tmp_path / "latin.yaml"
    latin.write_bytes(b"a: caf\xe9\n")
    with pytest.raises(UnsafeInputError, match=r"latin.yaml: not UTF-8"):
        load_yaml_file(latin)
    j = tmp_path / "x.json"
    j.write_bytes(b'{"a": "\xff"}')
    with pytest.raises(UnsafeInputError, match=r"x.json: not UTF-8"):
        load_json_file(j)


@pytest.mark.parametrize(
    "text,fragment",
    [("[" * 100000, "nested deeper"), ("[NaN]", "NaN is not a JSON number"), ("{", "malformed")],
)
def test_bad_json(text: str, fragment: str) -> None:
    with pytest.raises(UnsafeInputError, match=fragment):
        load_json_text(text, "h.json")


def test_short_repr_is_bounded_and_cheap() -> None:
    huge = [[list(range(1000))] * 1000] * 1000  # a billion values if printed in full
    t0 = time.perf_counter()
    text = short_repr(huge)
    assert len(text) <= 80 and time.perf_counter() - t0 < 0.1
    assert short_repr("x" * 10_000, 40).endswith("...") and len(short_repr("x" * 10_000, 40)) == 40
    assert short_repr(1.5) == "1.5"


def test_config_file_and_override_bombs_are_config_errors(tmp_path) -> None:
    cfg = tmp_path / "c.yaml"
    cfg.write_text(alias_bomb(key="robot"))
    with pytest.raises(ConfigError, match="alias bomb"):
        load_yaml(cfg)
    with pytest.raises(ConfigError, match="alias bomb"):
        parse_override("robot.radius_m=" + alias_bomb().replace("\n", ", ").join("{}"))
    with pytest.raises(ConfigError, match="nested"):
        merge_overrides({}, ["robot.radius_m=" + "[" * 3000 + "]" * 3000])


def test_bad_value_in_message_is_truncated() -> None:
    from semexplore_gym.envs.env_config import load_env_config

    with pytest.raises(ConfigError) as info:
        load_env_config(None, ["robot.radius_m=" + "[" + ", ".join(["1"] * 5000) + "]"])
    assert len(str(info.value)) < 300


def test_show_world_on_alias_bomb_map_is_one_short_line(tmp_path, capsys) -> None:
    y = tmp_path / "bomb.yaml"
    y.write_text(alias_bomb())
    t0 = time.perf_counter()
    assert main(["show-world", str(y), "--out", str(tmp_path / "o.png")]) == 2
    err = capsys.readouterr().err
    assert time.perf_counter() - t0 < 5.0
    assert "bomb.yaml" in err and "alias bomb" in err
    assert err.count("\n") == 1 and len(err) < 400


def test_non_utf8_map_yaml_names_the_file(tmp_path, capsys) -> None:
    y = tmp_path / "latin.yaml"
    y.write_bytes(b"image: m\xe9.pgm\nresolution: 0.05\norigin: [0, 0, 0]\n")
    assert main(["segment", str(y)]) == 2
    err = capsys.readouterr().err
    assert "latin.yaml" in err and "not UTF-8" in err
