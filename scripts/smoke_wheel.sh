#!/usr/bin/env bash
# The package as a user gets it: build the wheel, install it (not editable) in a fresh venv, and
# run the documented commands from a directory outside the repository, where nothing of the
# checkout can be imported or read. Proves that the wheel carries its data (configs, suites,
# pretrained models) and finds it through importlib.resources. No extra is installed (the
# core dependencies only): the commands that need one must say which in one line and exit 2;
# the tiny `train` is the torch-free frontier_value algorithm, run from the reproduce line that
# `semexplore pretrained` prints.
#
#   scripts/smoke_wheel.sh            # .ci/run calls it; about 3 min on 2 idle cores
#   PYTHON=python3.12 scripts/smoke_wheel.sh
set -euo pipefail
REPO=$(cd "$(dirname "$0")/.." && pwd)
PY=${PYTHON:-python}
WORK=$(mktemp -d "${TMPDIR:-/tmp}/semexplore-wheel.XXXXXX")
trap 'rm -rf "$WORK"' EXIT
step() { echo "[smoke_wheel $((SECONDS))s] $*"; }

step "build the wheel"
rm -rf "$REPO/build"  # files left in build/lib by an older tree would slip into the wheel
"$PY" -m pip wheel --no-deps --no-build-isolation -q -w "$WORK/dist" "$REPO"
rm -rf "$REPO/build"
WHEEL=$(ls "$WORK"/dist/semexplore_gym-*.whl)
# No top-level module besides the package (policies/ and configs/ live inside it).
"$PY" - "$WHEEL" <<'EOF'
import sys, zipfile
names = zipfile.ZipFile(sys.argv[1]).namelist()
tops = {n.split("/")[0] for n in names if not n.split("/")[0].endswith(".dist-info")}
assert tops == {"semexplore_gym"}, tops
for need in ("semexplore_gym/configs/suites/paper.yaml", "semexplore_gym/configs/expert/robust_paper_weights.yaml",
             "semexplore_gym/configs/agents/frontier_value.yml", "semexplore_gym/policies/pretrained/index.yaml"):
    assert need in names, need
EOF

step "install it in a fresh venv"
"$PY" -m venv "$WORK/venv"
VPY="$WORK/venv/bin/python"
"$VPY" -m pip install -q --disable-pip-version-check "$WHEEL"
export PATH="$WORK/venv/bin:$PATH"
unset PYTHONPATH  # nothing of the checkout
RUN="$WORK/run"
mkdir "$RUN"
cd "$RUN"

step "import from site-packages, no top-level policies"
"$VPY" - <<'EOF'
import importlib.util
import semexplore_gym
assert "site-packages" in semexplore_gym.__file__, semexplore_gym.__file__
assert importlib.util.find_spec("policies") is None
from semexplore_gym import load_suite, make_policy  # the public API
from semexplore_gym.config.resources import configs_dir
assert "site-packages" in str(configs_dir()), configs_dir()
# Every reproduce line's config is a shipped file (the torch-free one also runs below).
from semexplore_gym import pretrained_models
from semexplore_gym.config.resources import resolve_config_path
for m in pretrained_models():
    path = resolve_config_path(m.config)
    assert path.is_file() and "site-packages" in str(path), (m.name, path)
print(semexplore_gym.__version__, load_suite("paper").worlds[0].world, make_policy("semantic").name)
EOF
semexplore --version

step "semexplore explore (compiles the numba kernels once)"
semexplore explore --world maze1 --max-time-s 20 --no-progress
semexplore explore --world 'maze:seed=1,size_m=4' --policy-config configs/expert/paper_method.yaml \
  --max-time-s 10 --no-progress --json

step "semexplore benchmark --suite paper (tiny)"
semexplore benchmark --suite paper --policies semantic --runs 1 --max-time-s 10 --no-plots \
  --no-progress --out bench
test -s bench/runs.csv

step "semexplore pretrained"
semexplore pretrained
semexplore pretrained --json > pretrained.json
semexplore explore --world 'maze:seed=2,size_m=4' --policy pretrained:frontier_value --max-time-s 10 \
  --no-progress --json

step "a missing extra: one error line naming it, exit 2 (this venv has the core dependencies only)"
"$VPY" -c "import importlib.util as u; m = [n for n in ('torch', 'stable_baselines3', 'optuna', 'pettingzoo', 'ray') if u.find_spec(n)]; assert not m, m"
needs_extra() {  # needs_extra EXTRA semexplore ARGS...: exit 2, one stderr line naming EXTRA
  local extra=$1 rc=0
  shift
  "$@" --no-progress 2> err.txt || rc=$?
  if [ "$rc" -ne 2 ] || [ "$(grep -c . err.txt)" -ne 1 ] \
    || ! grep -qF "needs the '$extra' extra" err.txt || ! grep -qF "pip install 'semexplore-gym[$extra]'" err.txt; then
    echo "expected exit 2 and one line naming the '$extra' extra from: $* (exit $rc)"; cat err.txt; exit 1
  fi
}
needs_extra rl semexplore explore --world maze1 --policy pretrained:dagger_maze
needs_extra rl semexplore explore --world maze1 --policy sb3:x.zip
needs_extra multi semexplore explore --world maze1 --robots 2
needs_extra rl semexplore benchmark --policies pretrained:frontier_choice_maze --worlds maze1 --out extra1
needs_extra ray semexplore benchmark --policies semantic --worlds maze1 --backend ray --out extra2
needs_extra rl semexplore compare-weights --train-worlds maze1 --test-worlds maze2 --out extra3
"$VPY" -c "
from semexplore_gym import make_policy
from semexplore_gym.config.extras import MissingExtraError
try:
    make_policy('pretrained:dagger_maze')
except MissingExtraError as e:
    assert e.extra == 'rl' and \"semexplore-gym[rl]\" in str(e), e
else:
    raise AssertionError('make_policy loaded a torch model without torch')
"

step "semexplore train (tiny), from the reproduce line of pretrained:frontier_value"
REPRODUCE=$("$VPY" -c "import json; print(next(m['command'] for m in json.load(open('pretrained.json')) if m['name'] == 'frontier_value'))")
echo "$REPRODUCE"
read -ra CMD <<< "$REPRODUCE"  # plain words: semexplore train --algo ... --train-config configs/...
"${CMD[@]}" --no-progress --train-set generations=1 --train-set population=2 \
  --train-set elite=1 --train-set worlds_per_generation=1 --train-set workers=1 \
  --train-set max_time_s=5 --train-set 'worlds=["maze:seed=*,size_m=4"]'
test -s runs/frontier_value/model.yaml

step "ok"
