"""Missions and benchmarks: ``rollout`` (one mission, its metrics), ``harness``, ``report``.

Above envs and policies; used by the CLI, the scripts and ``semexplore_gym.training``.
"""
