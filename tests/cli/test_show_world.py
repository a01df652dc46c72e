"""``semexplore show-world`` writes a picture of a world."""

from __future__ import annotations

import json

import numpy as np
from PIL import Image

from semexplore_gym.cli import main


def test_show_world_writes_png_and_json(tmp_path, capsys) -> None:
    out = tmp_path / "maze1.png"
    assert main(["show-world", "maze1", "--out", str(out), "--json"]) == 0
    facts = json.loads(capsys.readouterr().out)
    assert facts["world"] == "maze1" and facts["n_segments"] > 10
    assert 6.5 <= facts["size_m"][0] <= 8.0
    img = np.asarray(Image.open(out))
    assert img.ndim == 3 and img.shape[0] > 100
    assert (img == 255).all(axis=2).sum() > 1000, "free space must be drawn white"


def test_show_world_unknown_world_is_a_clear_error(tmp_path, capsys) -> None:
    assert main(["show-world", "atlantis", "--out", str(tmp_path / "x.png")]) == 2
    assert "atlantis" in capsys.readouterr().err
