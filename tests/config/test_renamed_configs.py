"""The expert configs renamed to say what they hold: the old names load the new files for one
release, with a FutureWarning naming the new file once per process."""

from __future__ import annotations

import warnings
from pathlib import Path

import pytest
from semexplore_gym.policies.specs import load_policy_config

from semexplore_gym.config import resources
from semexplore_gym.config.resources import RENAMED_EXPERT_CONFIGS, resolve_config_path

REPO = Path(__file__).resolve().parents[2]


@pytest.fixture(autouse=True)
def _fresh_warnings():
    resources._warn_renamed.cache_clear()
    yield
    resources._warn_renamed.cache_clear()


def test_the_new_names_are_shipped_and_the_old_ones_are_gone() -> None:
    for old, new in RENAMED_EXPERT_CONFIGS.items():
        assert (REPO / "configs" / "expert" / new).is_file()
        assert not (REPO / "configs" / "expert" / old).exists()


@pytest.mark.parametrize(("old", "new"), sorted(RENAMED_EXPERT_CONFIGS.items()))
def test_an_old_name_loads_the_new_file_and_warns_once(
    old: str, new: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        first = resolve_config_path(f"configs/expert/{old}")
        second = resolve_config_path(f"configs/expert/{old}")
    assert first == second == REPO / "configs" / "expert" / new
    assert len(caught) == 1
    assert caught[0].category is FutureWarning
    assert f"configs/expert/{new}" in str(caught[0].message)


def test_the_old_paper_pure_name_still_gives_the_paper_method() -> None:
    with pytest.warns(FutureWarning, match="paper_method.yaml"):
        old = load_policy_config("configs/expert/paper_pure.yaml")
    assert old == load_policy_config("configs/expert/paper_method.yaml")


def test_other_names_do_not_warn(recwarn: pytest.WarningsRecorder) -> None:
    resolve_config_path("configs/expert/paper_method.yaml")
    resolve_config_path("configs/suites/paper.yaml")  # a suite named paper: not renamed
    resolve_config_path("configs/paper.yaml")  # the env preset: not renamed
    assert not [w for w in recwarn if w.category is FutureWarning]
