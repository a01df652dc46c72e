"""scripts/bench_slam.py: the SLAM mode's wall time against the perfect map's, alternated, and
its check of the issue's limit (at most 3x)."""

from __future__ import annotations

import json

import pytest

WORLD = "maze:seed=3,size_m=4"


@pytest.mark.slow
def test_one_round_reports_the_ratio_and_checks_the_limit(script, capsys) -> None:
    pytest.importorskip("gtsam")
    bench = script("bench_slam")
    code = bench.main(["--worlds", WORLD, "--rounds", "1", "--json"])
    out = json.loads(capsys.readouterr().out)
    ratio = out["worlds"][WORLD]["ratio"]
    assert out["median_ratio"] == ratio > 0
    assert out["max_ratio"] == 3.0 and out["within_max_ratio"] == (ratio <= 3.0)
    assert code == (0 if ratio <= 3.0 else 1)  # wall times: no verdict in a unit test
    # A limit below the measured ratio fails the check with one line naming both.
    assert bench.main(["--worlds", WORLD, "--rounds", "1", "--max-ratio", "0.01"]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert err[-1].startswith("check failed: the median SLAM / perfect wall-time ratio ")
    assert err[-1].endswith("is above --max-ratio 0.01")


@pytest.mark.parametrize(
    "args, says",
    [
        (["--rounds", "0"], "--rounds must be >= 1, got 0"),
        (["--max-ratio", "0"], "--max-ratio must be > 0, got 0.0"),
        (["--worlds", " ; "], "--worlds names no world"),
    ],
)
def test_bad_arguments_are_one_line(script, capsys, args: list[str], says: str) -> None:
    with pytest.raises(SystemExit) as e:
        script("bench_slam").main(args)
    assert e.value.code == 2
    assert says in capsys.readouterr().err
