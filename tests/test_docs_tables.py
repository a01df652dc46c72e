"""The user guide's result tables are computed from their data when the docs are built
(``docs/_ext/generated_tables.py``), by the function behind ``semexplore report``."""

from __future__ import annotations

import csv
import importlib.util
import re
from pathlib import Path

from semexplore_gym.cli import main
from semexplore_gym.evaluation.suites import world_family

DOCS = Path(__file__).resolve().parents[1] / "docs"
INCLUDE = re.compile(r"^```\{include\}\s+_generated/(\S+)\.md\s*$", re.M)


def _extension():
    spec = importlib.util.spec_from_file_location(
        "generated_tables", DOCS / "_ext/generated_tables.py"
    )
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _included() -> dict[str, list[str]]:
    """``{generated table: [pages that include it]}`` over the site's pages."""
    found: dict[str, list[str]] = {}
    for page in sorted(DOCS.glob("*.md")):
        for name in INCLUDE.findall(page.read_text(encoding="utf-8")):
            found.setdefault(name, []).append(page.name)
    return found


def test_the_build_step_writes_every_included_table(tmp_path: Path) -> None:
    written = _extension().write_tables(DOCS, tmp_path)
    included = _included()
    assert {
        "suites_overview",
        "best_known",
        "slam_vs_perfect",
        "learners_vs_expert",
        "teams_mazes",
    } <= set(included)
    assert set(included) == set(written), "a page includes a table no step makes, or vice versa"
    for name, path in written.items():
        text = path.read_text(encoding="utf-8")
        assert text.count("\n|") >= 3, f"{name}: no table"
        assert "*Computed when the docs are built from `" in text


def test_the_benchmark_table_has_each_family_and_policy_of_its_runs(tmp_path: Path) -> None:
    ext = _extension()
    text = ext.write_tables(DOCS, tmp_path)["suites_overview"].read_text(encoding="utf-8")
    source = DOCS / ext.TABLES["suites_overview"][0]
    with source.open(newline="") as f:
        runs = list(csv.DictReader(f))
    for family in {world_family(r["world"]) for r in runs}:
        for policy in {r["policy"] for r in runs}:
            n = sum(1 for r in runs if world_family(r["world"]) == family and r["policy"] == policy)
            assert f"| {family} | {policy} | {n} | " in text, (family, policy)


def test_the_learners_table_pairs_each_policy_of_its_runs_with_the_expert(tmp_path: Path) -> None:
    ext = _extension()
    text = ext.write_tables(DOCS, tmp_path)["learners_vs_expert"].read_text(encoding="utf-8")
    with (DOCS / ext.TABLES["learners_vs_expert"][0]).open(newline="") as f:
        runs = list(csv.DictReader(f))
    assert {r["policy_version"] for r in runs if r["policy"] == "semantic"} == {"semantic-v3"}
    for family in {world_family(r["world"]) for r in runs}:
        for policy in {r["policy"] for r in runs}:
            n = sum(1 for r in runs if world_family(r["world"]) == family and r["policy"] == policy)
            assert f"| {family} | {policy} | {n} | " in text, (family, policy)
    assert "T99 ÷ semantic" in text


def test_the_best_known_table_has_each_family_of_the_shipped_table(tmp_path: Path) -> None:
    ext = _extension()
    text = ext.write_tables(DOCS, tmp_path)["best_known"].read_text(encoding="utf-8")
    with (DOCS / ext.TABLES["best_known"][0]).open(newline="") as f:
        rows = list(csv.DictReader(f))
    for family, start in {(world_family(r["world"]), r["start"]) for r in rows}:
        n = sum(1 for r in rows if world_family(r["world"]) == family and r["start"] == start)
        assert f"| {family} | {start} | {n} | " in text, (family, start)


def test_the_slam_table_pairs_each_family_and_policy_of_its_runs(tmp_path: Path) -> None:
    """The shipped file holds the pairs only: each (family, policy) row counts half its rows."""
    ext = _extension()
    text = ext.write_tables(DOCS, tmp_path)["slam_vs_perfect"].read_text(encoding="utf-8")
    with (DOCS / ext.TABLES["slam_vs_perfect"][0]).open(newline="") as f:
        runs = list(csv.DictReader(f))
    slam = [r for r in runs if r["ate_m"]]
    assert 2 * len(slam) == len(runs)
    for family in {world_family(r["world"]) for r in runs}:
        for policy in {r["policy"] for r in runs if world_family(r["world"]) == family}:
            n = sum(1 for r in slam if world_family(r["world"]) == family and r["policy"] == policy)
            assert f"| {family} | {policy} | {n} | " in text, (family, policy)
    assert "| paper mazes | SLAM | " in text  # the expert against the baselines


