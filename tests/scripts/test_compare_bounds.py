"""scripts/compare_bounds.py: today's bound against one with other parameters, world by world."""

from __future__ import annotations

import json

WORLD = "maze:seed=3,size_m=4"


def test_the_hop_depth_raises_a_mazes_bound_and_no_branches_lowers_it(capsys, script):
    args = ["--world", WORLD, "--set", "hop_depth=false", "--json"]
    assert script("compare_bounds").main(args) == 0
    row = json.loads(capsys.readouterr().out.strip())
    assert row["world"] == WORLD and row["start_seed"] == 0
    assert 0 < row["changed_m"] < row["default_m"] and row["ratio"] < 1
    args = ["--world", WORLD, "--set", "branch_block_m=0", "--set", "group_scales=[1.0]"]
    assert script("compare_bounds").main(args) == 0
    table = capsys.readouterr().out.strip().splitlines()
    assert table[0].startswith("| world |") and len(table) == 3
    default_m, changed_m, ratio = (float(c) for c in table[2].split("|")[2:5])
    assert changed_m <= default_m and abs(ratio - changed_m / default_m) < 1e-3


def test_a_base_setting_is_the_first_bound_and_under_the_second(capsys, script):
    """``--base`` sets both bounds' parameters: the first is then what ``--set`` alone gives
    as its second, and the second has both (no depth, and then no branch part either)."""
    args = ["--world", WORLD, "--set", "hop_depth=false", "--json"]
    assert script("compare_bounds").main(args) == 0
    no_depth = json.loads(capsys.readouterr().out.strip())
    args = ["--world", WORLD, "--base", "hop_depth=false", "--set", "branch_block_m=0"]
    assert script("compare_bounds").main([*args, "--set", "group_scales=[1.0]", "--json"]) == 0
    row = json.loads(capsys.readouterr().out.strip())
    assert row["default_m"] == no_depth["changed_m"] != no_depth["default_m"]
    assert row["changed_m"] <= row["default_m"]


def test_bad_input_is_one_clear_line(capsys, script):
    for args, needle in (
        (["--world", WORLD, "--set", "hop_cells=0"], "hop_cells must be an integer"),
        (["--world", WORLD, "--set", "nope=1"], "unknown bound parameter 'nope'"),
        (
            ["--world", WORLD, "--base", "x", "--set", "hop_depth=0"],
            "--base wants KEY=VALUE, got 'x'",
        ),
        (["--world", WORLD, "--set", "threads=2"], "unknown bound parameter 'threads'"),
        (["--world", WORLD, "--set", "hop_depth"], "--set wants KEY=VALUE, got 'hop_depth'"),
        (["--world", WORLD], "give at least one --set"),
        (["--world", WORLD, "--set", "hop_depth=0", "--rounds", "0"], "--rounds must be"),
        (["--world", "maze:seed=3,size_m=-4", "--set", "hop_depth=false"], "size_m"),
    ):
        assert script("compare_bounds").main(args) == 2, args
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and needle in err[0], (args, err)
