"""The README and the documentation site as a newcomer uses them.

Every file they link is in the repository; every code block runs as written (``bash`` commands
with budget-shrinking flags, ``python`` snippets as they are), so stale docs fail CI; the site
builds with warnings as errors. Commands that need the real maps in ``../shared/maps`` skip with
a reason when that folder is absent (or ``SEMEXPLORE_TEST_HIDE_SHARED=1`` hides it).

A block that only illustrates (output, a sketch) is marked: a `` ```{code-block} LANG``
directive, or a ``<!-- not-run -->`` line right above its fence. Keep them few.

A ``bash`` block with a ``<!-- long -->`` line right above its fence holds long reproduce
commands (a published table's benchmark, hours on two cores): they are not run, but each must
parse with its command's own parser and name policies, worlds, suites and configs that resolve
(``scripts/check_docs_commands.py``, well under a second per command).
"""

from __future__ import annotations

import importlib.util
import os
import re
import resource
import runpy
import shlex
import shutil
import subprocess
import sys
import time
import warnings
from dataclasses import dataclass
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
SHARED = REPO.parent / "shared"
#: The config-override flag of ``semexplore train`` (one place to change if it is renamed).
SET = "--train-set"
#: Pages in reading order: the README first (its `maps get` comes before the pages' map use).
SITE_ORDER = (
    "index",
    "getting-started",
    "environment",
    "worlds",
    "policies",
    "benchmarks",
    "oracle",
    "teams",
    "team-study",
    "slam",
    "results",
    "learning",
    "learning-first-designs",
    "learned_frontier_value",
    "performance",
    "security",
    "api",
    "architecture",
)
#: Commands the docs show but CI runs itself (.ci/run installs, then runs pytest).
CI_COMMANDS = ("pip", "pytest")
#: At most this many illustrative (not-run) blocks over README and site together.
MAX_NOT_RUN = 4
#: Pages whose commands a newcomer runs first: no long block there.
FIRST_PAGES = ("README.md", "docs/index.md", "docs/getting-started.md")


def shared_maps_present() -> bool:
    return (SHARED / "maps").is_dir() and os.environ.get("SEMEXPLORE_TEST_HIDE_SHARED") != "1"


def doc_pages() -> list[Path]:
    """README.md, then the site's pages in reading order (pages not in the order last)."""
    pages = sorted((REPO / "docs").glob("*.md"))
    rank = {name: i for i, name in enumerate(SITE_ORDER)}
    pages.sort(key=lambda p: (rank.get(p.stem, len(rank)), p.name))
    return [REPO / "README.md", *pages]


def _rel(path: Path) -> str:
    return path.relative_to(REPO).as_posix()


# ------------------------------------------------------------------------------------- links
def _tracked_files() -> set[str] | None:
    if shutil.which("git") is None:
        return None
    try:
        out = subprocess.run(
            ["git", "ls-files", "-z"], cwd=REPO, capture_output=True, check=True, timeout=60
        ).stdout
    except (subprocess.CalledProcessError, subprocess.TimeoutExpired):
        return None
    return {p for p in out.decode().split("\0") if p}


def relative_links(markdown: str) -> list[str]:
    """Targets of the Markdown links and images that point into the repository."""
    markdown = re.sub(r"^```.*?^```", "", markdown, flags=re.S | re.M)  # not inside code
    targets = [
        a or b
        for a, b in re.findall(
            r"!?\[[^\]]*\]\(\s*(?:<([^>]+)>|([^)\s]+))(?:\s+\"[^\"]*\")?\s*\)", markdown
        )
    ]
    targets += re.findall(r"""<img[^>]+src=["']([^"']+)["']""", markdown)
    out = []
    for t in targets:
        if re.match(r"^[a-z][a-z0-9+.-]*:", t, re.I) or t.startswith(("#", "//")):
            continue  # a URL, mail address or an anchor in the same page
        out.append(t.split("#", 1)[0])
    return [t for t in out if t]


