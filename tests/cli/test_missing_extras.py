"""A missing optional extra: one ``error:`` line naming the extra and its pip command, exit 2.

The extras are installed here, so the tests hide their modules (``sys.modules[name] = None``
makes ``import name`` fail as if it were not installed); ``scripts/smoke_wheel.sh`` runs the same
commands in a venv that has only the core dependencies.
"""

from __future__ import annotations

import sys

import pytest

from semexplore_gym.cli import main
from semexplore_gym.config.extras import MissingExtraError, require_extra

RL = ("torch", "stable_baselines3", "sb3_contrib", "optuna")


def hide(monkeypatch: pytest.MonkeyPatch, *modules: str) -> None:
    """Make ``import m`` fail with ModuleNotFoundError for each of ``modules``."""
    for name in modules:
        monkeypatch.setitem(sys.modules, name, None)


def one_extra_line(err: str, extra: str) -> str:
    lines = [line for line in err.splitlines() if line.strip()]
    assert len(lines) == 1, err
    assert f"needs the {extra!r} extra" in lines[0], lines[0]
    assert f"pip install 'semexplore-gym[{extra}]'" in lines[0], lines[0]
    assert "Traceback" not in err
    return lines[0]


@pytest.mark.parametrize(
    ("argv", "hidden", "extra"),
    [
        (["explore", "--world", "maze1", "--policy", "pretrained:dagger_maze"], RL, "rl"),
        (["explore", "--world", "maze1", "--policy", "sb3:x.zip"], RL, "rl"),
        (["explore", "--world", "maze1", "--robots", "2"], ("pettingzoo",), "multi"),
        (["benchmark", "--policies", "pretrained:frontier_choice_maze"], RL, "rl"),
        (["benchmark", "--policies", "semantic", "--backend", "ray"], ("ray",), "ray"),
        (["compare-weights", "--train-worlds", "maze1", "--test-worlds", "maze2"], RL, "rl"),
        (["train", "--algo", "bc"], RL, "rl"),
    ],
    ids=["pretrained", "sb3", "robots", "benchmark-pretrained", "ray", "compare-weights", "train"],
)
def test_a_missing_extra_is_one_line_and_exit_2(argv, hidden, extra, monkeypatch, tmp_path, capsys):
    hide(monkeypatch, *hidden)
    # The multi-robot env checks for PettingZoo when its module is first imported.
    monkeypatch.delitem(sys.modules, "semexplore_gym.envs.multi_robot", raising=False)
    monkeypatch.chdir(tmp_path)
    if argv[0] in ("benchmark", "compare-weights", "train"):
        argv = [*argv, "--out", str(tmp_path / "out")]
    if argv[0] in ("explore", "benchmark", "compare-weights"):
        argv = [*argv, "--no-progress"]
    if argv[0] == "benchmark":
        argv = [*argv, "--worlds", "maze1", "--runs", "1", "--max-time-s", "1"]
    code = main(argv)
    assert code == 2
    one_extra_line(capsys.readouterr().err, extra)


def test_make_policy_raises_the_extra_error(monkeypatch):
    from semexplore_gym.policies.registry import make_policy

    hide(monkeypatch, *RL)
    with pytest.raises(MissingExtraError) as info:
        make_policy("pretrained:dagger_maze")
    assert info.value.extra == "rl"
    assert "pip install 'semexplore-gym[rl]'" in str(info.value)
    assert isinstance(info.value, ImportError)  # existing `except ImportError` still catch it


def test_require_extra_passes_when_installed_and_names_the_missing_module(monkeypatch):
    require_extra("rl", "x", "json")  # present: nothing happens
    hide(monkeypatch, "torch")
    with pytest.raises(MissingExtraError, match="no module named 'torch'"):
        require_extra("rl", "x", "json", "torch")
