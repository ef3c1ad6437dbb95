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

step "System packages: Mesa's lavapipe (Vulkan on the CPU) for the wgpu measurements"
if ! ls /usr/share/vulkan/icd.d/lvp_icd*.json >/dev/null 2>&1; then
  if command -v apt-get >/dev/null 2>&1 && [ "$(id -u)" = 0 ]; then
    apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq mesa-vulkan-drivers libvulkan1 >/dev/null
  else
    echo "note: cannot install mesa-vulkan-drivers here (not root or no apt-get); measurement tests will report a missing adapter"
  fi
fi

step "Python environment for notebooks"
if [ ! -x .venv/bin/python ]; then
  python3 -m venv .venv
fi
.venv/bin/pip install --quiet --disable-pip-version-check -r notebooks/requirements.txt

step "Build (release, once, with the wgpu measurement feature)"
mkdir -p out/ci
cargo build --release --locked --all-targets --features wgpu
export RENDERSIM_BIN="$root/target/release/rendersim"

step "Rust tests (unit, property, integration, doc; wgpu measurements on lavapipe)"
cargo test --release --locked --no-fail-fast --features wgpu 2>&1 | tee target/test-output.txt
grep -q "test result:" target/test-output.txt

step "Studies H1-H4 on this machine's adapter (H1 must predict its validation meshes exactly)"
if ls /usr/share/vulkan/icd.d/*.json >/dev/null 2>&1; then
  if ! "$RENDERSIM_BIN" study all --markdown out/ci/studies.md > out/ci/studies.txt 2> out/ci/studies.err; then
    cat out/ci/studies.txt out/ci/studies.err
    exit 1
  fi
  head -n 4 out/ci/studies.txt
else
  echo "no Vulkan driver installed: studies skipped"
fi

step "Experiments"
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
