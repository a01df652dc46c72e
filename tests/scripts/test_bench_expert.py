"""scripts/bench_expert.py through its command line: the map observation option."""

from __future__ import annotations

import json
import runpy
from pathlib import Path

import pytest

SCRIPT = Path(__file__).resolve().parents[2] / "scripts" / "bench_expert.py"
_TIMED = (
    "wall_time_s",
    "cpu_time_s",
    "speedup",
    "cpu_speedup",
    "stage_time_s",
    "mean_map_generation_ms",
    "mean_global_planning_ms",
)


def _missions(capsys, *options: str) -> list[dict]:
    main = runpy.run_path(str(SCRIPT), run_name="bench")["main"]
    argv = ["--world", "maze1", "--max-time-s", "40", "--seeds", "0", "1", "--json", *options]
    assert main(argv) == 0
    rows = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    return [{k: v for k, v in r.items() if k not in _TIMED} for r in rows]


def test_copied_and_shared_map_give_the_same_missions(capsys) -> None:
    copied = _missions(capsys, "--map-observation", "copy", "--no-warmup")
    shared = _missions(capsys, "--map-observation", "shared", "--no-warmup")
    default = _missions(capsys)  # auto: the expert gets the shared map
    assert len(copied) == 2 and copied[0]["steps"] == 200
    assert shared == copied and default == copied


def test_unknown_map_observation_is_refused(capsys) -> None:
    main = runpy.run_path(str(SCRIPT), run_name="bench")["main"]
    with pytest.raises(SystemExit) as e:
        main(["--map-observation", "live"])
    assert e.value.code == 2
    assert "invalid choice: 'live'" in capsys.readouterr().err
