"""Regenerate the committed figures in ``docs/figures/`` that one command draws.

The commands in the README and the docs write under ``runs/`` (or the current directory), never
into ``docs/``: the committed figures change only when this script is run on purpose, and the
text beside a figure is then checked against the new run.

    python scripts/make_figures.py --list
    python scripts/make_figures.py --only team_office.gif
    python scripts/make_figures.py                      # all of them, a few minutes on 2 cores

The benchmark figures (``suites_explored_area_*.png``, ``regret_ladder_*.png``,
``team_speedup.png`` ...) are the plots of the long runs whose reproduce commands their pages
give; they are copied from those runs' ``runs/`` directories.
"""

from __future__ import annotations

import argparse
import runpy
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
#: Figure file -> the command that draws it; ``{out}`` is the figure's path, ``{dir}`` its folder.
FIGURES: dict[str, list[str]] = {
    "expert_maze1.gif": [
        "semexplore", "explore", "--world", "maze1", "--policy", "semantic", "--seed", "0",
        "--gif", "{out}", "--no-progress",
    ],
    "team_office.gif": [
        "semexplore", "explore", "--world", "office:seed=304,size_m=8", "--robots", "3",
        "--gif", "{out}", "--gif-every-s", "1", "--max-time-s", "300", "--no-progress",
    ],
    "slam_maze1.gif": [
        "semexplore", "explore", "--world", "maze1", "--policy", "semantic", "--seed", "0",
        "--env-config", "slam", "--gif", "{out}", "--gif-every-s", "8", "--no-progress",
    ],
    "compute_scaling.png": [
        "python", "scripts/bench_compute_scaling.py", "--stat", "min",
        "--out", "{dir}/compute_scaling.csv", "--figure", "{out}",
    ],
}  # fmt: skip


def command_for(name: str, out_dir: Path) -> list[str]:
    """The command that draws figure ``name`` into ``out_dir``."""
    return [a.format(out=out_dir / name, dir=out_dir) if "{" in a else a for a in FIGURES[name]]


def run_command(argv: list[str]) -> int:
    """Run a ``semexplore`` command or a ``python scripts/X.py`` in this process."""
    if argv[0] == "semexplore":
        from semexplore_gym.cli import main as semexplore

        return semexplore(argv[1:])
    script = runpy.run_path(str(REPO / argv[1]), run_name="make_figures")
    return int(script["main"](argv[2:]) or 0)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--list", action="store_true", help="print each figure and its command")
    ap.add_argument(
        "--only", default=None, help=f"comma-separated figure names (of: {', '.join(FIGURES)})"
    )
    ap.add_argument(
        "--out-dir", type=Path, default=REPO / "docs" / "figures", help="default: %(default)s"
    )
    args = ap.parse_args(argv)
    names = [n.strip() for n in args.only.split(",")] if args.only else list(FIGURES)
    unknown = [n for n in names if n not in FIGURES]
    if unknown:
        ap.error(f"--only: unknown figure(s) {unknown}; known: {', '.join(FIGURES)}")
    for name in names:
        argv_ = command_for(name, args.out_dir)
        print(f"{name}: {' '.join(argv_)}", file=sys.stdout if args.list else sys.stderr)
        if args.list:
            continue
        args.out_dir.mkdir(parents=True, exist_ok=True)
        code = run_command(argv_)
        if code:
            print(f"{name}: the command failed (exit {code})", file=sys.stderr)
            return code
    return 0


if __name__ == "__main__":
    sys.exit(main())