def test_relative_links_are_found_in_markdown() -> None:
    md = (
        "![a](docs/a.gif) [b](DEVELOPERS.md#set-up) [c](https://x.org/y.png) [d](#layout) "
        '<img src="docs/e.png"> [f](<docs/f g.png>)\n```bash\necho [x](not/a/link.md)\n```\n'
    )
    assert relative_links(md) == ["docs/a.gif", "DEVELOPERS.md", "docs/f g.png", "docs/e.png"]


@pytest.mark.parametrize("doc", ["DEVELOPERS.md", *(_rel(p) for p in doc_pages())], ids=lambda d: d)
def test_every_file_the_docs_link_is_tracked_by_git(doc: str) -> None:
    tracked = _tracked_files()
    if tracked is None:
        pytest.skip("not a git checkout (or no git): cannot tell which files are tracked")
    text = (REPO / doc).read_text(encoding="utf-8")
    missing = []
    for target in relative_links(text):
        path = os.path.normpath((REPO / doc).parent.joinpath(target)).replace(os.sep, "/")
        rel = os.path.relpath(path, REPO).replace(os.sep, "/")
        is_dir = any(f.startswith(rel.rstrip("/") + "/") for f in tracked)
        if rel not in tracked and not is_dir:
            missing.append(target)
    assert not missing, f"{doc} links files that git does not track: {missing}"


# ------------------------------------------------------------------------- what users read
def test_readme_is_short() -> None:
    lines = (REPO / "README.md").read_text(encoding="utf-8").count("\n")
    assert lines <= 150, f"README.md has {lines} lines; move detail into docs/"


def test_readme_results_are_short_and_name_versions() -> None:
    """At most 10 rows of results, each naming the expert it measured; no long specs."""
    import re

    text = (REPO / "README.md").read_text(encoding="utf-8")
    section = text[text.index("## Headline results") :].split("\n## ", 1)[0]
    rows = [ln for ln in section.splitlines() if ln.startswith("| ") and "---" not in ln][1:]
    assert 1 <= len(rows) <= 10, f"{len(rows)} result rows; keep at most 10"
    assert all(
        ln.rstrip().endswith(("| v2 |", "| pre-v3 |", "| v3 |", "| v4 |", "| – |")) for ln in rows
    )
    long_specs = re.findall(r"[\w-]+\[[^\]\s]*;[^\]\s]*;[^\]\s]*\]", text)
    assert not long_specs, f"specs with more than two overrides: {long_specs}"


def _catalogue_hashes() -> set[str]:
    from semexplore_gym.maps import catalogue

    names = set()
    for value in vars(catalogue).values():
        if isinstance(value, dict):
            names |= {k for k in value if isinstance(k, str)}
    return {n.rsplit("-", 1)[-1] for n in names}


@pytest.mark.parametrize("doc", [_rel(p) for p in doc_pages()], ids=lambda d: d)
def test_no_issue_numbers_or_commit_hashes(doc: str) -> None:
    """User-facing text names no tracker issues and no commits (map names may hold hex)."""
    text = (REPO / doc).read_text(encoding="utf-8")
    issues = re.findall(r"(?<![\w&/])#\d+\b|\bissue\s*#?\d+", text, re.I)
    assert not issues, f"{doc} cites issues: {issues}"
    map_ids = _catalogue_hashes()
    hashes = [
        h
        for h in re.findall(r"(?<![\w-])[0-9a-f]{7,40}(?![\w-])", text)
        if re.search(r"\d", h) and re.search(r"[a-f]", h) and h not in map_ids
    ]
    assert not hashes, f"{doc} cites commit hashes: {hashes}"


# ------------------------------------------------------------------------------ code blocks
@dataclass(frozen=True)
class Block:
    page: str
    line: int
    lang: str  # "bash", "python", "not-run", "long" or a directive name such as "{toctree}"
    body: str


FENCE = re.compile(
    r"^(?P<mark><!-- (?:not-run|long) -->\n)?```(?P<info>[^\n]*)\n(?P<body>.*?)^```[ \t]*$",
    re.S | re.M,
)


