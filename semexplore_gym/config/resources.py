"""The configuration files shipped with the package: env presets, expert parameters, agent
training configs and benchmark suites.

The repository keeps them in ``configs/`` at its top level; the wheel installs the same tree as
``semexplore_gym/configs`` (``setup.py`` maps the folder, as it maps ``policies/``).
:func:`configs_dir` finds whichever of the two is there, through :mod:`importlib.resources`,
and :func:`resolve_config_path` is the one lookup every reader of a config file goes through,
so that a command written with ``configs/...`` (the docs, the reproduce lines of
``semexplore pretrained``) runs from any directory of a plain ``pip install``::

    resolve_config_path("configs/agents/bc_maze.yml")   # ./configs/... if it exists, else shipped
    resolve_config_path("my_run.yml")                   # a user's path, unchanged
"""

from __future__ import annotations

import functools
import importlib.resources
import os
import warnings
from pathlib import Path

#: The first component of a path that names a shipped config file.
CONFIGS_PREFIX = "configs"

#: Shipped expert configs renamed to say what they hold: old file name -> new one. The old
#: names still load, with a warning, for one release.
RENAMED_EXPERT_CONFIGS: dict[str, str] = {
    "paper.yaml": "robust_paper_weights.yaml",
    "paper_pure.yaml": "paper_method.yaml",
}


def configs_dir() -> Path:
    """The folder of the shipped configs: ``semexplore_gym/configs`` in an installed wheel,
    the repository's top-level ``configs/`` in a source checkout (or an editable install)."""
    packaged = importlib.resources.files("semexplore_gym").joinpath(CONFIGS_PREFIX)
    if packaged.is_dir():
        # pip installs unpacked, so the traversable is a real directory
        return Path(os.fspath(packaged))  # type: ignore[call-overload]
    return Path(__file__).resolve().parents[2] / CONFIGS_PREFIX


def resolve_config_path(path: str | os.PathLike) -> Path:
    """The file a config path stands for.

    A path that exists is the user's and wins. A relative path starting ``configs/`` that does
    not exist here is looked up among the shipped configs (so ``configs/suites/paper.yaml``
    works from any directory). Anything else comes back unchanged, for the caller's
    "not found" message.
    """
    p = Path(path)
    if p.exists():
        return p
    p = _renamed_expert_config(p)
    if p.exists() or p.is_absolute():
        return p
    parts = p.parts
    if len(parts) > 1 and parts[0] == CONFIGS_PREFIX and ".." not in parts:
        shipped = configs_dir().joinpath(*parts[1:])
        if shipped.is_file():
            return shipped
    return p


def _renamed_expert_config(p: Path) -> Path:
    """``p`` under its new name when it names a renamed expert config, else ``p``."""
    new = RENAMED_EXPERT_CONFIGS.get(p.name)
    if new is None or p.parent.name != "expert":
        return p
    _warn_renamed(p.as_posix(), p.with_name(new).as_posix())
    return p.with_name(new)


@functools.cache
def _warn_renamed(old: str, new: str) -> None:
    """A FutureWarning, once per process and old path, that ``old`` is now ``new``."""
    warnings.warn(
        f"{old} was renamed {new}; the old name stops working in the next release",
        FutureWarning,
        stacklevel=2,
    )


def shipped_configs(kind: str) -> list[str]:
    """Names (file stems) of the shipped configs of one kind: ``suites``, ``agents``,
    ``expert``."""
    d = configs_dir() / kind
    if not d.is_dir():
        return []
    return sorted(f.stem for f in d.iterdir() if f.suffix in (".yaml", ".yml"))
