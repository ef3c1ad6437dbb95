#!/usr/bin/env bash
# Sets up and runs every test of rendersim on a fresh machine:
#   - Python packages for the notebooks (in .venv, from notebooks/requirements.txt);
#   - the Python package (python/, built from source into .venv) and its pytest tests;
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

# Without XDG_RUNTIME_DIR, Mesa's device-selection layer makes libwayland
# print "error: XDG_RUNTIME_DIR is invalid or not set" on every Vulkan
# instance the tests open in-process; its own switch turns it off (the
# binary does the same by itself, see src/main.rs; a test checks that).
if [ -z "${XDG_RUNTIME_DIR:-}" ] && [ -z "${WAYLAND_DISPLAY:-}" ]; then
  export NODEVICE_SELECT=1
fi

step "Python environment for notebooks"
# A venv left half made by an interrupted run has python but no pip: remake it.
if [ ! -x .venv/bin/pip ]; then
  rm -rf .venv
  python3 -m venv .venv
fi
.venv/bin/pip install --quiet --disable-pip-version-check -r notebooks/requirements.txt

step "Build (release, once, with the wgpu measurement feature)"
# Everything the tests write goes into a temp folder made here, removed at
# the end (set RENDERSIM_KEEP_CI_OUT=1 to keep it for a look).
ci_out=$(mktemp -d "${TMPDIR:-/tmp}/rendersim-ci.XXXXXX")
if [ -z "${RENDERSIM_KEEP_CI_OUT:-}" ]; then
  trap 'rm -rf "$ci_out"' EXIT
else
  echo "outputs kept in $ci_out"
fi
cargo build --release --locked --workspace --all-targets --features wgpu
export RENDERSIM_BIN="$root/target/release/rendersim"

step "Formatting and lints (cargo fmt --check; clippy and rustdoc with warnings as errors)"
for tool in rustfmt clippy; do
  cargo "${tool/rustfmt/fmt}" --version >/dev/null 2>&1 || rustup component add "$tool" || true
done
if cargo fmt --version >/dev/null 2>&1; then cargo fmt --all --check; else echo "rustfmt unavailable: skipped"; fi
if cargo clippy --version >/dev/null 2>&1; then
  cargo clippy --release --locked --workspace --all-targets --features wgpu -- -D warnings
else
  echo "clippy unavailable: skipped"
fi
# The API documentation builds without a warning (a broken or private link
# fails); it reuses clippy's checked dependencies (about 16 s here).
RUSTDOCFLAGS="-D warnings" cargo doc --release --locked --no-deps --workspace --features wgpu

step "Rust tests (unit, property, integration, doc; wgpu measurements on lavapipe)"
# (The fuzz test runs in its own step below, so that its counts are shown.)
cargo test --release --locked --no-fail-fast --workspace --features wgpu -- --skip every_input_ends_in_a_result_or_a_clean_error 2>&1 | tee "$ci_out/test-output.txt"
grep -q "test result:" "$ci_out/test-output.txt"

step "Fuzz: 2,000 seeded leaf-value cases (models, --set values, meshes, experiments), 1,000 text-damage cases of every file kind read (models, devices, experiments, CSVs, instances, meshes, shard files), plus the regression cases"
cargo test --release --locked --features wgpu --test it fuzz:: -- --nocapture

