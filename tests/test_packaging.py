"""The distribution as users install it: the wheel's contents, the shipped configs found from any
directory, the public API at the top of the package, the version.

``scripts/smoke_wheel.sh`` (run by ``.ci/run``) installs the wheel in a fresh venv and runs the
commands from outside the repository; these tests check the parts that need no install.
"""

from __future__ import annotations

import importlib
import re
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

import semexplore_gym
from semexplore_gym.cli import main
from semexplore_gym.config.resources import configs_dir, resolve_config_path, shipped_configs

REPO = Path(__file__).resolve().parents[1]


def _pyproject_version() -> str:
    text = (REPO / "pyproject.toml").read_text()
    return re.search(r'^version = "([^"]+)"', text, re.M).group(1)  # type: ignore[union-attr]


# ------------------------------------------------------------------------------------ version
VERSION = "0.3.0"


def test_version_is_one_number_everywhere(capsys: pytest.CaptureFixture[str]) -> None:
    assert semexplore_gym.__version__ == _pyproject_version() == VERSION
    with pytest.raises(SystemExit) as exc:
        main(["--version"])
    assert exc.value.code == 0
    assert capsys.readouterr().out.strip() == f"semexplore {VERSION}"


def test_the_changelog_has_the_release_under_the_unreleased_section() -> None:
    changelog = (REPO / "CHANGELOG.md").read_text()
    headings = re.findall(r"^## .*$", changelog, re.M)
    assert headings[:3] == [
        "## [Unreleased]",
        f"## [{VERSION}] - 2026-12-04",
        "## [0.2.0] - 2026-11-27",
    ]
    # Nothing above the first heading but the preamble: every entry is in a section.
    assert not re.search(r"^### ", changelog.split("## [Unreleased]", 1)[0], re.M)


def test_the_licence_file_is_mit_and_declared() -> None:
    text = (REPO / "LICENSE").read_text()
    assert (
        text.startswith("MIT License") and "Copyright (c) 2026 SemanticExplore developers" in text
    )
    pyproject = (REPO / "pyproject.toml").read_text()
    assert re.search(r'^license = "MIT"$', pyproject, re.M)
    assert re.search(r'^license-files = \["LICENSE"\]$', pyproject, re.M)


def test_the_command_runs_as_a_module() -> None:
    out = subprocess.run(
        [sys.executable, "-m", "semexplore_gym.cli", "--version"],
        capture_output=True,
        text=True,
        cwd=REPO,
        timeout=120,
    )
    assert out.returncode == 0 and out.stdout.strip() == f"semexplore {VERSION}", out.stderr


