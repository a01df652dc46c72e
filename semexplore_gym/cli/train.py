"""``semexplore train --algo bc|dagger|ppo|maskable_ppo|frontier_value|oracle_student|option_ppo --train-config FILE --out DIR``: train an agent.

``bc`` records expert episodes and behaviour-clones an SB3 policy; ``dagger`` does the same and
then runs DAgger rounds; ``ppo`` trains SB3 PPO on the egocentric env, optionally starting from
a BC/DAgger model (``ppo.init_from``). With ``env.env_id`` set to a macro-action env
(``SemanticExploreFrontier-v0``, ``SemanticExploreWeights-v0``) ``ppo`` and ``maskable_ppo``
(sb3-contrib ``MaskablePPO``, using the env's ``action_masks``) train an MLP on that env's own
observation instead (``env.macro`` holds its ``MacroParams`` fields, ``env.expert`` overrides of
the driving expert's parameters). Every run directory gets ``model.zip``, the resolved
``config.yaml``, ``args.json`` (arguments and command line), TensorBoard logs (CSV when
tensorboard is missing) and, for bc/dagger, the dataset ``dataset.npz`` and ``metrics.json``.
``frontier_value`` fits a learned frontier value for the expert (no torch needed) and writes
``model.yaml``, ``generations.jsonl``, ``config.yaml``, ``args.json`` and ``metrics.json``.
``oracle_student`` trains the frontier student on the oracle's labels by DAgger (no torch;
:mod:`~semexplore_gym.training.oracle_student`) and writes ``model.yaml``, one model per round,
the labels (``samples/``), ``episodes.jsonl``, ``rounds.jsonl`` and ``metrics.json``; rerun the
same command to resume. ``option_ppo`` trains MaskablePPO choosing among every reachable
frontier option, with a privileged critic, after behaviour cloning of the frontier student
(:mod:`~semexplore_gym.training.option_ppo`); it writes ``model.zip``, ``bc_model.zip``,
``curve.csv``, ``curve.png`` and ``checkpoints/last.zip``; rerun the same command to resume.

The shipped configs (``configs/agents/*.yml``: bc_maze, dagger_maze, ppo_maze,
frontier_choice_maze, planner_weights_maze, frontier_value, oracle_student, option_ppo) work from any
directory.

Example::

    semexplore train --algo dagger --train-config configs/agents/dagger_maze.yml --out runs/dagger
    semexplore train --algo bc --train-config configs/agents/bc_maze.yml --train-set bc.epochs=2 --out runs/bc
"""

# This module parses the arguments and writes the run directory; the configuration
# (semexplore_gym.training.train_config) and the runs (training.imitation, training.ppo,
# training.frontier_value_search) live in semexplore_gym.training.

from __future__ import annotations

import argparse
import json
import shlex
import sys
import time
from pathlib import Path
from typing import Any

import yaml

from semexplore_gym.cli._flags import add_renamed_flag
from semexplore_gym.cli._output import add_json_flag, print_result
from semexplore_gym.config import ConfigError, to_dict
from semexplore_gym.config.extras import require_extra
from semexplore_gym.evaluation.errors import ParameterError

ALGOS = (
    "bc",
    "dagger",
    "ppo",
    "maskable_ppo",
    "frontier_value",
    "oracle_student",
    "option_ppo",
)


