"""``semexplore pretrained``: the agents shipped inside the package, ready to run.

Each line starts with the policy spec that runs the model (``pretrained:NAME``), then what it
is, what it was trained on, the command and config that reproduce it, and its measured results.

Example::

    semexplore pretrained
    semexplore pretrained --json
    semexplore explore --world maze1 --policy pretrained:dagger_maze
    semexplore benchmark --worlds 'maze:size_m=6,seed=*' --policies semantic,pretrained:frontier_choice_maze --runs 5 --out runs/bench
"""

from __future__ import annotations

import argparse
import json


def add_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    from semexplore_gym.cli import describe

    p = sub.add_parser(
        "pretrained",
        help="list the shipped pretrained agents (policy spec pretrained:NAME)",
        description=describe(__doc__),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument(
        "--json", action="store_true", help="a JSON list (with each model's path and size)"
    )
    return p


def run(args: argparse.Namespace) -> int:
    from semexplore_gym.policies.pretrained import pretrained_models

    models = pretrained_models()
    if args.json:
        print(json.dumps([m.to_dict() for m in models], indent=2))
        return 0
    for m in models:
        print(m.summary_line())
    return 0
