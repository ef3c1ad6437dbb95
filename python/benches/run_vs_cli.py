"""The Python package's run() of the default model against the command
line's `rendersim run --out` of the same model, pair by pair in one
process (the target: at most 5% over the CLI); then run()'s overhead over
its own simulation on 200,000 frames of models/fixed.toml, the frames
handed to pandas (issue 58's target: at most 20%). Usage, after
`pip install ./python` and `cargo build --release`:

    python python/benches/run_vs_cli.py [PAIRS]

RENDERSIM_BIN names the binary (default target/release/rendersim)."""

import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import rendersim

ROOT = Path(__file__).resolve().parents[2]
exe = os.environ.get("RENDERSIM_BIN") or str(ROOT / "target" / "release" / "rendersim")
pairs = int(sys.argv[1]) if len(sys.argv) > 1 else 5
py, lib, cli, ratios = [], [], [], []
rendersim.run(frames=30)  # warm-up: the module's pages, pandas
for _ in range(pairs):
    with tempfile.TemporaryDirectory() as d:
        t0 = time.perf_counter()
        r = rendersim.run()
        t1 = time.perf_counter()
        subprocess.run([exe, "run", "--out", os.path.join(d, "o")], check=True, capture_output=True)
        t2 = time.perf_counter()
    py.append(t1 - t0)
    lib.append(r.summary["wall_seconds"])
    cli.append(t2 - t1)
    ratios.append((t1 - t0) / (t2 - t1))


def mmm(v):
    return f"min {min(v):.3f}  median {statistics.median(v):.3f}  max {max(v):.3f}"


print(f"python rendersim.run() s:        {mmm(py)}")
print(f"  of which the library (wall) s:  {mmm(lib)}")
print(f"rendersim run --out (process) s:  {mmm(cli)}")
print(f"ratio python / CLI, pair by pair: {mmm(ratios)}")


# run() against the simulation inside it (the summary's wall_seconds): what
# the frames cost on their way to a DataFrame, and the rest of the call.
overhead = []
for _ in range(pairs):
    t0 = time.perf_counter()
    big = rendersim.run(ROOT / "models" / "fixed.toml", frames=200_000)
    t1 = time.perf_counter()
    overhead.append(100 * ((t1 - t0) / big.summary["wall_seconds"] - 1))
print(f"run() over its simulation, 200,000 frames, %: {mmm(overhead)}  (target: at most 20)")
