"""Learning splits: the shipped files are disjoint, stable and keep the rule; a split part runs
through ``semexplore benchmark --split`` and prints the learning table."""

from __future__ import annotations

import hashlib
import json
import re

import pytest

from semexplore_gym.cli import main
from semexplore_gym.config.resources import configs_dir
from semexplore_gym.evaluation.harness import read_runs
from semexplore_gym.evaluation.learning_table import (
    BEST_BASELINE_TITLE,
    SECTION_TITLE,
    learning_table_lines,
)
from semexplore_gym.evaluation.splits import PARTS, RULE, list_splits, load_split, split_suite
from semexplore_gym.evaluation.suites import list_suites, load_suite, world_family

FAMILIES = ("mazes", "offices", "caves", "open", "dungeon")


def _seed(world: str) -> int | None:
    m = re.search(r"seed=(\d+)", world)
    return int(m.group(1)) if m else None


def test_every_family_has_a_split_with_the_rule() -> None:
    assert set(FAMILIES) <= set(list_splits())
    for name in FAMILIES:
        split = load_split(name)
        assert split.name == name and split.version >= 1
        text = (configs_dir() / "splits" / f"{name}.yaml").read_text()
        assert f"rule: {RULE}" in text and "THE RULE: no test world is ever used" in text
        # One family per split, or the families of its suite (caves: cave and noisecave).
        families = {world_family(w) for p in PARTS for w in split.parts[p]}
        if name == "dungeon":
            assert families == {world_family(split.parts["test"][0])}
        else:
            assert families == {world_family(w.world) for w in load_suite(name).worlds}


def test_parts_are_disjoint_and_seeds_unused_by_any_suite() -> None:
    suite_worlds = {w.world for s in list_suites() for w in load_suite(s).worlds}
    suite_seeds = {_seed(w) for w in suite_worlds} - {None}
    seen_seeds: dict[int, str] = {}
    seen_worlds: set[str] = set()
    for name in FAMILIES:
        split = load_split(name)
        for part in PARTS:
            for w in split.parts[part]:
                assert w not in seen_worlds and w not in suite_worlds, w
                seen_worlds.add(w)
                seed = _seed(w)
                if seed is not None:
                    assert seed not in suite_seeds, w
                    assert seed not in seen_seeds, f"{w} repeats seed of {seen_seeds[seed]}"
                    seen_seeds[seed] = f"{name}:{part}"


def test_sizes_and_test_set_n() -> None:
    for name in FAMILIES:
        split = load_split(name)
        test = split.suite("test")
        assert len(test.worlds) * test.runs >= 40, name  # the paired tests' n per family
        if name != "dungeon":
            params = {re.sub(r"seed=\d+,?", "", w.world) for w in load_suite(name).worlds}
            for part in PARTS:
                assert {re.sub(r"seed=\d+,?", "", w) for w in split.parts[part]} == params
    dungeon = load_split("dungeon")
    assert dungeon.parts["test"] == tuple(f"map:dungeon-test-img-{i}" for i in range(9900, 10000))
    assert len(dungeon.parts["train"]) == 200 and len(dungeon.parts["validation"]) == 50
    assert not dungeon.suite("test").random_start  # the start marker, as in their benchmark


@pytest.mark.parametrize("name", FAMILIES)
def test_splits_are_stable(name: str) -> None:
    split = load_split(name)
    text = "\n".join(w for p in PARTS for w in split.parts[p])
    digest = hashlib.sha256(text.encode()).hexdigest()
    assert (split.version, digest) == STABLE[name], f"split {name} changed: bump its version"


#: (version, sha256 of the split's worlds "\n"-joined in part order): a changed world must
#: bump the version, and this pin with it.
STABLE = {
    "mazes": (1, "7b5c431296336929ce7f7fe2013a04c3c8c7a67de9165cfb3a65aa2670cdd055"),
    "offices": (1, "05d695e6ce885528f645ca0c8f41a5f3c55312cdbb143192463696cc98e46552"),
    "caves": (1, "87d95797c4dc08c6ab08801ef949329760a83320a39224be0e0cd3f3ef52d87d"),
    "open": (1, "b3ee4ba5982c09d723a36b378403b6ed679d098261d8c518774375efca7306c8"),
    "dungeon": (1, "b1b9df2ba2f308a757e06cdf41e97650b7165a1c878d6b26531fbc4b9e0c519c"),
}


def test_split_suite_names_and_errors() -> None:
    suite = split_suite("mazes:test")
    assert suite.name == "mazes-test" and suite.runs == 2 and len(suite.worlds) == 24
    with pytest.raises(ValueError, match="NAME:PART"):
        split_suite("mazes")
    with pytest.raises(ValueError, match="no part 'tset'"):
        split_suite("mazes:tset")
    with pytest.raises(FileNotFoundError, match="known splits: .*dungeon"):
        split_suite("atlantis:test")


TINY_SPLIT = f"""\
name: tiny
version: 1
rule: {RULE}
runs: 1
random_start: true
max_time_s: 60
train:
- maze:seed=90001,size_m=4
validation:
- maze:seed=90002,size_m=4
test:
- maze:seed=90003,size_m=4
"""


