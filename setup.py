"""Package layout: the repository keeps ``policies/`` and ``configs/`` at its top level; the
wheel installs them as ``semexplore_gym.policies`` (no generic top-level ``policies`` module in
site-packages) and ``semexplore_gym/configs`` (the env presets, expert parameters, agent
training configs and benchmark suites, found through ``importlib.resources``: see
``semexplore_gym/config/resources.py``). Everything else about the distribution is in
``pyproject.toml``.

The data folders (``configs/suites``, ``policies/pretrained/<model>`` ...) are listed as
namespace packages too: they hold no Python, but Python could import them, and setuptools warns
at length about every importable folder left out of ``packages``. Their files are the package
data that ``pyproject.toml`` lists."""

from setuptools import find_namespace_packages, find_packages, setup

NO_CACHE = ["*__pycache__*"]
POLICIES = ["semexplore_gym." + name for name in find_packages(include=["policies", "policies.*"])]
MODEL_FOLDERS = [
    "semexplore_gym." + name
    for name in find_namespace_packages(include=["policies.pretrained.*"], exclude=NO_CACHE)
]
CONFIG_FOLDERS = [
    "semexplore_gym.configs." + name
    for name in find_namespace_packages(where="configs", exclude=NO_CACHE)
]

setup(
    packages=find_packages(include=["semexplore_gym", "semexplore_gym.*"])
    + POLICIES
    + MODEL_FOLDERS
    + ["semexplore_gym.configs"]
    + CONFIG_FOLDERS,
    package_dir={"semexplore_gym.policies": "policies", "semexplore_gym.configs": "configs"},
)
