"""Model zips load with ``torch.load(weights_only=True)``; --help says which specs run code."""

from __future__ import annotations

import io
import json
import os
import zipfile
from pathlib import Path

import pytest

from semexplore_gym.cli import main

torch = pytest.importorskip("torch")
pytest.importorskip("stable_baselines3")


class _Payload:
    """Pickles as a call to os.system: what a malicious policy.pt could hold."""

    def __init__(self, marker: Path) -> None:
        self.marker = marker

    def __reduce__(self):  # noqa: D105
        return (os.system, (f"touch {self.marker}",))


def test_a_model_zip_that_runs_code_is_refused(tmp_path, capsys) -> None:
    from semexplore_gym.policies.sb3_model import MODEL_META_NAME, POLICY_ENTRY_NAME

    marker = tmp_path / "pwned"
    buf = io.BytesIO()
    torch.save({"data": _Payload(marker), "state_dict": {}}, buf)
    model = tmp_path / "evil.zip"
    with zipfile.ZipFile(model, "w") as z:
        z.writestr(POLICY_ENTRY_NAME, buf.getvalue())
        z.writestr(MODEL_META_NAME, json.dumps({"format": "policy"}))
    argv = ["explore", "--world", "maze1", "--policy", f"sb3:{model}", "--max-time-s", "1"]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "posix.system" in err[0] and "SEMEXPLORE_TRUST_MODEL_PICKLE" in err[0]
    assert not marker.exists()


@pytest.mark.parametrize("command", ["explore", "benchmark", "compare-weights"])
def test_help_says_model_and_py_specs_must_be_trusted(command, capsys) -> None:
    with pytest.raises(SystemExit):
        main([command, "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert "trusted sources" in text and "semantic[cost.w_" in text or command == "compare-weights"
    assert "trusted sources" in text
