"""``semexplore segment``: drawing, JSON summary, export and errors."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import pytest

from semexplore_gym.cli import segment as seg_cli

SHARED = Path(__file__).resolve().parents[2] / ".." / "shared"


def parse(argv: list[str]) -> argparse.Namespace:
    parser = argparse.ArgumentParser()
    seg_cli.add_parser(parser.add_subparsers(dest="command"))
    return parser.parse_args(argv)


def test_segment_world_draws_and_prints_json(tmp_path, capsys):
    out = tmp_path / "seg.png"
    args = parse(["segment", "maze1", "--out", str(out), "--json"])
    assert seg_cli.run(args) == 0
    d = json.loads(capsys.readouterr().out)
    for key in ("intersections", "pathways", "dead_ends", "frontier_pathways"):
        assert isinstance(d[key], int)
    assert d["intersections"] >= 3 and d["dead_ends"] >= 1
    assert (
        d["frontier_pathways"] == 0 and d["frontiers"] == []
    )  # a fully known world has no frontier
    assert d["time_ms"] > 0
    assert (
        len(d["areas"])
        == d["intersections"] + d["pathways"] + d["dead_ends"] + d["frontier_pathways"]
    )
    for a in d["areas"]:
        assert a["type"] in ("intersection", "pathway", "dead_end", "frontier_pathway")
        if a["type"] == "intersection":
            assert len(a["openings"]) >= 3
        for o in a["openings"]:
            assert a["id"] in o["area_ids"] and o["width_m"] > 0.3
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    from PIL import Image

    assert min(Image.open(out).size) > 200


def test_segment_export_and_text_output(tmp_path, capsys):
    export = tmp_path / "map.json"
    args = parse(["segment", "maze1", "--export", str(export), "--resolution", "0.05"])
    assert seg_cli.run(args) == 0
    line = capsys.readouterr().out
    assert "intersections" in line and "ms" in line
    d = json.loads(export.read_text())
    assert d["format"] == "semexplore-topometric/1"
    assert {"opening_graph", "area_graph", "areas", "openings", "frontiers"} <= set(d)


def test_segment_through_the_main_dispatcher_reports_errors(tmp_path, capsys):
    from semexplore_gym.cli import main

    assert main(["segment", str(tmp_path / "missing.yaml")]) == 2
    assert "missing.yaml" in capsys.readouterr().err
    assert main(["segment", "no_such_world_name"]) == 2
    assert main(["segment", "maze1", "--resolution", "-1"]) == 2
    assert "resolution" in capsys.readouterr().err


def test_segment_ros_map(tmp_path, capsys):
    path = SHARED / "maps" / "turtlebot3" / "world" / "map.yaml"
    if not path.is_file():
        pytest.skip(f"shared maps not found at {path.parent} (../shared beside the repository)")
    args = parse(["segment", str(path), "--json", "--out", str(tmp_path / "tb3.png")])
    assert seg_cli.run(args) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["intersections"] >= 1  # the arena around the pillars
    assert (tmp_path / "tb3.png").stat().st_size > 1000


def test_time_ms_excludes_kernel_loading(capsys, monkeypatch):
    # The CLI segments a tiny grid first, so the reported time is the map's own segmentation.
    from semexplore_gym.core import topometric

    calls = []
    real = topometric.segment_map

    def spy(grid, *a, **k):
        calls.append(getattr(grid, "shape", None))
        return real(grid, *a, **k)

    monkeypatch.setattr(topometric, "segment_map", spy)
    assert seg_cli.run(parse(["segment", "maze1", "--json"])) == 0
    assert calls[0] == (8, 8) and len(calls) == 2 and calls[1][0] > 100
    assert json.loads(capsys.readouterr().out)["time_ms"] > 0


def test_closed_pipe_ends_quietly(monkeypatch):
    # `semexplore segment ... --json | head`: the reader goes away; exit 0, no traceback.
    import semexplore_gym.cli as cli

    redirected = []

    def broken(args):
        raise BrokenPipeError(32, "Broken pipe")

    monkeypatch.setattr(seg_cli, "run", broken)
    monkeypatch.setattr(cli.os, "dup2", lambda a, b: redirected.append(b))
    assert cli.main(["segment", "maze1", "--json"]) == 0
    assert len(redirected) == 1
