#!/bin/bash
# Compares the outputs of two rendersim binaries on 20 `draw`-fidelity
# variants of the shipped models (GPU noise, vsync off, mailbox, FIFOs of
# 0, 1 and 8 entries and 64 KiB, one and four frames in flight, binning,
# unified, run.until, run.max_events, and six other models): every file
# of `run --out` must be identical but for wall-clock fields and the event
# counts. Used to check that a speed change leaves every result as it was.
#
#   scripts/compare-draw-outputs.sh OLD_BINARY NEW_BINARY
#
# Writes only inside a temporary folder it creates and removes.
set -u
A=${1:?old binary}; B=${2:?new binary}
root=$(cd "$(dirname "$0")/.." && pwd)
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
n=0; bad=0
strip() { # a run's files without wall-clock fields and event counts
  for f in "$1"/*; do
    grep -v '"build_seconds"\|"events_per_second"\|"simulate_seconds"\|"wall_seconds"\|"gpu_front_end"\|"total"\|cpu_seconds\|"seconds"\|cost_us' "$f"
  done
}
run() { # name model sets...
  local name=$1 model=$2; shift 2
  local sets=(); for s in "$@"; do sets+=(--set "$s"); done
  for side in a b; do
    local bin=$A; [ $side = b ] && bin=$B
    if ! "$bin" run "$root/models/$model.toml" --set 'fidelity="draw"' "${sets[@]}" --out "$tmp/$side/$name" >/dev/null 2>"$tmp/$side-$name.err"; then
      echo "FAILED $side $name: $(tail -n 1 "$tmp/$side-$name.err")"
    fi
  done
  n=$((n + 1))
  if [ ! -f "$tmp/a/$name/summary.json" ] || [ ! -f "$tmp/b/$name/summary.json" ]; then
    echo "MISSING $name"; bad=$((bad + 1)); return
  fi
  if ! diff <(strip "$tmp/a/$name") <(strip "$tmp/b/$name") >/dev/null; then
    echo "DIFFER $name"; bad=$((bad + 1))
  fi
}
run base default 'run.frames=600'
run gpu-noise default 'run.frames=600' 'noise.periodic.0.target="gpu"' 'noise.random.0.target="gpu"' 'noise.random.0.rate="300Hz"'
run no-vsync default 'run.frames=600' 'display.vsync=false'
run fifo-8 default 'run.frames=600' 'command_fifo.capacity=8'
run fifo-0 default 'run.frames=300' 'command_fifo.capacity=0'
run fifo-1 default 'run.frames=300' 'command_fifo.capacity=1'
run ahead-1 default 'run.frames=600' 'cpu.max_frames_ahead=1'
run ahead-4 default 'run.frames=600' 'cpu.max_frames_ahead=4'
run mailbox default 'run.frames=600' 'display.present_mode="mailbox"' 'display.buffers=3'
run fifo-bytes default 'run.frames=300' 'command_fifo.unit="bytes"' 'command_fifo.capacity=65536'
run until default 'run.frames=600' 'run.until="1.2345s"'
run max-events default 'run.frames=600' 'run.max_events=33333'
run binning default 'run.frames=300' 'gpu.fragment.binning="draw"'
run unified default 'run.frames=300' 'gpu.architecture="unified"'
run city city 'run.frames=200'
run terrain terrain 'run.frames=200'
run single-view single-view 'run.frames=200'
run walkthrough-city walkthrough-city 'run.frames=200'
run walkthrough-forest walkthrough-forest 'run.frames=200'
run one-mesh one-mesh 'run.frames=200'
echo "$n variants, $bad differ"
[ "$bad" -eq 0 ]
