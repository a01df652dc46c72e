"""Policy specs in the README and the docs stay short and current: no spec with more than two
overrides (an older expert is named by its version, ``semantic-v2``, not by a list of
switches), and none that sets a switch the expert's params no longer have."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from semexplore_gym.policies.expert.params import REMOVED_SWITCHES

REPO = Path(__file__).resolve().parents[2]
PAGES = [REPO / "README.md", *sorted((REPO / "docs").glob("*.md"))]
#: A policy name (the expert's versions, the baselines, the learned agents, team policies)
#: followed by a bracket with at least one ``key=value`` item.
SPEC = re.compile(
    r"(?<![\w.\-/])((?:semantic|frontier|nearest|random|oracle|team)[\w\-]*)\[([^\]\n]*=[^\]\n]*)\]"
)
MAX_OVERRIDES = 2
#: A ``--policy-set key=value`` flag (the CLI's per-key override).
POLICY_SET = re.compile(r"--policy-set[ =]'?\"?([\w.]+)=")


def specs_in(text: str) -> list[tuple[str, list[str]]]:
    """The policy specs with overrides in ``text``: ``(spec, [key, ...])`` each."""
    out = []
    for m in SPEC.finditer(text):
        items = [t.strip() for t in re.split(r"[;,]", m.group(2)) if t.strip()]
        keys = [t.split("=", 1)[0].strip() for t in items if "=" in t]
        out.append((m.group(0), keys))
    return out


def test_the_scanner_finds_specs_and_their_keys() -> None:
    text = "run `semantic[cost.w_v=0;cost.w_p=0]` and frontier-student[expert.grid_candidate=true]"
    assert specs_in(text) == [
        ("semantic[cost.w_v=0;cost.w_p=0]", ["cost.w_v", "cost.w_p"]),
        ("frontier-student[expert.grid_candidate=true]", ["expert.grid_candidate"]),
    ]
    assert specs_in("a list[int] = x; semantic[tuned]") == []
    assert POLICY_SET.findall("--policy-set grid_candidate=false --policy-set 'cost.w_v=2'") == [
        "grid_candidate",
        "cost.w_v",
    ]


@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.name)
def test_no_spec_has_more_than_two_overrides_or_a_removed_key(page: Path) -> None:
    bad = []
    for spec, keys in specs_in(page.read_text(encoding="utf-8")):
        if len(keys) > MAX_OVERRIDES:
            bad.append(f"{spec} ({len(keys)} overrides; name a version instead)")
        gone = [k for k in keys if k.rsplit(".", 1)[-1] in REMOVED_SWITCHES]
        if gone:
            bad.append(f"{spec} (removed: {', '.join(gone)})")
    for key in POLICY_SET.findall(page.read_text(encoding="utf-8")):
        if key.rsplit(".", 1)[-1] in REMOVED_SWITCHES:
            bad.append(f"--policy-set {key}=... (removed)")
    assert not bad, f"{page.name}: " + "; ".join(bad)
