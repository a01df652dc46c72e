"""Benchmark harness, figures and summaries (above envs and policies; used by the CLI)."""
