"""``--help`` of every subcommand: a description, plain text (no reST markup), and the facts
users asked for."""

from __future__ import annotations

import argparse

import pytest

from semexplore_gym.cli import SUBCOMMANDS, build_parser, main
from semexplore_gym.cli.explore import format_result


def _help(argv: list[str], capsys) -> str:
    with pytest.raises(SystemExit) as exc:
        main([*argv, "--help"])
    assert exc.value.code == 0
    return capsys.readouterr().out


def _subparsers() -> dict[str, argparse.ArgumentParser]:
    parser = build_parser()
    (action,) = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]
    return dict(action.choices)


def test_every_subcommand_is_built() -> None:
    assert set(_subparsers()) == set(SUBCOMMANDS)


@pytest.mark.parametrize("command", sorted(SUBCOMMANDS))
def test_help_has_a_description_and_no_rest_markup(command: str, capsys) -> None:
    sub = _subparsers()[command]
    assert sub.description and len(sub.description.split()) >= 5, f"{command} has no description"
    text = _help([command], capsys)
    assert "``" not in text, f"semexplore {command} --help shows raw double backticks"
    assert "::\n" not in text and ":func:`" not in text and ":class:`" not in text
    # The description is shown, not only the usage line.
    assert sub.description.splitlines()[0].strip()[:40] in text


def test_top_level_help_lists_every_subcommand(capsys) -> None:
    text = _help([], capsys)
    assert "``" not in text
    for command in SUBCOMMANDS:
        assert command in text


def test_explore_policy_help_names_every_kind_of_spec(capsys) -> None:
    text = " ".join(_help(["explore"], capsys).split())
    for spec in ("semantic", "frontier", "nearest", "random", "sb3:", "py:"):
        assert spec in text, spec


def test_compare_weights_help_spells_the_config_keys(capsys) -> None:
    text = _help(["compare-weights"], capsys)
    for key in ("cost.w_v", "cost.w_p", "cost.w_i"):
        assert key in text


def test_explore_speed_reads_as_faster_than_simulated_time() -> None:
    summary = {
        "world": "maze1",
        "policy": "semantic",
        "seed": 0,
        "coverage": 0.99,
        "explored_area_m2": 40.0,
        "mission_time_s": 250.0,
        "self_stopped": True,
        "stop_reason": "no frontier left",
        "path_length_m": 50.0,
        "collisions": 0,
        "T90_s": 180.0,
        "T99_s": 240.0,
        "wall_time_s": 2.5,
        "mean_map_generation_ms": 5.0,
        "mean_global_planning_ms": 3.0,
        "n_replans": 100,
        "stage_time_s": {"env_step": 1.0},
    }
    line = next(x for x in format_result(summary).splitlines() if x.startswith("wall_time_s"))
    assert "100x faster than simulated time" in line


def test_segment_export_says_what_it_wrote(tmp_path, capsys) -> None:
    out = tmp_path / "export.json"
    assert main(["segment", "maze1", "--export", str(out)]) == 0
    assert out.is_file() and out.stat().st_size > 0
    assert f"wrote {out}" in capsys.readouterr().err