def code_blocks(markdown: str, page: str = "") -> list[Block]:
    """Every fenced block, with what the test does with it."""
    blocks = []
    for m in FENCE.finditer(markdown):
        info = m.group("info").strip()
        line = markdown.count("\n", 0, m.start("info")) + 1
        if m.group("mark") and "long" in m.group("mark"):
            lang = "long"
        elif m.group("mark") or info.startswith("{code-block}"):
            lang = "not-run"
        elif info.startswith("{"):
            lang = info.split()[0]
        else:
            lang = info
        blocks.append(Block(page, line, lang, m.group("body")))
    return blocks


def indented_code_lines(markdown: str) -> list[int]:
    """Lines that start an indented (4-space) code block outside fences: they would escape."""
    bad, fenced, prev = [], False, ""
    for i, line in enumerate(markdown.splitlines(), 1):
        if line.startswith("```"):
            fenced = not fenced
        elif not fenced and not prev.strip() and re.match(r"^ {4,}\S", line):
            bad.append(i)
        prev = line
    return bad


def bash_commands(body: str) -> list[list[str]]:
    """The commands of a ``bash`` block as argv lists (continuation lines joined, comments
    dropped, ``a && b`` split, leading ``VAR=value`` assignments removed)."""
    commands = []
    for line in body.replace("\\\n", " ").splitlines():
        tokens = shlex.split(line, comments=True)
        while tokens:
            cut = tokens.index("&&") if "&&" in tokens else len(tokens)
            argv, tokens = tokens[:cut], tokens[cut + 1 :]
            while argv and re.fullmatch(r"[A-Z_][A-Z0-9_]*=\S*", argv[0]):
                argv = argv[1:]
            if argv:
                commands.append(argv)
    return commands


def is_runnable(argv: list[str]) -> bool:
    return argv[0] == "semexplore" or (
        argv[0] == "python" and len(argv) > 1 and argv[1].startswith("scripts/")
    )


def python_files(blocks: list[Block]) -> dict[str, str]:
    """The ``python`` blocks that start with ``# NAME.py``: files that commands use."""
    out = {}
    for b in blocks:
        if b.lang == "python":
            m = re.fullmatch(r"#\s*([\w./-]+\.py)", b.body.splitlines()[0].strip())
            if m:
                out[m.group(1)] = b.body
    return out


def all_blocks() -> list[Block]:
    return [b for p in doc_pages() for b in code_blocks(p.read_text(encoding="utf-8"), _rel(p))]


def test_code_blocks_are_found() -> None:
    md = (
        "```bash\nsemexplore explore --world maze1 \\\n    --json  # c\nPYTHONPATH=$PWD python "
        "scripts/x.py && pip install -e .\n```\n<!-- not-run -->\n```python\nraise SystemExit\n"
        "```\n```{code-block} text\nout\n```\n```{toctree}\nindex\n```\n<!-- long -->\n```bash\n"
        "semexplore benchmark --suite caves --out runs/x\n```\n"
    )
    blocks = code_blocks(md)
    assert [b.lang for b in blocks] == ["bash", "not-run", "not-run", "{toctree}", "long"]
    assert bash_commands(blocks[0].body) == [
        ["semexplore", "explore", "--world", "maze1", "--json"],
        ["python", "scripts/x.py"],
        ["pip", "install", "-e", "."],
    ]
    assert indented_code_lines("text\n\n    semexplore x\n\n- a\n  b\n") == [3]


def test_every_code_block_is_run_or_marked() -> None:
    """A block is a ``bash`` block of runnable commands, a ``python`` snippet, a Sphinx
    directive, or explicitly marked not-run; nothing else slips past the command test."""
    problems, not_run = [], []
    for page in doc_pages():
        text = page.read_text(encoding="utf-8")
        for line in indented_code_lines(text):
            problems.append(f"{_rel(page)}:{line}: an indented code block; fence it as ```bash")
        for b in code_blocks(text, _rel(page)):
            where = f"{b.page}:{b.line}"
            if b.lang == "not-run":
                not_run.append(where)
            elif b.lang == "bash":
                for argv in bash_commands(b.body):
                    if not is_runnable(argv) and argv[0] not in CI_COMMANDS:
                        problems.append(f"{where}: cannot run {shlex.join(argv)!r}")
            elif b.lang == "long" and _rel(page) in FIRST_PAGES:
                problems.append(f"{where}: a long block on a page newcomers run first")
            elif b.lang not in ("python", "long", "{toctree}", "{eval-rst}", "{include}"):
                problems.append(f"{where}: a ```{b.lang} block: use bash/python or mark it")
    assert not problems, "\n".join(problems)
    assert len(not_run) <= MAX_NOT_RUN, f"too many illustrative blocks: {not_run}"


