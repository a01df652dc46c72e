"""scripts/check_docs_commands.py: the docs' long reproduce commands, checked without running."""

from __future__ import annotations

from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def checker(docs_commands_checker):
    return docs_commands_checker


def _page(tmp_path: Path, *commands: str) -> Path:
    """A page with prose, then one long block holding ``commands`` (the first on line 6)."""
    page = tmp_path / "study.md"
    body = "\n".join(commands)
    page.write_text(f"# A study\n\nThe command is below.\n<!-- long -->\n```bash\n{body}\n```\n")
    return page


GOOD = (
    "semexplore benchmark --suite caves --policies 'semantic,semantic-v2[cost.w_v=2],nearest' "
    "--no-oracle --workers 2 --out runs/caves"
)


def test_a_good_block_passes(checker, tmp_path: Path) -> None:
    page = _page(
        tmp_path,
        "# about 2 h on 2 cores",
        GOOD,
        "semexplore benchmark --worlds maze1,maze:seed=*,size_m=8 --policies semantic \\",
        "    --env-config slam --env-set lidar.n_beams=180 --runs 3 --out runs/w",
        "PYTHONPATH=$PWD python scripts/robustness_sweep.py --families cave,forest "
        "--per-family 25 --policies semantic,nearest --out runs/sweep",
        "semexplore benchmark --split dungeon:test --policies "
        "'semantic,pretrained:oracle_student,sb3:runs/student/model.zip' --out runs/t",
        "semexplore explore --world map:tb3-world --policy semantic --json",
        "semexplore benchmark --worlds 'office:seed=*,size_m=20' --robots 1,2,3,4 "
        "--policies semantic,independent,greedy --runs 20 --out runs/team_study",
    )
    assert checker.check_page(page) == (6, [])


def test_a_python_c_list_feeds_a_later_command(checker, tmp_path: Path) -> None:
    page = _page(
        tmp_path,
        'W=$(python -c \'print(",".join(f"maze:seed={s},size_m=6" for s in range(3)))\')',
        'semexplore benchmark --worlds "$W" --policies semantic --out runs/w',
    )
    commands = checker.block_commands(page.read_text().split("```bash\n")[1], 6)
    assert commands[0][0] == 7
    assert commands[0][1][3].endswith(",maze:seed=2,size_m=6")
    assert checker.check_page(page) == (1, [])


@pytest.mark.parametrize(
    ("command", "says"),
    [
        (GOOD + " --bogus", "unrecognized arguments: --bogus"),
        (GOOD.replace("nearest", "nearestt"), "unknown policy 'nearestt'"),
        (
            GOOD.replace("semantic-v2[cost.w_v=2]", "semantic[vanish_on_frontier=false]"),
            "'vanish_on_frontier' was removed",
        ),
        (GOOD + " --env-config configs/no_such_env.yaml", "configs/no_such_env.yaml"),
        (GOOD.replace("caves", "cavez", 1), "unknown suite 'cavez'"),
        ("semexplore benchmark --worlds maze:sise_m=8 --out runs/x", "unknown maze parameter"),
        ("semexplore benchmark --worlds map:no-such-map --out runs/x", "unknown map"),
        ("semexplore benchmark --split mazes:exam --out runs/x", "--split 'mazes:exam'"),
        (
            "semexplore train --algo bc --train-config configs/agents/none.yaml --out runs/x",
            "--train-config",
        ),
        ("python scripts/robustness_sweep.py --families noisecaves --out runs/x", "noisecaves"),
        (
            "semexplore benchmark --worlds office:seed=*,size_m=8 --robots 1,2 "
            "--policies semantic,greedyy --out runs/x",
            "unknown team policy 'greedyy'",
        ),
        ("python scripts/no_such_script.py --out runs/x", "no such script"),
        ("bash run_everything.sh", "not the project's command"),
    ],
    ids=lambda v: v if len(v) < 30 else v[:30],
)
def test_a_bad_command_fails_naming_page_and_line(
    checker, tmp_path: Path, command: str, says: str
) -> None:
    page = _page(
        tmp_path,
        "# about 2 h on 2 cores",
        "semexplore benchmark --suite caves \\",
        "  --out runs/ok",
        command,
    )
    checked, problems = checker.check_page(page)
    assert checked == 2 and len(problems) == 1, problems
    assert problems[0].startswith(f"{page}:9: ") and says in problems[0], problems[0]


def test_main_reports_and_fails(checker, tmp_path: Path, capsys) -> None:
    page = _page(tmp_path, GOOD.replace("nearest", "nearestt"))
    assert checker.main([str(page)]) == 1
    out = capsys.readouterr()
    assert "1 long commands checked, 1 problems" in out.out and "nearestt" in out.err
    assert checker.main([str(_page(tmp_path, GOOD))]) == 0