def test_a_split_part_runs_through_benchmark_with_the_learning_table(tmp_path, capsys) -> None:
    split = tmp_path / "tiny.yaml"
    split.write_text(TINY_SPLIT)
    out = tmp_path / "run"
    argv = ["benchmark", "--split", f"{split}:test", "--policies", "semantic,nearest"]
    argv += ["--out", str(out), "--no-plots", "--no-progress"]
    assert main(argv) == 0
    printed = capsys.readouterr().out
    assert printed.splitlines()[0].split() == ["ran", "3"]  # the oracle is on by default
    rows = read_runs(out / "runs.csv")
    assert {r["world"] for r in rows} == {"maze:seed=90003,size_m=4"}
    assert {r["policy"] for r in rows} == {"semantic", "nearest", "oracle"}
    summary = (out / "summary.md").read_text()
    assert "Suites: `tiny-test` v1" in summary and SECTION_TITLE in summary
    table = summary[summary.index(SECTION_TITLE) : summary.index(BEST_BASELINE_TITLE)]
    body = [line for line in table.splitlines() if line.startswith("| maze |")]
    assert [line.split("|")[2].strip() for line in body] == ["oracle", "semantic", "nearest"]
    against = summary[summary.index(BEST_BASELINE_TITLE) :].splitlines()
    against = [line.split("|")[2:4] for line in against if line.startswith("| maze |")]
    assert [[c.strip() for c in cells] for cells in against] == [
        ["oracle", "nearest"],
        ["semantic", "nearest"],
    ]
    assert SECTION_TITLE in printed and (out / "regret.csv").is_file()
    d99 = {line.split("|")[2].strip(): line.split("|")[7].strip() for line in body}
    assert all(v == "∞" or float(v) > 0 for v in d99.values()) and d99["oracle"] != "∞", d99
    assert json.loads((out / "benchmark.json").read_text())["splits"] == [f"{split}:test"]
    # resumes
    assert main([*argv, "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["skipped"] == 3
    # a bad part names the flag
    assert main([*argv[:2], f"{split}:tset", *argv[3:]]) == 2
    assert "--split" in capsys.readouterr().err


def test_learning_table_ratios_and_infinite_t99() -> None:
    def row(policy: str, seed: int, t99: float | None, time_s: float) -> dict:
        return {"world": "maze:seed=1", "policy": policy, "seed": seed, "coverage": 0.99,
                "T99_s": t99, "mission_time_s": time_s}  # fmt: skip

    rows = [row("oracle", s, 50.0, 50.0) for s in range(3)]
    rows += [row("semantic", s, 100.0, 100.0) for s in range(3)]
    rows += [row("mine", 0, 80.0, 80.0), row("mine", 1, 80.0, 80.0), row("mine", 2, None, 90.0)]
    lines = [line for line in learning_table_lines(rows) if line.startswith("| maze |")]
    cells = {
        line.split("|")[2].strip(): [c.strip() for c in line.split("|")[3:-1]] for line in lines
    }
    # n, coverage, T99, time, D99, T99/expert, time/expert, T99/oracle, time/oracle, p, p
    assert cells["semantic"][5:9] == ["–", "–", "2.00", "2.00"]
    assert cells["mine"][:2] == ["3", "0.990"]
    assert cells["mine"][5:9] == ["0.80", "0.80", "1.60", "1.60"]
    assert cells["mine"][2] == "80.0"  # median of 80, 80, ∞
    assert cells["mine"][4] == "–"  # no benchmark directory: no D99
    assert cells["oracle"][5] == "0.50"


def test_the_best_baseline_is_the_faster_one_per_family_and_pairs_every_policy() -> None:
    def row(world: str, policy: str, seed: int, t99: float | None, time_s: float) -> dict:
        return {"world": world, "policy": policy, "seed": seed, "coverage": 0.99,
                "T99_s": t99, "mission_time_s": time_s}  # fmt: skip

    maze, office = "maze:seed=1", "office:seed=1"
    rows = [row(maze, "semantic", s, 100.0, 100.0) for s in range(3)]
    rows += [row(maze, "nearest", s, 120.0, 125.0) for s in range(3)]
    rows += [row(maze, "frontier", s, 200.0, 150.0) for s in range(3)]  # slower: not the bar
    rows += [row(maze, "mine", s, 60.0, 100.0) for s in range(3)]
    rows += [row(office, "semantic", 0, 100.0, 100.0), row(office, "frontier", 0, 80.0, 90.0)]
    rows += [row(office, "nearest", 0, 85.0, 80.0)]  # FE reaches 99 % sooner here
    rows += [row(office, "semantic", 1, 100.0, 100.0), row(office, "frontier", 1, 80.0, 90.0)]
    rows += [row(office, "nearest", 1, 85.0, 80.0)]
    lines = learning_table_lines(rows)
    against = lines[lines.index(BEST_BASELINE_TITLE) :]
    cells = {
        tuple(c.strip() for c in line.split("|")[1:4]): [c.strip() for c in line.split("|")[4:-1]]
        for line in against
        if line.startswith(("| maze |", "| office |"))
    }
    assert cells[("maze", "mine", "nearest")][:3] == ["3", "0.50", "0.80"]
    assert cells[("maze", "semantic", "nearest")][1:3] == ["0.83", "0.80"]
    assert cells[("maze", "frontier", "nearest")][1:3] == ["1.67", "1.20"]
    assert ("maze", "nearest", "nearest") not in cells
    assert cells[("office", "nearest", "frontier")][1:3] == ["1.06", "0.89"]
    # a baseline that stops early without reaching 99 % is not the faster one
    quits = [
        {**r, "T99_s": None, "mission_time_s": 10.0} if r["policy"] == "frontier" else r
        for r in rows
    ]
    against = learning_table_lines(quits)
    assert any(line.startswith("| office | frontier | nearest |") for line in against)
    # without a baseline there is no second table
    no_base = [r for r in rows if r["policy"] not in ("nearest", "frontier")]
    assert BEST_BASELINE_TITLE not in learning_table_lines(no_base)