def test_long_blocks_parse_and_resolve(docs_commands_checker) -> None:
    """Every long reproduce command parses with its command's parser and names policies,
    worlds, suites, splits and configs that resolve (nothing is run)."""
    checker = docs_commands_checker
    long = [b for b in all_blocks() if b.lang == "long"]
    assert long, "no <!-- long --> block found"
    checked, problems = 0, []
    for page in doc_pages():
        n, found = checker.check_page(page)
        checked, problems = checked + n, problems + found
    assert checked >= len(long)
    assert not problems, "long reproduce commands that would not start:\n" + "\n".join(problems)


def test_commands_are_found() -> None:
    blocks = all_blocks()
    commands = [" ".join(c[:2]) for b in blocks if b.lang == "bash" for c in bash_commands(b.body)]
    assert "semexplore explore" in commands and "semexplore train" in commands
    assert "my_planner.py" in python_files(blocks)
    bench = next(
        c for b in blocks if b.lang == "bash" for c in bash_commands(b.body) if "runs/mine" in c
    )
    assert "path/to/your_map.yaml" not in " ".join(shrink(bench, []))
    readme = code_blocks((REPO / "README.md").read_text(encoding="utf-8"))
    assert any(b.lang == "python" and "run_mission" in b.body for b in readme)
    assert any(b.lang == "python" and "record_expert_dataset" in b.body for b in blocks)


def test_the_shrunk_benchmark_skips_the_oracle_only_beyond_the_paper_suite() -> None:
    def run(*flags: str) -> list[str]:
        return shrink(["semexplore", "benchmark", *flags, "--out", "runs/x"], [])

    assert "--no-oracle" in run("--suite", "paper,mazes")
    assert "--no-oracle" not in run("--suite", "paper")
    assert "--no-oracle" not in run("--worlds", "maze1")
    assert "--no-oracle" not in run("--suite", "mazes", "--oracle")  # asked for: kept
    assert run("--suite", "mazes", "--no-oracle").count("--no-oracle") == 1


# ------------------------------------------------------------------------- running commands
def _replace_or_add(argv: list[str], flag: str, value: str) -> list[str]:
    if flag in argv:
        i = argv.index(flag)
        return [*argv[: i + 1], value, *argv[i + 2 :]]
    return [*argv, flag, value]


TINY_IMITATION = [
    "torch_threads=1",
    "env.world=maze:size_m=4,seed=3",
    "expert.episodes=2",
    "expert.max_steps=12",
    "expert.holdout_fraction=0.5",
    "expert.workers=1",
    "bc.epochs=1",
]
TINY_DAGGER = [
    "dagger.rounds=1",
    "dagger.episodes_per_round=1",
    "dagger.epochs_per_round=1",
    "dagger.workers=1",
]
TINY_PPO = [
    "torch_threads=1",
    "env.world=maze:size_m=4,seed=3",
    "ppo.total_timesteps=8",
    "ppo.n_steps=4",
    "ppo.batch_size=4",
    "ppo.n_epochs=1",
]
#: The frontier student's DAgger and its headroom script: one short mission on a small maze.
TINY_ORACLE_STUDENT = [
    "rounds=1",
    "episodes_per_round=1",
    "splits=[mazes]",
    "max_size_m=6",
    "max_time_s=60",
    "workers=1",
]
TINY_FRONTIER_VALUE = [
    "generations=1",
    "population=2",
    "elite=1",
    "worlds_per_generation=1",
    "max_time_s=5",
    "workers=1",
]