def add_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    from semexplore_gym.cli import describe

    p = sub.add_parser(
        "train",
        help="train a learning agent (BC, DAgger, PPO, MaskablePPO, a learned frontier value "
        "or the frontier student taught by the oracle)",
        description=describe(__doc__),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument(
        "--algo",
        required=True,
        choices=ALGOS,
        help="bc, dagger, ppo, maskable_ppo (macro-action envs), frontier_value (a learned "
        "frontier value for the expert, fitted by a cross-entropy method over missions) or "
        "oracle_student (a frontier chooser trained by DAgger on the oracle's labels) or "
        "option_ppo (MaskablePPO over every frontier option, a privileged critic)",
    )
    p.add_argument(
        "--train-config",
        default=None,
        help="agent config YAML: yours, or a shipped one (configs/agents/NAME.yml)",
    )
    p.add_argument("--out", required=True, help="run directory (created)")
    p.add_argument(
        "--train-set",
        dest="overrides",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="override a config key, e.g. bc.epochs=5 (repeatable)",
    )
    p.add_argument("--no-progress", action="store_true", help="no tqdm progress bars")
    add_json_flag(p, "the run's metrics (as in OUT/metrics.json) and the model's path")
    add_renamed_flag(p, "--config", "use --train-config FILE (agent training config YAML)")
    add_renamed_flag(p, "--set", "use --train-set KEY=VALUE (training config override)")
    return p


def _command_line(args: argparse.Namespace) -> str:
    """The ``semexplore train`` command that reproduces this run (also when called via ``main``)."""
    parts = ["semexplore", "train", "--algo", args.algo, "--out", str(args.out)]
    if args.train_config:
        parts += ["--train-config", str(args.train_config)]
    for text in args.overrides:
        parts += ["--train-set", text]
    if args.no_progress:
        parts.append("--no-progress")
    return shlex.join(parts)


def run(args: argparse.Namespace) -> int:
    if args.algo == "frontier_value":
        return _run_frontier_value(args)
    if args.algo == "oracle_student":
        return _run_oracle_student(args)
    if args.algo == "option_ppo":
        return _run_option_ppo(args)
    require_extra("rl", f"semexplore train --algo {args.algo}", "torch", "stable_baselines3")
    import torch

    from semexplore_gym.training.train_config import check_train_config, load_train_config

    try:
        cfg = load_train_config(args.train_config, args.overrides)
    except ConfigError as e:
        raise ValueError(str(e)) from e
    try:
        check_train_config(cfg, args.algo)
    except ParameterError as e:
        raise e.for_flags({"algo": "--algo"}) from None
    out = Path(args.out)
    _write_run_record(out, cfg, args)
    torch.set_num_threads(cfg.torch_threads)
    torch.manual_seed(cfg.seed)
    t0 = time.perf_counter()
    metrics = _train(cfg, args, out)
    metrics["total_s"] = time.perf_counter() - t0
    metrics["model"] = str(out / "model.zip")
    (out / "metrics.json").write_text(json.dumps(metrics, indent=2, default=float))
    print_result(args, {k: v for k, v in metrics.items() if k != "dagger_rounds"})
    return 0


def _run_frontier_value(args: argparse.Namespace) -> int:
    """``--algo frontier_value``: no torch; missions only (:mod:`~semexplore_gym.training.frontier_value_search`)."""
    from semexplore_gym.training.frontier_value_search import (
        load_frontier_value_config,
        train_frontier_value,
    )

    return _run_without_torch(args, load_frontier_value_config, train_frontier_value)


def _run_oracle_student(args: argparse.Namespace) -> int:
    """``--algo oracle_student``: no torch; DAgger on the oracle's labels
    (:mod:`~semexplore_gym.training.oracle_student`)."""
    from semexplore_gym.core.coverage_tour.tour import require_solver
    from semexplore_gym.training.oracle_student import (
        load_oracle_student_config,
        train_oracle_student,
    )

    try:
        require_solver()  # the teacher's tours; checked before any episode starts
    except ImportError as e:
        print(f"semexplore train --algo oracle_student: {e}", file=sys.stderr)
        return 2
    return _run_without_torch(args, load_oracle_student_config, train_oracle_student)


def _run_option_ppo(args: argparse.Namespace) -> int:
    """``--algo option_ppo``: BC then MaskablePPO over frontier options
    (:mod:`~semexplore_gym.training.option_ppo`)."""
    require_extra("rl", "semexplore train --algo option_ppo", "torch", "sb3_contrib")
    from functools import partial

    from semexplore_gym.training.option_ppo import load_option_ppo_config, train_option_ppo

    train = partial(train_option_ppo, progress=not args.no_progress)
    return _run_without_torch(args, load_option_ppo_config, train, "model.zip")


def _run_without_torch(
    args: argparse.Namespace, load: Any, train: Any, model: str = "model.yaml"
) -> int:
    """Load the config, write the run record, ``train(cfg, out, log=...)``, write
    ``metrics.json`` (its result, the wall time and ``model.yaml``'s path)."""
    try:
        cfg = load(args.train_config, args.overrides)
    except ConfigError as e:
        raise ValueError(str(e)) from e
    out = Path(args.out)
    _write_run_record(out, cfg, args)
    t0 = time.perf_counter()
    final = train(cfg, out, log=lambda line: print(line, flush=True))
    metrics = {"total_s": time.perf_counter() - t0, "model": str(out / model), **final}
    (out / "metrics.json").write_text(json.dumps(metrics, indent=2, default=float))
    print_result(args, metrics)
    return 0


def _write_run_record(out: Path, cfg: Any, args: argparse.Namespace) -> None:
    """``config.yaml`` (resolved) and ``args.json`` (arguments, argv, command line) in ``out``."""
    out.mkdir(parents=True, exist_ok=True)
    (out / "config.yaml").write_text(yaml.safe_dump(to_dict(cfg), sort_keys=False))
    (out / "args.json").write_text(
        json.dumps(
            {
                "args": {k: v for k, v in vars(args).items() if not k.startswith("_")},
                "process_argv": sys.argv,
                "command_line": _command_line(args),
            },
            indent=2,
        )
    )


def _train(cfg: Any, args: argparse.Namespace, out: Path) -> dict[str, Any]:
    progress = not args.no_progress
    if args.algo in ("ppo", "maskable_ppo"):
        from semexplore_gym.training.ppo import train_ppo

        return train_ppo(cfg, args.algo, out, progress)  # SB3's own logger writes out/tb/ppo_N
    from semexplore_gym.training.imitation import train_imitation
    from semexplore_gym.training.scalar_log import ScalarLogger

    log = ScalarLogger(out / "tb" / args.algo)
    try:
        return train_imitation(cfg, args.algo, out, log, progress)
    finally:
        log.close()