# -------------------------------------------------------------------------------------- wheel
@pytest.fixture(scope="module")
def wheel_build(tmp_path_factory: pytest.TempPathFactory) -> tuple[zipfile.ZipFile, str]:
    """The wheel, built from a copy of the sources (the checkout gets no build/ folder), and the
    build's verbose output."""
    src = tmp_path_factory.mktemp("src")
    skip = shutil.ignore_patterns("__pycache__", "*.pyc", "*.egg-info")
    for name in ("semexplore_gym", "policies", "configs"):
        shutil.copytree(REPO / name, src / name, ignore=skip)
    for name in ("setup.py", "pyproject.toml", "README.md", "LICENSE"):
        shutil.copy(REPO / name, src / name)
    dist = tmp_path_factory.mktemp("dist")
    cmd = [sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation", "-v"]
    out = subprocess.run(
        [*cmd, "-w", str(dist), str(src)], capture_output=True, text=True, timeout=600
    )
    if out.returncode != 0 and "No module named" in out.stderr:
        pytest.skip(f"cannot build a wheel here: {out.stderr.strip()[-300:]}")
    assert out.returncode == 0, out.stderr[-2000:]
    (path,) = dist.glob("semexplore_gym-*.whl")
    return zipfile.ZipFile(path), out.stdout + out.stderr


@pytest.fixture(scope="module")
def wheel(wheel_build: tuple[zipfile.ZipFile, str]) -> zipfile.ZipFile:
    return wheel_build[0]


def test_the_wheel_build_is_quiet_about_the_data_folders(
    wheel_build: tuple[zipfile.ZipFile, str],
) -> None:
    """configs/ and policies/pretrained/ folders are declared, so setuptools does not print its
    forty-line "Package would be ignored" notice for each of them."""
    log = wheel_build[1]
    assert "running build_py" in log  # the verbose output of setuptools is there
    assert "would be ignored" not in log and "absent from the `packages`" not in log, log[-3000:]


def test_the_wheel_installs_one_top_level_package(wheel: zipfile.ZipFile) -> None:
    tops = {n.split("/")[0] for n in wheel.namelist()}
    assert {t for t in tops if not t.endswith(".dist-info")} == {"semexplore_gym"}
    assert "semexplore_gym/policies/registry.py" in wheel.namelist()
    assert not any(n.startswith("policies/") for n in wheel.namelist())


def test_the_wheel_carries_every_config_and_pretrained_model(wheel: zipfile.ZipFile) -> None:
    names = set(wheel.namelist())
    configs = [
        p.relative_to(REPO).as_posix()
        for pattern in ("*.y*ml", "*.csv")
        for p in (REPO / "configs").rglob(pattern)
    ]
    assert len(configs) >= 10
    missing = [c for c in configs if f"semexplore_gym/{c}" not in names]
    assert not missing, f"configs not in the wheel: {missing}"
    for f in (REPO / "policies" / "pretrained").rglob("*"):
        if f.is_file() and "__pycache__" not in f.parts:
            rel = f.relative_to(REPO).as_posix()
            assert f"semexplore_gym/{rel}" in names, rel
    meta = wheel.read(next(n for n in names if n.endswith(".dist-info/METADATA"))).decode()
    assert f"Version: {VERSION}" in meta and "moviepy" in meta  # RecordVideo: the render extra


def test_the_wheel_carries_the_licence(wheel: zipfile.ZipFile) -> None:
    names = wheel.namelist()
    licence = [n for n in names if n.endswith(".dist-info/licenses/LICENSE")]
    assert licence, [n for n in names if ".dist-info/" in n]
    assert wheel.read(licence[0]) == (REPO / "LICENSE").read_bytes()
    meta = wheel.read(next(n for n in names if n.endswith(".dist-info/METADATA"))).decode()
    assert "License-Expression: MIT" in meta and "License-File: LICENSE" in meta


def test_the_old_policies_import_path_names_the_new_one() -> None:
    out = subprocess.run(
        [sys.executable, "-c", "import policies"],
        capture_output=True,
        text=True,
        cwd=REPO,  # a checkout: the folder policies/ is on sys.path
        timeout=120,
    )
    assert out.returncode != 0
    assert "ImportError" in out.stderr and "semexplore_gym.policies" in out.stderr


# ---------------------------------------------------------------------------- shipped configs
def test_configs_dir_is_the_checkouts_configs_folder() -> None:
    assert configs_dir() == REPO / "configs"
    assert "paper" in shipped_configs("suites") and "bc_maze" in shipped_configs("agents")


def test_configs_paths_resolve_to_the_shipped_files_from_any_directory(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)
    for rel in (
        "configs/suites/paper.yaml",
        "configs/expert/robust_paper_weights.yaml",
        "configs/paper.yaml",
    ):
        assert resolve_config_path(rel) == REPO / rel
    assert (
        resolve_config_path("./configs/agents/bc_maze.yml") == REPO / "configs/agents/bc_maze.yml"
    )
    # Not a shipped file, or not under configs/: the path as given, for the "not found" message.
    assert resolve_config_path("configs/suites/nope.yaml") == Path("configs/suites/nope.yaml")
    assert resolve_config_path("mine.yaml") == Path("mine.yaml")
    assert resolve_config_path("configs/../configs/paper.yaml") == Path(
        "configs/../configs/paper.yaml"
    )


def test_a_users_own_configs_folder_wins(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)
    mine = tmp_path / "configs" / "suites" / "paper.yaml"
    mine.parent.mkdir(parents=True)
    mine.write_text("name: mine\nversion: 7\nworlds: [maze1]\n")
    assert resolve_config_path("configs/suites/paper.yaml") == Path("configs/suites/paper.yaml")
    from semexplore_gym.evaluation.suites import load_suite

    assert load_suite("configs/suites/paper.yaml").name == "mine"
    assert load_suite("paper").name == "paper"  # a name is always the shipped suite


def test_every_reader_of_a_config_finds_the_shipped_one_from_elsewhere(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from semexplore_gym.policies.specs import load_policy_config

    from semexplore_gym.envs.env_config import load_env_config
    from semexplore_gym.evaluation.suites import list_suites, load_suite
    from semexplore_gym.training.train_config import load_train_config

    monkeypatch.chdir(tmp_path)
    assert {"paper", "mazes", "real"} <= set(list_suites())
    assert load_suite("paper").name == "paper"
    assert load_suite("configs/suites/mazes.yaml").name == "mazes"
    assert load_policy_config("configs/expert/paper_method.yaml").policy == "semantic-paper"
    assert load_env_config("configs/paper.yaml").robot.max_linear_speed_mps == 0.15
    assert load_train_config("configs/agents/bc_maze.yml", []).bc.epochs > 0


def test_benchmark_suite_and_policy_config_run_from_another_directory(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)
    argv = ["explore", "--world", "maze:seed=0,size_m=3", "--max-time-s", "2", "--no-progress"]
    assert main([*argv, "--policy-config", "configs/expert/paper_method.yaml", "--json"]) == 0
    argv = ["benchmark", "--suite", "paper", "--policies", "random", "--runs", "1"]
    argv += ["--max-time-s", "2", "--no-plots", "--no-progress", "--out", "bench"]
    assert main(argv) == 0
    assert (tmp_path / "bench" / "runs.csv").is_file()


# --------------------------------------------------------------------------------- public API
def test_the_public_api_resolves_from_the_top() -> None:
    from semexplore_gym import make_policy, record_expert_dataset, run_mission  # noqa: F401

    for name, module in semexplore_gym.PUBLIC_API.items():
        value = getattr(semexplore_gym, name)
        assert value is getattr(importlib.import_module(module), name), name
        assert name in semexplore_gym.__all__ and name in dir(semexplore_gym)
    with pytest.raises(AttributeError, match="no attribute 'nope'"):
        semexplore_gym.nope  # noqa: B018


def test_importing_the_package_stays_light() -> None:
    """``import semexplore_gym`` pulls in no env, policy, runner or learner: the public API is
    imported on first use."""
    code = (
        "import sys, semexplore_gym\n"
        "heavy = ['semexplore_gym.envs', 'semexplore_gym.policies', 'semexplore_gym.evaluation',"
        " 'semexplore_gym.training', 'torch', 'pymunk', 'matplotlib']\n"
        "print([m for m in heavy if m in sys.modules])\n"
        "semexplore_gym.make_world\n"
        "print('semexplore_gym.core.worlds' in sys.modules)\n"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, cwd=REPO, timeout=120
    )
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["[]", "True"]
