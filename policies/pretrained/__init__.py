"""Pretrained agents shipped inside the package: ``make_policy("pretrained:NAME")``.

Each model lives in its own folder here, ``<name>/model.zip`` (an SB3 model) or
``<name>/model.yaml`` (the weights of a learned frontier value, :mod:`semexplore_gym.policies.learned_frontier_value`)
beside the resolved ``config.yaml`` of the ``semexplore train`` run that produced it (a
macro-action agent reads its settings from it). ``index.yaml`` describes them: what each was trained on, the command and
config that reproduce it, and its measured results. ``semexplore pretrained`` lists them, one
short line each starting with the policy spec (``--details`` for everything else)::

    from semexplore_gym.policies.registry import make_policy
    policy = make_policy("pretrained:dagger_maze")

The SB3 models need the ``rl`` extra (torch, stable-baselines3, sb3-contrib) to load; a
``model.yaml`` needs nothing beyond the package.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

#: The folder holding the model folders and the index.
PRETRAINED_DIR = Path(__file__).resolve().parent
#: The index of the shipped models.
INDEX_PATH = PRETRAINED_DIR / "index.yaml"
#: Largest model file shipped (bytes); a test holds every model to it.
MAX_MODEL_BYTES = 5 * 1024 * 1024

_FIELDS = (
    "name",
    "summary",
    "description",
    "trained_on",
    "command",
    "config",
    "training_time",
    "results",
)
#: Fields an entry may leave out, with their default.
_OPTIONAL_FIELDS = {"expert_version": "semantic-v2", "policy": ""}


@dataclass(frozen=True)
class PretrainedModel:
    """One shipped model, as described in ``index.yaml``.

    Attributes:
        name: Its name: the policy spec is ``pretrained:<name>``.
        summary: What it is and how it did, in a few words (its line in ``semexplore pretrained``).
        description: What the agent is, in one sentence.
        trained_on: The worlds and the amount of experience it was trained on.
        command: The ``semexplore train`` command that reproduces it (from any directory: its
            ``configs/...`` path is found among the shipped configs).
        config: The training config of that command (``configs/agents/...``, shipped).
        training_time: Wall time of the training run and the machine it ran on.
        results: Its measured results on unseen worlds, and how they were measured.
        expert_version: The expert version its results were compared with: the expert of its
            time (``semantic-v2`` for the models measured before the 0.3.0 release, unless its
            entry says otherwise; :mod:`semexplore_gym.policies.expert.versions`).
        policy: The policy name that runs its model file (``option-ppo``); empty: chosen by
            the file (an SB3 zip, a frontier value or a frontier student).
    """

    name: str
    summary: str
    description: str
    trained_on: str
    command: str
    config: str
    training_time: str
    results: str
    expert_version: str = "semantic-v2"
    policy: str = ""

    @property
    def spec(self) -> str:
        """The policy spec that runs it: ``pretrained:<name>``."""
        return f"pretrained:{self.name}"

    @property
    def model_path(self) -> Path:
        """The model file: ``model.zip`` (an SB3 model; its folder also holds the run's
        ``config.yaml``), or ``model.yaml`` (the parameters of a learned frontier value,
        :mod:`semexplore_gym.policies.learned_frontier_value`) when the folder has no zip."""
        folder = PRETRAINED_DIR / self.name
        if not (folder / "model.zip").is_file() and (folder / "model.yaml").is_file():
            return folder / "model.yaml"
        return folder / "model.zip"

    def summary_line(self) -> str:
        """One short line: the spec, then the summary."""
        return f"{self.spec:<31} {self.summary}"

    def detail_lines(self) -> list[str]:
        """Every field of the index, one line each (the command kept whole, to copy)."""
        rows = [
            ("what", self.description),
            ("trained on", self.trained_on),
            ("training", self.training_time),
            ("reproduce", self.command),
            ("config", self.config),
            ("results", self.results),
            ("expert", f"compared with {self.expert_version} (the expert of its time)"),
            ("model", str(self.model_path)),
        ]
        return [self.spec] + [f"  {k + ':':<12}{v}" for k, v in rows]

    def to_dict(self) -> dict[str, Any]:
        """The index fields plus ``spec``, ``model_path`` and ``size_bytes``."""
        d: dict[str, Any] = {k: getattr(self, k) for k in (*_FIELDS, *_OPTIONAL_FIELDS)}
        size = self.model_path.stat().st_size if self.model_path.is_file() else None
        return {"spec": self.spec, **d, "model_path": str(self.model_path), "size_bytes": size}


def pretrained_models() -> list[PretrainedModel]:
    """The shipped models, in the index's order.

    Raises:
        ValueError: the index is malformed (a missing or unknown field).
    """
    from semexplore_gym.policies.expert.versions import EXPERT_VERSIONS

    from semexplore_gym.config.loading import load_yaml_file

    data = load_yaml_file(INDEX_PATH, "pretrained model index") or {}
    entries = data.get("models") if isinstance(data, dict) else None
    if not isinstance(entries, list):
        raise ValueError(f"{INDEX_PATH} must hold a 'models' list")
    models = []
    for entry in entries:
        if not isinstance(entry, dict) or not set(_FIELDS) <= set(entry) <= {
            *_FIELDS,
            *_OPTIONAL_FIELDS,
        }:
            keys = sorted(entry) if isinstance(entry, dict) else entry
            raise ValueError(
                f"{INDEX_PATH}: each model needs exactly {list(_FIELDS)} (optional: "
                f"{list(_OPTIONAL_FIELDS)}), got {keys}"
            )
        values = {**_OPTIONAL_FIELDS, **entry}
        if values["expert_version"] not in EXPERT_VERSIONS:
            raise ValueError(
                f"{INDEX_PATH}: model {entry['name']!r}: expert_version must be one of "
                f"{list(EXPERT_VERSIONS)}, got {values['expert_version']!r}"
            )
        models.append(PretrainedModel(**{k: " ".join(str(values[k]).split()) for k in values}))
    return models


def get_pretrained(name: str) -> PretrainedModel:
    """The shipped model called ``name``.

    Raises:
        ValueError: no model has that name (the message lists the names).
    """
    models = {m.name: m for m in pretrained_models()}
    if name not in models:
        known = ", ".join(f"pretrained:{n}" for n in models) or "(none)"
        shown = f"pretrained:{name}" if name else "'pretrained' without a name"
        raise ValueError(f"unknown pretrained model {shown}; shipped: {known}")
    return models[name]