step "Examples (each asserts what it shows)"
for ex in examples/*.rs crates/*/examples/*.rs; do
  name=$(basename "$ex" .rs)
  echo "-- $name"
  "target/release/examples/$name" | tail -n 2
done

step "Python package: built from source (pip install ./python) and its tests (pytest)"
# The package's build backend (python/build_backend/rendersim_build.py)
# shares the checkout's target folder, so the release build's crates are
# reused: PyO3, the bindings and rendersim's own crates are compiled.
.venv/bin/pip install --quiet --disable-pip-version-check ./python
.venv/bin/pytest -q -p no:cacheprovider --basetemp "$ci_out/pytest" python/tests
# The native module's stubs against the module, and the package's own
# annotations type-checked (mypy's stubtest; its cache in the temp folder).
.venv/bin/pip install --quiet --disable-pip-version-check -r python/requirements-check.txt
(cd "$ci_out" && "$root/.venv/bin/python" -m mypy.stubtest rendersim)

step "Browser: rendersim explore in headless Chromium (Debian's chromium and chromium-driver, driven by Selenium)"
if [ ! -x /usr/bin/chromium ] || [ ! -x /usr/bin/chromedriver ]; then
  if command -v apt-get >/dev/null 2>&1 && [ "$(id -u)" = 0 ]; then
    apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium chromium-driver >/dev/null
  else
    echo "note: cannot install chromium and chromium-driver here (not root or no apt-get); the browser test skips itself"
  fi
fi
.venv/bin/pip install --quiet --disable-pip-version-check -r tests/browser/requirements.txt
# Screenshots into the CI folder; the test prints the redraw times.
RENDERSIM_SCREENSHOTS="$ci_out/screenshots" .venv/bin/pytest -q -s -p no:cacheprovider -rs \
  --basetemp "$ci_out/pytest-browser" tests/browser

step "Studies H1-H4 on this machine's adapter (H1 must predict its validation meshes exactly)"
if ls /usr/share/vulkan/icd.d/*.json >/dev/null 2>&1; then
  # --require-exact: on lavapipe an inexact H1 is a regression, not a finding.
  if ! "$RENDERSIM_BIN" study all --require-exact --markdown "$ci_out/studies.md" --csv "$ci_out/study-passes.csv" \
      > "$ci_out/studies.txt" 2> "$ci_out/studies.err"; then
    cat "$ci_out/studies.txt" "$ci_out/studies.err"
    exit 1
  fi
  head -n 4 "$ci_out/studies.txt"
  echo "$(($(wc -l < "$ci_out/study-passes.csv") - 1)) measured passes in the pass CSV; the machine's load while measuring:"
  cat "$ci_out/study-passes.csv.load.csv"
  # A device profile fitted afresh on a designed set of passes (`study
  # profile`: 135 passes, one process, 9 interleaved rounds, the median
  # kept): each pass predicted by a fit to the others (reported), and a fit
  # on a fixed half predicting the other half (checked: median |error| at
  # most 15%, 90th percentile at most 30%; measured here: 6-11% and 20-25%
  # over five runs). The machine's load while measuring is printed with it.
  "$RENDERSIM_BIN" study profile --csv "$ci_out/profile-passes.csv" > "$ci_out/profile.txt" 2> "$ci_out/profile.err" \
    || { cat "$ci_out/profile.txt" "$ci_out/profile.err"; exit 1; }
  head -n 1 "$ci_out/profile.txt"
  cat "$ci_out/profile-passes.csv.load.csv"
  "$RENDERSIM_BIN" calibrate "$ci_out/profile-passes.csv" --out "$ci_out/llvmpipe.toml" \
    --vertex-cache lavapipe --loo --kfold 5 --holdout --holdout-max-median 15 --holdout-max-p90 30 \
    > "$ci_out/calibrate.txt" 2> "$ci_out/calibrate.err" \
    || { cat "$ci_out/calibrate.txt" "$ci_out/calibrate.err"; exit 1; }
  grep -E '^(fit|leave-one-out|linear baseline|k-fold by mesh|held-out half)' "$ci_out/calibrate.txt"
  # A pass the profile was not fitted on (a mesh, and loops, it did not
  # measure), predicted and measured in one run (the prediction's error,
  # and measuring vs simulating wall time).
  "$RENDERSIM_BIN" predict grid:64x64 --device "$ci_out/llvmpipe.toml" --size 256x256 \
    --vs-loops 50 --fs-loops 20 --measure 2>/dev/null
else
  echo "no Vulkan driver installed: studies skipped"
fi

step "Rendering-time estimation on this machine's adapter (h1-h4 and pos; 1000 single-, 300 multi-object passes)"
if ls /usr/share/vulkan/icd.d/*.json >/dev/null 2>&1; then
  # 10-13 s on lavapipe on the 2-core machine (1,412 passes x 5 rounds).
  "$RENDERSIM_BIN" study estimation --single 1000 --multi 300 --repeats 5 --markdown "$ci_out/estimation.md" \
    --csv "$ci_out/estimation-passes.csv" > "$ci_out/estimation.txt" 2> "$ci_out/estimation.err" \
    || { cat "$ci_out/estimation.txt" "$ci_out/estimation.err"; exit 1; }
  grep -m 1 -F '**Verdict.**' "$ci_out/estimation.md"
else
  echo "no Vulkan driver installed: estimation study skipped"
fi

step "Experiments"
for f in experiments/*.toml; do
  name=$(basename "$f" .toml)
  echo "-- $name"
  "$RENDERSIM_BIN" experiment "$f" --out "$ci_out/$name" --quiet | tail -n 3
done

step "Notebooks (committed with their outputs; each executed again here, printing the same text)"
.venv/bin/python - notebooks/*.ipynb <<'PY'
import json, sys
for path in sys.argv[1:]:
    cells = [c for c in json.load(open(path))["cells"] if c["cell_type"] == "code"]
    bare = [i for i, c in enumerate(cells) if c.get("execution_count") is None]
    if bare:
        sys.exit(f"{path}: code cells {bare} have no outputs; run jupyter nbconvert --to notebook --execute --inplace {path}")
print(f"{len(sys.argv) - 1} notebooks carry their outputs")
PY
# Executed again into the CI folder; the text each cell prints must be the
# text committed (scripts/notebook-outputs.py: pictures aside).
mkdir -p "$ci_out/notebooks"
for nb in notebooks/*.ipynb; do
  [ -e "$nb" ] || continue
  echo "-- $nb"
  .venv/bin/jupyter nbconvert --log-level WARN --to notebook --execute --output-dir "$ci_out/notebooks" "$nb"
  .venv/bin/python scripts/notebook-outputs.py "$nb" "$ci_out/notebooks/$(basename "$nb")"
done

step "Slurm: a 4-task job array and its merge on a one-machine Slurm, compared with one process"
if [ "$(id -u)" = 0 ]; then
  bash scripts/slurm-test.sh
else
  echo "skipped: the one-machine Slurm needs root (slurmd runs as root; installing slurm-wlm and munge needs apt-get)"
fi

step "Device script: bash -n, and its dry run lists the commands"
bash -n scripts/device-studies.sh
DRY_RUN=1 bash scripts/device-studies.sh collect "$ci_out/device" | tail -n 3

step "Benchmarks (quick scale, printed for the log)"
"$RENDERSIM_BIN" bench all --scale 0.05

printf '\nall tests passed\n'
