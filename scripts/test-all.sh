#!/usr/bin/env bash
# Sets up and runs every test of rendersim on a fresh machine:
#   - Python packages for the notebooks (in .venv, from notebooks/requirements.txt);
#   - one release build, reused by the unit, property and integration tests,
#     the experiments and the notebook;
#   - every experiment in experiments/ (its reference checks must pass);
#   - every notebook in notebooks/, executed headless.
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)

step() { printf '\n== %s\n' "$*"; }

step "Python environment for notebooks"
if [ ! -x .venv/bin/python ]; then
  python3 -m venv .venv
fi
.venv/bin/pip install --quiet --disable-pip-version-check -r notebooks/requirements.txt

step "Build (release, once)"
cargo build --release --locked --all-targets
export RENDERSIM_BIN="$root/target/release/rendersim"

step "Rust tests (unit, property, integration, doc)"
cargo test --release --locked --no-fail-fast 2>&1 | tee target/test-output.txt
grep -q "test result:" target/test-output.txt

step "Experiments"
mkdir -p out/ci
for f in experiments/*.toml; do
  name=$(basename "$f" .toml)
  echo "-- $name"
  "$RENDERSIM_BIN" experiment "$f" --out "out/ci/$name" --quiet | tail -n 3
done

step "Notebooks"
for nb in notebooks/*.ipynb; do
  [ -e "$nb" ] || continue
  echo "-- $nb"
  .venv/bin/jupyter execute "$nb"
done

step "Benchmarks (quick scale, printed for the log)"
"$RENDERSIM_BIN" bench all --scale 0.05

printf '\nall tests passed\n'
