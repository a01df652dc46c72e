"""Package layout: the repository keeps ``policies/`` and ``configs/`` at its top level; the
wheel installs them as ``semexplore_gym.policies`` (no generic top-level ``policies`` module in
site-packages) and ``semexplore_gym/configs`` (the env presets, expert parameters, agent
training configs and benchmark suites, found through ``importlib.resources``: see
``semexplore_gym/config/resources.py``). Everything else about the distribution is in
``pyproject.toml``."""

from setuptools import find_packages, setup

POLICIES = ["semexplore_gym." + name for name in find_packages(include=["policies", "policies.*"])]

setup(
    packages=find_packages(include=["semexplore_gym", "semexplore_gym.*"])
    + POLICIES
    + ["semexplore_gym.configs"],
    package_dir={"semexplore_gym.policies": "policies", "semexplore_gym.configs": "configs"},
)
