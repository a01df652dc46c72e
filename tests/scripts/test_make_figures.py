"""scripts/make_figures.py: the one way the committed figures in docs/figures/ change."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

REPO = Path(__file__).resolve().parents[2]


def test_every_figure_is_committed_and_shown_by_a_page(script: Any) -> None:
    pages = " ".join(p.read_text(encoding="utf-8") for p in (REPO / "docs").glob("*.md"))
    for name in script("make_figures").FIGURES:
        assert (REPO / "docs" / "figures" / name).is_file(), name
        assert f"figures/{name}" in pages, name


def test_list_prints_each_command_writing_into_the_out_dir(tmp_path, capsys, script: Any) -> None:
    mod = script("make_figures")
    assert mod.main(["--list", "--out-dir", str(tmp_path)]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert [line.split(":", 1)[0] for line in lines] == list(mod.FIGURES)
    for name in mod.FIGURES:
        argv = mod.command_for(name, tmp_path)
        assert str(tmp_path / name) in argv and not any("{" in a for a in argv)
    assert not list(tmp_path.iterdir())  # --list runs nothing


def test_an_unknown_figure_is_one_error(capsys, script: Any) -> None:
    with pytest.raises(SystemExit) as info:
        script("make_figures").main(["--only", "nope.gif"])
    assert info.value.code == 2
    assert "unknown figure(s) ['nope.gif']" in capsys.readouterr().err


def test_the_team_figure_is_drawn_in_this_process(tmp_path, monkeypatch, script: Any) -> None:
    pytest.importorskip("pettingzoo")
    mod = script("make_figures")
    calls: list[list[str]] = []
    import semexplore_gym.cli as cli

    monkeypatch.setattr(cli, "main", lambda argv: calls.append(argv) or 0)
    assert mod.main(["--only", "team_office.gif", "--out-dir", str(tmp_path)]) == 0
    assert calls == [mod.command_for("team_office.gif", tmp_path)[1:]]
