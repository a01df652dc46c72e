"""Package layout: the repository keeps ``policies/`` at its top level, the wheel installs it as
``semexplore_gym.policies`` (no generic top-level ``policies`` module in site-packages).
Everything else about the distribution is in ``pyproject.toml``."""

from setuptools import find_packages, setup

POLICIES = ["semexplore_gym." + name for name in find_packages(include=["policies", "policies.*"])]

setup(
    packages=find_packages(include=["semexplore_gym", "semexplore_gym.*"]) + POLICIES,
    package_dir={"semexplore_gym.policies": "policies"},
)
