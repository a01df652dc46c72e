"""``semexplore pretrained``: the agents shipped inside the package, ready to run.

One short line per model: the policy spec that runs it (``pretrained:NAME``) and what it is.
``--details`` adds what it was trained on, the command and config that reproduce it (they run
from any directory: the ``configs/...`` files ship with the package) and its measured results.

Example::

    semexplore pretrained
    semexplore pretrained --details
    semexplore pretrained --json
    semexplore explore --world maze1 --policy pretrained:dagger_maze
    semexplore benchmark --worlds 'maze:size_m=6,seed=*' --policies semantic,pretrained:frontier_choice_maze --runs 5 --out runs/bench
"""

from __future__ import annotations

import argparse

from semexplore_gym.cli._output import print_json


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
    p.add_argument(
        "--details",
        action="store_true",
        help="every field of each model: training data, reproduce command, config, results",
    )
    return p


def run(args: argparse.Namespace) -> int:
    from semexplore_gym.policies.pretrained import pretrained_models

    models = pretrained_models()
    if args.json:
        print_json(args, [m.to_dict() for m in models], indent=2)
        return 0
    for i, m in enumerate(models):
        if args.details:
            print(("\n" if i else "") + "\n".join(m.detail_lines()))
        else:
            print(m.summary_line())
    return 0
