"""The README as a newcomer uses it: every file it links is in the repository, and every command
in its ``bash`` blocks runs as written (with budget-shrinking flags), so a stale README fails CI."""

from __future__ import annotations

import os
import re
import runpy
import shlex
import shutil
import subprocess
import sys
import time
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
DOCS = ("README.md", "DEVELOPERS.md")
SHARED = REPO.parent / "shared"
#: The config-override flag of ``semexplore train`` (one place to change if it is renamed).
SET = "--train-set"


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
        '<img src="docs/e.png"> [f](<docs/f g.png>)'
    )
    assert relative_links(md) == ["docs/a.gif", "DEVELOPERS.md", "docs/f g.png", "docs/e.png"]


@pytest.mark.parametrize("doc", DOCS)
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


# ---------------------------------------------------------------------------------- commands
def bash_blocks(markdown: str) -> list[str]:
    return re.findall(r"^```bash\n(.*?)^```", markdown, re.S | re.M)


def readme_commands(markdown: str) -> list[list[str]]:
    """Every ``semexplore ...`` and ``python scripts/...`` command of the ``bash`` blocks, in
    order, as argv lists (continuation lines joined, comments dropped, ``a && b`` split)."""
    commands = []
    for block in bash_blocks(markdown):
        for line in block.replace("\\\n", " ").splitlines():
            tokens = shlex.split(line, comments=True)
            while tokens:
                cut = tokens.index("&&") if "&&" in tokens else len(tokens)
                argv, tokens = tokens[:cut], tokens[cut + 1 :]
                if argv[:1] == ["semexplore"] or (
                    argv[:1] == ["python"] and len(argv) > 1 and argv[1].startswith("scripts/")
                ):
                    commands.append(argv)
    return commands


def python_files(markdown: str) -> dict[str, str]:
    """The README's ``python`` blocks that start with ``# NAME.py``: the files its commands use."""
    out = {}
    for block in re.findall(r"^```python\n(.*?)^```", markdown, re.S | re.M):
        first = block.splitlines()[0].strip()
        m = re.fullmatch(r"#\s*([\w./-]+\.py)", first)
        if m:
            out[m.group(1)] = block
    return out


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

TINY_FRONTIER_VALUE = [
    "generations=1",
    "population=2",
    "elite=1",
    "worlds_per_generation=1",
    "max_time_s=5",
    "workers=1",
]


def shrink(argv: list[str], tiny_macro: list[str]) -> list[str]:
    """The same command with a test-sized budget (flags substituted or appended)."""
    if argv[0] == "python":
        if argv[1] == "scripts/bench_imitation.py":
            argv = _replace_or_add(argv, "--seeds", "100-100")
            return _replace_or_add(argv, "--expert-max-time-s", "20")
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
        return [*argv, "--no-progress"]
    if command == "compare-weights":
        for flag, value in (("--trials", "1"), ("--train-runs", "1"), ("--runs", "1")):
            argv = _replace_or_add(argv, flag, value)
        return [*_replace_or_add(argv, "--max-time-s", "5"), "--no-progress"]
    if command == "train":  # the progress bar stays on, as documented
        algo = argv[argv.index("--algo") + 1]
        config = argv[argv.index("--train-config") + 1] if "--train-config" in argv else ""
        if "frontier_choice" in config or "planner_weights" in config:
            return [*argv, *(a for a in tiny_macro if a != "--no-progress")]
        sets = {
            "bc": TINY_IMITATION,
            "dagger": TINY_IMITATION + TINY_DAGGER,
            "frontier_value": TINY_FRONTIER_VALUE,
        }.get(algo, TINY_PPO)
        return [*argv, *(t for s in sets for t in (SET, s))]
    return argv


def test_readme_commands_are_found() -> None:
    text = (REPO / "README.md").read_text(encoding="utf-8")
    commands = [" ".join(c[:2]) for c in readme_commands(text)]
    assert "semexplore explore" in commands and "semexplore train" in commands
    assert not any(c.startswith(("pip", "pytest")) for c in commands)
    assert "my_planner.py" in python_files(text)
    bench = next(c for c in readme_commands(text) if "runs/mine" in c)
    assert "path/to/your_map.yaml" not in " ".join(shrink(bench, []))


def _run(argv: list[str], work: Path, env: dict[str, str], subprocess_run: bool) -> str | None:
    """Run one README command in ``work``; returns an error report, or None when it passed."""
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
    except Exception as e:  # noqa: BLE001 - reported with the command
        return f"{type(e).__name__}: {e}"
    return None if code in (0, None) else f"exit code {code}"


@pytest.mark.slow
def test_every_readme_command_runs(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, tiny_macro_train_args, one_torch_thread
) -> None:
    pytest.importorskip("stable_baselines3")
    text = (REPO / "README.md").read_text(encoding="utf-8")
    work = tmp_path / "work"
    work.mkdir()
    # Relative paths of the README resolve as in a checkout; outputs land in the temp dir.
    for name in ("configs", "scripts"):
        (work / name).symlink_to(REPO / name, target_is_directory=True)
    for name, source in python_files(text).items():
        (work / name).write_text(source)
    # Maps fetched by `semexplore maps get` land in a cache of this test, not the user's.
    monkeypatch.setenv("SEMEXPLORE_CACHE", str(tmp_path / "cache"))
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(REPO), env.get("PYTHONPATH", "")])
    monkeypatch.chdir(work)
    seen: set[tuple[str, ...]] = set()
    failures, skipped, timings = [], [], []
    t_all = time.perf_counter()
    for argv in readme_commands(text):
        if tuple(argv) in seen:
            continue
        seen.add(tuple(argv))
        if any(a.startswith("path/to/") and a.endswith(".yaml") for a in argv):
            skipped.append(" ".join(argv))  # a placeholder for the reader's own suite file
            continue
        # `map:NAME` worlds (and `maps path NAME`) need the `maps get ... --from ../shared/maps`
        # earlier in the README.
        needs_map = argv[1:3] == ["maps", "path"] or any(a.startswith("map:") for a in argv)
        if needs_map or any("../shared" in a for a in argv):
            if not SHARED.is_dir():
                skipped.append(" ".join(argv))
                continue
            argv = [a.replace("../shared", str(SHARED)) for a in argv]
        run = shrink(argv, tiny_macro_train_args(2))
        t0 = time.perf_counter()
        error = _run(run, work, env, subprocess_run=not timings)
        timings.append((round(time.perf_counter() - t0, 1), shlex.join(run)))
        if error is not None:
            failures.append(f"$ {shlex.join(run)}\n{error}")
    print(f"README commands: {len(timings)} run in {time.perf_counter() - t_all:.0f} s")
    for t, c in timings:
        print(f"  {t:6.1f} s  {c}")
    if skipped:
        print("skipped (no ../shared):", *skipped, sep="\n  ")
    assert not failures, "README commands failed:\n\n" + "\n\n".join(failures)
    assert (work / "maze1.gif").is_file() and (work / "runs" / "bc" / "model.zip").is_file()
