"""Training runners above envs and policies: imitation datasets, BC, DAgger, PPO, weight tuning.

Modules, in dependency order: ``dataset`` (``.npz`` imitation datasets), ``episodes`` (one
labelled roll-out), ``workers`` (per-episode random streams and the process pool),
``recording`` (expert datasets), ``learner`` (a fresh SB3 learner; model zips), ``bc``,
``dagger``, ``weight_tuning`` (Optuna). Only the CLI and scripts import this package.
"""