def test_the_team_table_has_each_policy_and_team_size_of_its_runs(tmp_path: Path) -> None:
    ext = _extension()
    text = ext.write_tables(DOCS, tmp_path)["teams_mazes"].read_text(encoding="utf-8")
    with (DOCS / ext.TABLES["teams_mazes"][0]).open(newline="") as f:
        runs = list(csv.DictReader(f))
    assert {r["policy"] for r in runs} == {"team_independent", "team_oracle"}
    assert "| T_oracle(1) / T99 | regret | T99 / bound |" in text  # the team oracle's columns
    from semexplore_gym.evaluation.suites import world_family

    sections = {}  # per family (the table's bold headings): its rows
    for family in {world_family(r["world"]) for r in runs}:
        start = text.index(f"**{family}**")
        end = text.find("\n**", start + 1)
        sections[family] = text[start : end if end >= 0 else len(text)]
    for family, policy, robots in {
        (world_family(r["world"]), r["policy"], r["n_robots"]) for r in runs
    }:
        n = sum(
            1
            for r in runs
            if world_family(r["world"]) == family
            and r["policy"] == policy
            and r["n_robots"] == robots
        )
        assert f"| {policy} | {robots} | {n} | " in sections[family], (family, policy, robots)
    oracle_rows = [ln for ln in text.splitlines() if ln.startswith("| team_oracle |")]
    assert oracle_rows and all(ln.split(" | ")[-2] == "1.00" for ln in oracle_rows)  # regret


def test_the_shipped_team_missions_never_beat_their_lower_bound() -> None:
    """teams.md says the team bound held on every shipped mission with a T99."""
    with (DOCS / "results/teams/runs.csv").open(newline="") as f:
        runs = [r for r in csv.DictReader(f) if r["T99_s"]]
    assert len(runs) >= 100
    for r in runs:
        assert 0 <= float(r["lower_bound_s"]) <= float(r["T99_s"]), r


def test_the_docs_tables_are_what_semexplore_report_prints(tmp_path: Path, capsys) -> None:
    ext = _extension()
    written = ext.write_tables(DOCS, tmp_path)
    for name, (source, table) in ext.TABLES.items():
        assert main(["report", str(DOCS / source), *(["--table", table] if table else [])]) == 0
        printed = capsys.readouterr().out
        assert written[name].read_text(encoding="utf-8").startswith(printed), name


def test_the_oracle_tables_have_each_family_of_their_runs(tmp_path: Path) -> None:
    ext = _extension()
    written = ext.write_tables(DOCS, tmp_path)
    with (DOCS / ext.TABLES["oracle_regret"][0]).open(newline="") as f:
        runs = list(csv.DictReader(f))
    regret = written["oracle_regret"].read_text(encoding="utf-8")
    for family in {world_family(r["world"]) for r in runs}:
        assert f"### {family}\n" in regret, family
    with (DOCS / ext.TABLES["lower_bound_check"][0]).open(newline="") as f:
        missions = list(csv.DictReader(f))
    check = written["lower_bound_check"].read_text(encoding="utf-8")
    for family in {world_family(r["world"]) for r in missions}:
        n = sum(1 for r in missions if world_family(r["world"]) == family)
        assert re.search(rf"^\| {family} \| \d+ \| {n} \| 0 \|", check, re.M), family
    assert f"missions: {len(missions)};" in check


def test_the_dungeon_learners_table_pairs_fixed_starts_with_the_best_known(tmp_path: Path) -> None:
    """The DungeonMaps start on their markers: the table's missions pair with the best-known
    table's fixed starts (its gap-closed and bound columns filled for every learner)."""
    ext = _extension()
    text = ext.write_tables(DOCS, tmp_path)["learners_vs_expert_dungeon"].read_text("utf-8")
    with (DOCS / ext.TABLES["learners_vs_expert_dungeon"][0]).open(newline="") as f:
        runs = list(csv.DictReader(f))
    for policy in {r["policy"] for r in runs}:
        n = sum(1 for r in runs if r["policy"] == policy)
        row = next(line for line in text.splitlines() if line.startswith(f"| dungeon | {policy} |"))
        cells = [c.strip() for c in row.strip("|").split("|")]
        assert cells[2] == str(n), policy
        assert cells[-1] == f"{cells[-1].split()[0]} ({n})" and cells[-1] != "–", policy
        if policy != "semantic":
            assert re.fullmatch(r"-?\d+\.\d\d \(\d+\)", cells[-2]), (policy, cells[-2])