#: Benchmarks skip their figures in the test (one command, the README's first, keeps them).
NO_PLOTS = ["--no-plots"]


def _cpu_s() -> float:
    """CPU seconds of this process and its finished children (a load-independent clock)."""
    own, kids = (
        resource.getrusage(resource.RUSAGE_SELF),
        resource.getrusage(resource.RUSAGE_CHILDREN),
    )
    return own.ru_utime + own.ru_stime + kids.ru_utime + kids.ru_stime


def _suites_beyond_paper(argv: list[str]) -> bool:
    """Whether a benchmark runs a suite other than ``paper``: there the oracle (on by default
    with ``--suite``) plans its tour and bound on worlds of up to 40 m, minutes of CPU that no
    mission budget shrinks, so the docs test runs it with ``--no-oracle`` (the oracle inside a
    benchmark is tested on small worlds: tests/evaluation/test_regret.py; the paper suite keeps
    it here)."""
    if "--suite" not in argv:
        return False
    return any(s != "paper" for s in argv[argv.index("--suite") + 1].split(","))


def shrink(argv: list[str], tiny_macro: list[str]) -> list[str]:
    """The same command with a test-sized budget (flags substituted or appended)."""
    if argv[0] == "python":
        script = argv[1]
        if script == "scripts/bench_imitation.py":
            argv = _replace_or_add(argv, "--seeds", "100-100")
            return _replace_or_add(argv, "--expert-max-time-s", "20")
        if script == "scripts/bench_compute_scaling.py":
            return [*_replace_or_add(argv, "--repeats", "1"), "--quick"]
        if script == "scripts/teacher_headroom.py":
            argv = _replace_or_add(_replace_or_add(argv, "--episodes", "1"), "--workers", "1")
            return [*argv, *(t for s in TINY_ORACLE_STUDENT[2:5] for t in (SET, s))]
        if script == "scripts/fuzz.py":
            return _replace_or_add(_replace_or_add(argv, "--sample", "12"), "--jobs", "1")
        return argv
    command = argv[1]
    if command == "explore":
        return [*_replace_or_add(argv, "--max-time-s", "10"), "--no-progress"]
    if command == "benchmark":
        if "--worlds" in argv:
            i = argv.index("--worlds")
            worlds = ",".join(w for w in argv[i + 1].split(",") if not w.startswith("path/to/"))
            argv = [*argv[: i + 1], worlds, *argv[i + 2 :]]
        argv = _replace_or_add(_replace_or_add(argv, "--runs", "1"), "--max-time-s", "5")
        if _suites_beyond_paper(argv) and "--oracle" not in argv and "--no-oracle" not in argv:
            argv = [*argv, "--no-oracle"]
        return [*_replace_or_add(argv, "--workers", "1"), "--no-progress", *NO_PLOTS]
    if command == "compare-weights":
        for flag, value in (("--trials", "1"), ("--train-runs", "1"), ("--runs", "1")):
            argv = _replace_or_add(argv, flag, value)
        if "--train-max-time-s" in argv:
            argv = _replace_or_add(argv, "--train-max-time-s", "5")
        argv = _replace_or_add(argv, "--max-time-s", "5")
        return [*_replace_or_add(argv, "--workers", "1"), "--no-progress"]
    if command == "train":  # the progress bar stays on, as documented
        algo = argv[argv.index("--algo") + 1]
        config = argv[argv.index("--train-config") + 1] if "--train-config" in argv else ""
        if "frontier_choice" in config or "planner_weights" in config:
            return [*argv, *(a for a in tiny_macro if a != "--no-progress")]
        sets = {
            "bc": TINY_IMITATION,
            "dagger": TINY_IMITATION + TINY_DAGGER,
            "frontier_value": TINY_FRONTIER_VALUE,
            "oracle_student": TINY_ORACLE_STUDENT,
        }.get(algo, TINY_PPO)
        return [*argv, *(t for s in sets for t in (SET, s))]
    return argv


