#!/usr/bin/env bash
# Interrupts rendersim at spread moments and counts what is left behind.
#   scripts/interrupt-stress.sh [BINARY] [TRIALS]
# - TRIALS runs of `run --out DIR --trace FILE` and TRIALS of `experiment
#   --out DIR`, each sent SIGTERM after a random delay within its usual run
#   time (the commit window included);
# - TRIALS/4 rounds of six runs started at once into one absent folder.
# Prints, per kind, how many ended by the signal, how many finished, and how
# many left a temporary file (.NAME.partial-PID, .NAME.tmp-PID, .NAME.old-PID)
# or an incomplete set. Everything happens in a temp folder it removes.
set -euo pipefail
bin=${1:-target/release/rendersim}
bin=$(realpath "$bin")
trials=${2:-100}
work=$(mktemp -d "${TMPDIR:-/tmp}/rendersim-stress.XXXXXX")
# Removed by this shell only (a subshell that ran the trap would take the
# folder from under the rounds still running).
main_pid=$$
trap '[ "$BASHPID" = "$main_pid" ] && rm -rf "$work"' EXIT
cd "$work"
printf '[run]\nframes = 3000\n[noise]\nenabled = false\n[workload]\nkind = "fixed"\ncpu = "2ms"\ngpu = "9ms"\n' > m.toml
printf 'name = "e"\nmodel = "m.toml"\nreplications = 6\n[set]\n"run.frames" = 300\n[[metric]]\npath = "metrics.frame_time_ms.mean"\n' > e.toml
leftovers() { find . -name '.*.partial-*' -o -name '.*.tmp-*' -o -name '.*.old-*' | wc -l; }
span_us() { local t0 t1; t0=$(date +%s%N); "$@" >/dev/null 2>&1; t1=$(date +%s%N); echo $(( (t1 - t0) / 1000 )); }
stress() {
  local kind=$1; shift
  local span signalled=0 finished=0 left=0 i
  span=$(span_us "$@")
  for ((i = 0; i < trials; i++)); do
    "$@" >/dev/null 2>&1 &
    local pid=$!
    sleep "$(awk -v s="$span" -v r="$RANDOM" 'BEGIN { printf "%.6f", s * 1.25 * r / 32768 / 1e6 }')"
    kill -TERM "$pid" 2>/dev/null || true
    local rc=0
    wait "$pid" || rc=$?
    if [ "$rc" = 0 ]; then finished=$((finished + 1)); else signalled=$((signalled + 1)); fi
    local n; n=$(leftovers)
    if [ "$n" != 0 ]; then left=$((left + 1)); find . -name '.*.partial-*' -o -name '.*.tmp-*' -o -name '.*.old-*' | xargs rm -rf; fi
  done
  echo "$kind: $trials trials (run takes ${span} us): $signalled ended by SIGTERM, $finished finished, $left left a temporary file"
}
stress "run --out --trace" "$bin" run m.toml --out out --trace out-trace.json
stress "run --out (trace inside)" "$bin" run m.toml --out out --trace out/trace.json
stress "experiment --out" "$bin" experiment e.toml --quiet --out eout
rounds=$((trials / 4)) failed=0
for ((r = 0; r < rounds; r++)); do
  pids=()
  for s in 1 2 3 4 5 6; do "$bin" run m.toml --seed "$s" --out "c$r/new/out" >/dev/null 2>"err-$r-$s" & pids+=($!); done
  for p in "${pids[@]}"; do wait "$p" || failed=$((failed + 1)); done
done
echo "concurrent: $rounds rounds of 6 runs into one absent folder: $failed runs failed, $(leftovers) temporary files left"
