#!/usr/bin/env bash
# Type-check the package as it is installed: mypy cannot follow setup.py's mapping of the
# top-level policies/ folder to semexplore_gym.policies, so this builds a shadow tree of
# symbolic links (semexplore_gym/ with policies/ inside it) and runs mypy there with the
# project's settings. Paths in the report are the repository's own.
# Usage: scripts/typecheck.sh [extra mypy arguments]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
shadow=$(mktemp -d)
trap 'rm -rf "$shadow"' EXIT
cp -rs "$root/semexplore_gym" "$shadow/semexplore_gym"
rm -rf "$shadow/semexplore_gym/policies"
cp -rs "$root/policies" "$shadow/semexplore_gym/policies"
find "$shadow" -name __pycache__ -prune -exec rm -rf {} +
cd "$shadow"
status=0
python -m mypy --config-file "$root/pyproject.toml" semexplore_gym "$@" > report.txt 2>&1 || status=$?
sed -e "s#^semexplore_gym/policies/#policies/#" report.txt
exit "$status"