def needs_real_maps(argv: list[str]) -> bool:
    """Whether a command reads the real maps (``../shared/maps`` or a fetched ``map:NAME``)."""
    if argv[1:3] in (["maps", "path"], ["maps", "get"]):
        return True  # the docs fetch with --from ../shared/maps; CI has no network
    if any("map:" in a or "../shared" in a for a in argv):
        return True
    if "--suite" in argv or "--test-suite" in argv:
        flag = "--suite" if "--suite" in argv else "--test-suite"
        return "real" in argv[argv.index(flag) + 1].split(",")
    return False


def test_the_readme_shows_the_users_commands() -> None:
    """The README's commands work on a user's clone: none reads this project's ../shared."""
    readme = code_blocks((REPO / "README.md").read_text(encoding="utf-8"))
    commands = [c for b in readme if b.lang == "bash" for c in bash_commands(b.body)]
    assert ["semexplore", "maps", "get", "tb3-world"] in commands
    assert not [c for c in commands if any("../shared" in a for a in c)]


def test_getting_started_lists_every_extra() -> None:
    tomllib = pytest.importorskip("tomllib")  # Python 3.11+

    project = tomllib.loads((REPO / "pyproject.toml").read_text())["project"]
    extras = set(project["optional-dependencies"]) - {"dev"}
    text = (REPO / "docs" / "getting-started.md").read_text(encoding="utf-8")
    listed = re.search(r"^The extras:(.*?)\n\n", text, re.S | re.M)
    assert listed is not None, "docs/getting-started.md has no 'The extras:' paragraph"
    missing = sorted(e for e in extras if f"`{e}` (" not in listed.group(1))
    assert not missing, f"getting-started's extras list lacks {missing}"
    dev = re.search(r"`dev` = (.*?) and the tools", text, re.S)
    assert dev is not None and all(f"`{e}`" in dev.group(1) for e in extras), dev


def test_user_docs_carry_no_notes_about_the_projects_own_machines() -> None:
    """Notes about this project's machines (a torch wheel on disk) live in DEVELOPERS.md."""
    for page in doc_pages():
        text = page.read_text(encoding="utf-8")
        assert "torch==2.13.0" not in text and "project's own" not in text, _rel(page)
    assert "torch==2.13.0" in (REPO / "DEVELOPERS.md").read_text(encoding="utf-8")


#: Flags whose value is a path a command writes.
OUTPUT_FLAGS = ("--out", "--gif", "--figure", "--out-dir", "--csv", "--json-out")


def _writes_into_docs(argv: list[str]) -> list[str]:
    """The paths under ``docs/`` that a documented command would write (given or by default)."""
    paths = [v for flag, v in zip(argv, argv[1:], strict=False) if flag in OUTPUT_FLAGS]
    paths += [a.split("=", 1)[1] for a in argv if "=" in a and a.split("=", 1)[0] in OUTPUT_FLAGS]
    bad = [p for p in paths if Path(os.path.normpath(p)).parts[:1] == ("docs",)]
    if argv[0] == "python":  # a script's own default output paths
        source = (REPO / argv[1]).read_text(encoding="utf-8")
        bad += re.findall(r"default=[\"'](docs/[^\"']*)", source)
    return bad


def test_no_documented_command_writes_into_docs() -> None:
    """Docs commands write under runs/; the committed figures change only through
    scripts/make_figures.py."""
    assert _writes_into_docs(["semexplore", "explore", "--gif", "docs/figures/x.gif"])
    assert _writes_into_docs(["semexplore", "benchmark", "--out=./docs/r"])
    assert not _writes_into_docs(["semexplore", "explore", "--gif", "runs/x.gif"])
    found = []
    for b in all_blocks():
        if b.lang in ("bash", "long"):
            for argv in bash_commands(b.body):
                if is_runnable(argv) and _writes_into_docs(argv):
                    found.append(f"{b.page}:{b.line}: {shlex.join(argv)}")
    assert not found, "documented commands write into docs/:\n" + "\n".join(found)


def test_real_map_commands_are_recognised() -> None:
    assert needs_real_maps(["semexplore", "benchmark", "--suite", "paper,real"])
    assert needs_real_maps(["semexplore", "explore", "--world", "map:tb3-world"])
    assert needs_real_maps(["semexplore", "maps", "path", "tb3-world"])
    assert not needs_real_maps(["semexplore", "benchmark", "--suite", "paper,mazes"])
    assert not needs_real_maps(["semexplore", "maps", "list", "--files"])


def _run_command(
    argv: list[str], work: Path, env: dict[str, str], subprocess_run: bool
) -> str | None:
    """Run one documented command in ``work``; returns an error report, or None if it passed."""
    if subprocess_run:  # through the installed console script, exactly as a user types it
        exe = shutil.which("semexplore")
        cmd = (
            [exe] if exe else [sys.executable, "-c", "from semexplore_gym.cli import main; main()"]
        )
        proc = subprocess.run(
            [*cmd, *argv[1:]], cwd=work, env=env, capture_output=True, text=True, timeout=600
        )
        return None if proc.returncode == 0 else proc.stderr[-3000:]
    # In this process (the entry point's own function): kernels and imports are loaded once.
    from semexplore_gym.cli import main

    try:
        if argv[0] == "semexplore":
            code = main(argv[1:])
        else:
            script = runpy.run_path(str(REPO / argv[1]), run_name="readme_script")
            code = script["main"](argv[2:])
    except SystemExit as e:
        code = e.code
    except Exception as e:  # noqa: BLE001 - reported with the command
        return f"{type(e).__name__}: {e}"
    return None if code in (0, None) else f"exit code {code}"


def _run_snippet(block: Block) -> str | None:
    """Run a ``python`` snippet as a script in the current directory."""
    try:
        exec(compile(block.body, f"{block.page}:{block.line}", "exec"), {"__name__": "__main__"})
    except Exception as e:  # noqa: BLE001 - reported with the block
        return f"{type(e).__name__}: {e}"
    return None


@pytest.mark.slow
@pytest.mark.clean_clone
def test_every_documented_command_runs(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, tiny_macro_train_args, one_torch_thread
) -> None:
    """Every command and snippet of the README and the site, shrunk to a test budget."""
    pytest.importorskip("stable_baselines3")
    blocks = all_blocks()
    work = tmp_path / "work"
    work.mkdir()
    # Relative paths of the docs resolve as in a checkout; outputs land in the temp dir.
    for name in ("configs", "scripts"):
        (work / name).symlink_to(REPO / name, target_is_directory=True)
    for name, source in python_files(blocks).items():
        (work / name).write_text(source)
    # Maps fetched by `semexplore maps get` land in a cache of this test, not the user's.
    monkeypatch.setenv("SEMEXPLORE_CACHE", str(tmp_path / "cache"))
    monkeypatch.delenv("SEMEXPLORE_MAPS_DIR", raising=False)
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(REPO), env.get("PYTHONPATH", "")])
    monkeypatch.chdir(work)
    maps = shared_maps_present()
    # SEMEXPLORE_TEST_HIDE_SHARED=1 (CI's clean-clone pass): every other command gives the same
    # result as in the full pass, so only the real-map ones are looked at, and they must skip.
    only_real_maps = os.environ.get("SEMEXPLORE_TEST_HIDE_SHARED") == "1"
    seen: set[str] = set()
    plotted = False
    failures, skipped, timings = [], [], []
    t_all, c_all = time.perf_counter(), _cpu_s()
    for block in blocks:
        where = f"{block.page}:{block.line}"
        if block.lang == "python":
            if re.match(r"#\s*[\w./-]+\.py\s*$", block.body.splitlines()[0]):
                continue  # a file the commands use, written above
            if block.body in seen:
                continue
            seen.add(block.body)
            if not maps and ("map:" in block.body or "../shared" in block.body):
                skipped.append(f"{where} (python snippet)")
                continue
            if only_real_maps:
                continue
            t0, c0 = time.perf_counter(), _cpu_s()
            error = _run_snippet(block)
            timings.append((time.perf_counter() - t0, _cpu_s() - c0, f"python snippet {where}"))
            if error is not None:
                failures.append(f"python snippet at {where}\n{error}")
            continue
        if block.lang != "bash":
            continue
        for argv in bash_commands(block.body):
            if not is_runnable(argv):
                continue  # pip and pytest: .ci/run runs them itself
            if any(a.startswith("path/to/") and a.endswith(".yaml") for a in argv):
                skipped.append(f"{where} {shlex.join(argv)} (the reader's own suite file)")
                continue
            if needs_real_maps(argv):
                if not maps:
                    skipped.append(f"{where} {shlex.join(argv)}")
                    continue
                argv = [a.replace("../shared", str(SHARED)) for a in argv]
                if argv[1:3] == ["maps", "get"] and "--from" not in argv:
                    argv = [*argv, "--from", str(SHARED / "maps")]  # CI has no network
            elif only_real_maps:
                continue
            run = shrink(argv, tiny_macro_train_args(2))
            if run[1] == "benchmark" and not plotted and "--no-plots" not in argv:
                run, plotted = [a for a in run if a != "--no-plots"], True  # figures once
            if shlex.join(run) in seen:
                continue
            seen.add(shlex.join(run))
            t0, c0 = time.perf_counter(), _cpu_s()
            error = _run_command(run, work, env, subprocess_run=not timings)
            timings.append((time.perf_counter() - t0, _cpu_s() - c0, shlex.join(run)))
            if error is not None:
                failures.append(f"{where}\n$ {shlex.join(run)}\n{error}")
    print(
        f"documented commands: {len(timings)} run in {time.perf_counter() - t_all:.0f} s wall, "
        f"{_cpu_s() - c_all:.0f} s CPU"
    )
    for t, cpu, c in timings:
        print(f"  {t:6.1f} s wall {cpu:6.1f} s CPU  {c}")
    if skipped:
        reason = "" if maps else " (no ../shared/maps: the real maps are absent)"
        print(f"skipped{reason}:", *skipped, sep="\n  ")
        if not maps:
            warnings.warn(
                f"{len(skipped)} documented commands skipped: they need the real maps in "
                f"{SHARED / 'maps'}, which is absent (or hidden by SEMEXPLORE_TEST_HIDE_SHARED=1)",
                stacklevel=1,
            )
    assert not failures, "documented commands failed:\n\n" + "\n\n".join(failures)
    if only_real_maps:
        assert skipped and not timings, "with ../shared hidden every real-map command must skip"
        return
    assert (work / "maze1.gif").is_file() and (work / "runs" / "bc" / "model.zip").is_file()


def test_ci_runs_only_the_clean_clone_checks_without_shared() -> None:
    """.ci/run runs this file twice, the second time with ../shared hidden: that pass selects
    the tests marked ``clean_clone`` (the commands that need the real maps, which must skip),
    so the slow blocks run once; every other test here gives the same result either way."""
    ci = (REPO / ".ci" / "run").read_text(encoding="utf-8")
    hidden = [
        line for line in ci.splitlines() if line.startswith("SEMEXPLORE_TEST_HIDE_SHARED=1 pytest")
    ]
    assert len(hidden) == 1, hidden
    argv = shlex.split(hidden[0].split("||")[0])
    assert argv[argv.index("-m") + 1] == "clean_clone" and "tests/test_readme.py" in argv
    marked = [
        name
        for name, obj in globals().items()
        if name.startswith("test_")
        and any(m.name == "clean_clone" for m in getattr(obj, "pytestmark", []))
    ]
    assert marked == ["test_every_documented_command_runs"]


# ------------------------------------------------------------------------------ the site
@pytest.mark.slow
def test_docs_site_builds_without_warnings(tmp_path: Path) -> None:
    for module in ("sphinx", "furo", "myst_parser"):
        if importlib.util.find_spec(module) is None:
            pytest.skip(f"{module} is not installed (pip install -e '.[docs]')")
    proc = subprocess.run(
        [sys.executable, "-m", "sphinx", "-W", "--keep-going", "-q", "-b", "html",
         str(REPO / "docs"), str(tmp_path / "html"), "-d", str(tmp_path / "doctrees")],
        cwd=REPO, capture_output=True, text=True, timeout=600,
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr[-5000:]
    assert (tmp_path / "html" / "results.html").is_file()
