#!/usr/bin/env bash
# Everything a later session needs from a machine with a real GPU, measured
# in one run, for sessions that are lent one (the `device` tool; it has no
# network, so everything travels from here).
#
#   bash scripts/device-studies.sh prepare   # here: build dist/rendersim, fetch the Vulkan loader
#                                            # and the GL dispatch libraries NVIDIA's driver needs into .gl/
#   # then, with the device tool: carry ["dist", ".gl"], timeout_s 600, command:
#   #   bash scripts/device-studies.sh run   # installs .gl/, then `collect "$OUT"`
#   # and copy $OUT/* into docs/measurements/<adapter>/.
#
#   bash scripts/device-studies.sh collect DIR   # the measurements alone, into DIR (any machine with Vulkan)
#
# `collect` writes into DIR (see the README.md it writes there):
#   adapter.json adapter.txt              the adapter as wgpu reports it; nvidia-smi, uname, rendersim version
#   studies.md studies.json studies.err   `rendersim study all` (an inexact H1 is a finding: exit status 0)
#   studies-passes.csv                    every pass the studies measured (pass CSV format)
#   estimation.md estimation.json         `rendersim study estimation` (h1-h4 and pos fitted on measured
#   estimation-passes.csv estimation.err  single-object passes, scored on multi-object passes; one CSV row per object)
#   profile.md profile-passes.csv         `rendersim study profile`: 135 designed passes for `calibrate`
#   profile.err                           (short, no-draw and many-draw passes among them), rounds interleaved
#   load-grid.csv                         the passes of docs/measurements/nvidia-h200/load-grid.csv
#   fixed-costs.csv                       passes of no draw (3 sizes), and grid:32x32 and grid:256x256 at
#                                         128x128 in 1, 4, 16, 64, 256 and 4096 draws (a profile's
#                                         pass_overhead_ns and draw_ns)
#   load-sweep.csv                        every pass of the H200 sweep's lists (6 meshes x 3 sizes x 7 loads),
#                                         the rows the shared file held out included, less the capped ones
#   vertex-reuse.csv corpus-passes.csv    VS invocations of each corpus/*.idx (one draw, 256x256)
#   skipped.txt                           passes left out (capped, timed out, past the deadline) and why
#   commands.txt                          every command run, with its exit status and seconds
#
# Budget: about 3 minutes on an H200 (estimated from the shared pass times:
# sweep and grid passes about 25 s of GPU time at 7 passes each, the random
# mesh's heavy passes about 45 s at 4 passes each, ~190 processes at ~0.3 s
# each, the studies about 10 s); every measurement is limited to
# PASS_TIMEOUT seconds (60) and no new one starts after DEADLINE seconds
# (450), so a slower device still ends within the device tool's 10 minutes.
# The estimation study (1,412 passes x 5 rounds at --load-scale
# EST_LOAD_SCALE, default 10: loop counts from the H200 files' ns per loop,
# at most ~1 ms per object there) is estimated at under 30 s and limited to
# 240 s.
#
# Environment: RENDERSIM (binary; default dist/rendersim, else
# target/release/rendersim), QUICK=1 (a scaled-down run for lavapipe: small
# meshes and targets, loop counts / 100, H1 only, one pass per measurement),
# DRY_RUN=1 (print the commands, measure nothing), PASS_TIMEOUT, DEADLINE,
# CORPUS (default docs/measurements/nvidia-h200/corpus), EST_LOAD_SCALE
# (the estimation study's --load-scale; QUICK=1: 1, with 100 single and 30
# multi-object passes, one round).
set -euo pipefail
cd "$(dirname "$0")/.."

# Packages NVIDIA's Vulkan driver needs on the lent machine
# (../shared/notes/vulkan-on-the-gpu-machine.md).
DEBS="libvulkan1 libegl1 libglvnd0 libopengl0 libgl1 libglx0 libgles2"

collect() {
  local dir=$1
  local bin=${RENDERSIM:-}
  if [ -z "$bin" ]; then
    if [ -x dist/rendersim ]; then bin=dist/rendersim; else bin=target/release/rendersim; fi
  fi
  local quick=${QUICK:-} dry=${DRY_RUN:-}
  local pass_timeout=${PASS_TIMEOUT:-60} deadline=${DEADLINE:-450}
  local corpus=${CORPUS:-docs/measurements/nvidia-h200/corpus}
  local start=$SECONDS

  # The lists of the shared H200 files (docs/measurements/nvidia-h200/README.md).
  local grid_mesh=grid:96x96:optimized grid_size=384x384
  local grid_vs=(0 2000 67390) grid_fs=(0 500 2000 7681)
  local extra_meshes=(grid:256x256 grid:32x32) extra_sizes=(64x64 1024x1024)
  local fixed_meshes=(grid:32x32 grid:256x256) fixed_sizes=(128x128 512x512 2048x2048)
  local fixed_draws=(1 4 16 64 256 4096)
  local sweep_meshes=(grid:32x32 grid:96x96:optimized grid:256x256 grid:64x64:shuffled:1 strip:64x64 random:30000:5000:7)
  local sweep_sizes=(128x128 512x512 2048x2048)
  local sweep_loads=("0 0" "1000 0" "0 300" "1000 300" "10000 3000" "1000 0 geo" "10000 0 geo")
  local passes=(--repeats 5 --warmup 2) heavy_passes=(--repeats 3 --warmup 1)
  local study=all corpus_files
  local est_args=(--load-scale "${EST_LOAD_SCALE:-10}" --repeats 5)
  local profile_args=(--repeats 9)
  corpus_files=$(ls "$corpus"/*.idx 2>/dev/null || true)
  if [ -n "$quick" ]; then
    grid_mesh=grid:16x16:optimized grid_size=64x64
    grid_vs=(0 20 670) grid_fs=(0 5 77)
    extra_meshes=(grid:8x8 grid:4x4) extra_sizes=(32x32 64x64)
    fixed_meshes=(grid:8x8) fixed_sizes=(32x32 64x64) fixed_draws=(1 4 256)
    sweep_meshes=(grid:16x16 strip:8x8 random:300:50:7)
    sweep_sizes=(32x32 64x64)
    sweep_loads=("0 0" "10 0" "0 3" "10 3" "100 30" "10 0 geo" "100 0 geo")
    passes=(--repeats 1 --warmup 0) heavy_passes=(--repeats 1 --warmup 0)
    study=h1
    est_args=(--load-scale "${EST_LOAD_SCALE:-1}" --single 100 --multi 30 --repeats 1)
    profile_args=(--repeats 1)
    corpus_files=$(printf '%s\n' $corpus_files | head -n 4)
  fi

  # A pass left out, and why: into skipped.txt (printed in a dry run).
  note() {
    if [ -n "$dry" ]; then echo "# skipped: $1"; else echo "$1" >> "$dir/skipped.txt"; fi
  }

  # Runs "$@" limited to $1 seconds (when coreutils' timeout is there).
  limit() {
    local secs=$1; shift
    if command -v timeout >/dev/null 2>&1; then timeout --kill-after=10 "$secs" "$@"; else "$@"; fi
  }

  # Runs one command (its stdout into $1, or /dev/null), limited to $2
  # seconds; logs it. Returns the command's status (124: timed out).
  run_one() {
    local out=$1 limit=$2; shift 2
    local t0=$SECONDS rc=0
    if [ -n "$dry" ]; then
      printf '%s > %s\n' "$*" "$out"
      return 0
    fi
    limit "$limit" "$@" > "$out" 2>> "$dir/stderr.txt" || rc=$?
    printf '%s\t# exit %s, %s s\n' "$*" "$rc" "$((SECONDS - t0))" >> "$dir/commands.txt"
    return "$rc"
  }

  # One `rendersim measure` whose row goes to $1 (skipped past the deadline).
  measure() {
    local csv=$1; shift
    if [ $((SECONDS - start)) -ge "$deadline" ]; then
      note "rendersim measure $*: not run, past the ${deadline} s deadline"
      return 0
    fi
    local rc=0
    run_one /dev/null "$pass_timeout" "$bin" measure "$@" --csv "$csv" || rc=$?
    if [ "$rc" = 124 ] || [ "$rc" = 137 ]; then
      echo "rendersim measure $*: timed out after ${pass_timeout} s" >> "$dir/skipped.txt"
    elif [ "$rc" != 0 ]; then
      echo "rendersim measure $*: failed with status $rc (see stderr.txt)" >> "$dir/skipped.txt"
    fi
  }

  # A load "VS FS [geo]" as measure options.
  load_args() {
    local vs=$1 fs=$2 geo=${3:-}
    printf -- '--vs-loops %s --fs-loops %s%s' "$vs" "$fs" "${geo:+ --geometry-only}"
  }

  # The random mesh's passes with heavy fragment loads at large targets
  # take 36 s to 10 minutes each on an H200 (load-sweep.csv: 2.5 s at
  # 512x512 with 300 fragment loops); they are left out.
  capped() {
    local mesh=$1 size=$2 fs=$3 geo=${4:-}
    [[ $mesh == random:* ]] || return 1
    [ -z "$geo" ] || return 1
    { [ "$size" = 512x512 ] && [ "$fs" -ge 3000 ]; } || { [ "$size" = 2048x2048 ] && [ "$fs" -gt 0 ]; }
  }

  if [ -n "$dry" ]; then echo "# DRY_RUN: the commands collect would run, into $dir"; else mkdir -p "$dir"; : > "$dir/skipped.txt"; : > "$dir/commands.txt"; fi

  # 1. The adapter.
  if [ -z "$dry" ]; then
    {
      echo "date: $(date -u +%Y-%m-%dT%H:%M:%SZ)"
      echo "rendersim: $("$bin" --version 2>&1)"
      echo "commit: $(cat dist/COMMIT 2>/dev/null || git rev-parse HEAD 2>/dev/null || echo unknown)"
      echo "uname: $(uname -a)"
      echo "VK_DRIVER_FILES: ${VK_DRIVER_FILES:-}"
      if command -v nvidia-smi >/dev/null 2>&1; then
        nvidia-smi -L || true
        nvidia-smi --query-gpu=name,driver_version,memory.total,clocks.max.sm,clocks.max.mem --format=csv || true
      fi
    } > "$dir/adapter.txt" 2>&1
  fi
  run_one "$dir/adapter.json" 120 "$bin" measure grid:1x1 --size 64x64 --repeats 1 --warmup 0 --json || true

  # 2. The studies (an inexact H1 is a finding, exit status 0; no --require-exact).
  local study_rc=0
  if [ -n "$dry" ]; then
    echo "$bin study $study --repeats 5 --markdown $dir/studies.md --json --csv $dir/studies-passes.csv > $dir/studies.json 2> $dir/studies.err"
  else
    local t0=$SECONDS
    limit 300 "$bin" study "$study" --repeats 5 --markdown "$dir/studies.md" --json \
      --csv "$dir/studies-passes.csv" > "$dir/studies.json" 2> "$dir/studies.err" || study_rc=$?
    printf '%s\t# exit %s, %s s\n' "$bin study $study --repeats 5 --markdown studies.md --json --csv studies-passes.csv" \
      "$study_rc" "$((SECONDS - t0))" >> "$dir/commands.txt"
  fi

  # 2b. Rendering-time estimation: h1-h4 and pos on measured passes.
  local est_rc=0
  if [ -n "$dry" ]; then
    echo "$bin study estimation ${est_args[*]} --markdown $dir/estimation.md --json --csv $dir/estimation-passes.csv > $dir/estimation.json 2> $dir/estimation.err"
  else
    local t0=$SECONDS
    limit 240 "$bin" study estimation "${est_args[@]}" --markdown "$dir/estimation.md" --json \
      --csv "$dir/estimation-passes.csv" > "$dir/estimation.json" 2> "$dir/estimation.err" || est_rc=$?
    printf '%s\t# exit %s, %s s\n' "$bin study estimation ${est_args[*]} --markdown estimation.md --json --csv estimation-passes.csv" \
      "$est_rc" "$((SECONDS - t0))" >> "$dir/commands.txt"
  fi

  # 2c. The profile study: designed passes for `calibrate` in one process,
  # rounds interleaved (short passes, no-draw and many-draw passes among them).
  local profile_rc=0
  if [ -n "$dry" ]; then
    echo "$bin study profile ${profile_args[*]} --markdown $dir/profile.md --csv $dir/profile-passes.csv > /dev/null 2> $dir/profile.err"
  else
    local t0=$SECONDS
    limit 120 "$bin" study profile "${profile_args[@]}" --markdown "$dir/profile.md" \
      --csv "$dir/profile-passes.csv" > /dev/null 2> "$dir/profile.err" || profile_rc=$?
    printf '%s\t# exit %s, %s s\n' "$bin study profile ${profile_args[*]} --markdown profile.md --csv profile-passes.csv" \
      "$profile_rc" "$((SECONDS - t0))" >> "$dir/commands.txt"
  fi

  # 3. The load grid, in the shared file's order.
  local vs fs mesh size
  for vs in "${grid_vs[@]}"; do
    for fs in "${grid_fs[@]}"; do
      measure "$dir/load-grid.csv" "$grid_mesh" --size "$grid_size" --vs-loops "$vs" --fs-loops "$fs" "${passes[@]}"
    done
    measure "$dir/load-grid.csv" "$grid_mesh" --size "$grid_size" --vs-loops "$vs" --fs-loops 0 --geometry-only "${passes[@]}"
  done
  for size in "${extra_sizes[@]}"; do
    for mesh in "${extra_meshes[@]}"; do
      measure "$dir/load-grid.csv" "$mesh" --size "$size" "${passes[@]}"
    done
  done

  # 3b. Fixed costs (issue 30): passes that draw nothing (the pass overhead
  #     and the clear), and two meshes split into more and more draw calls
  #     (a draw's cost apart from its triangles'; more draws than
  #     triangles leave some empty).
  for size in "${fixed_sizes[@]}"; do
    measure "$dir/fixed-costs.csv" "${fixed_meshes[0]}" --size "$size" --draws 0 "${passes[@]}"
  done
  local draws
  for mesh in "${fixed_meshes[@]}"; do
    for draws in "${fixed_draws[@]}"; do
      measure "$dir/fixed-costs.csv" "$mesh" --size "${fixed_sizes[0]}" --draws "$draws" "${passes[@]}"
    done
  done

  # 4. Vertex reuse of the corpus: one draw of each index buffer.
  local f json counts
  if [ -z "$dry" ]; then echo "file,indices,unique_vertices,vs_invocations" > "$dir/vertex-reuse.csv"; fi
  for f in $corpus_files; do
    if [ -n "$dry" ]; then json=/dev/null; else json=$(mktemp); fi
    if run_one "$json" "$pass_timeout" "$bin" measure "$f" --size 256x256 --repeats 1 --warmup 0 --json \
      --csv "$dir/corpus-passes.csv" && [ -z "$dry" ]; then
      counts=$(for key in indices unique_vertices vs_invocations; do
        sed -n "s/^ *\"$key\": \([0-9]*\),\{0,1\}$/\1/p" "$json" | head -n 1
      done | paste -sd, -)
      echo "corpus/$(basename "$f"),$counts" >> "$dir/vertex-reuse.csv"
    elif [ -z "$dry" ]; then
      note "rendersim measure $f: failed (see stderr.txt)"
    fi
    [ -n "$dry" ] || rm -f "$json"
  done

  # 5. The load sweep: every mesh, size and load; the random mesh last (its
  #    passes are the longest, so a deadline drops them first).
  local load geo args
  for mesh in "${sweep_meshes[@]}"; do
    for size in "${sweep_sizes[@]}"; do
      for load in "${sweep_loads[@]}"; do
        read -r vs fs geo <<< "$load"
        if capped "$mesh" "$size" "$fs" "$geo"; then
          note "rendersim measure $mesh --size $size $(load_args "$vs" "$fs" "$geo"): capped (estimated over 30 s per pass on an H200)"
          continue
        fi
        # shellcheck disable=SC2207
        args=($(load_args "$vs" "$fs" "$geo"))
        if [[ $mesh == random:* ]]; then
          measure "$dir/load-sweep.csv" "$mesh" --size "$size" "${args[@]}" "${heavy_passes[@]}"
        else
          measure "$dir/load-sweep.csv" "$mesh" --size "$size" "${args[@]}" "${passes[@]}"
        fi
      done
    done
  done

  [ -z "$dry" ] || return 0
  write_readme "$dir" "$bin" "$study" "$study_rc" "$((SECONDS - start))" "${passes[*]}" "${heavy_passes[*]}" \
    "${est_args[*]}" "$est_rc"
  echo "collected into $dir in $((SECONDS - start)) s:"
  (cd "$dir" && wc -l ./*.csv skipped.txt | sed 's/^/  /')
  head -c 3000 "$dir/studies.md" 2>/dev/null || true
}

# README.md: how each file of DIR was produced.
write_readme() {
  local dir=$1 bin=$2 study=$3 study_rc=$4 secs=$5 passes=$6 heavy=$7 est_args=$8 est_rc=$9
  local rows
  rows() { if [ -f "$dir/$1" ]; then echo $(($(wc -l < "$dir/$1") - 1)); else echo 0; fi; }
  cat > "$dir/README.md" <<EOF
# Device measurements (scripts/device-studies.sh collect)

Collected $(date -u +%Y-%m-%d) in ${secs} s by \`bash scripts/device-studies.sh\` with \`$bin\`${QUICK:+ (QUICK=1: scaled down)}.
Adapter: see \`adapter.txt\` and \`adapter.json\`. Counters are Vulkan
pipeline-statistics queries around one indexed draw; times are timestamp
queries around the render pass, medians of the recorded passes.

| file | what it holds | how it was produced |
| --- | --- | --- |
| \`adapter.json\`, \`adapter.txt\` | the adapter as wgpu reports it; nvidia-smi, uname, rendersim version and commit | \`rendersim measure grid:1x1 --size 64x64 --repeats 1 --warmup 0 --json\` |
| \`studies.md\`, \`studies.json\`, \`studies.err\` | \`rendersim study $study\` (exit status $study_rc; an inexact H1 is printed to \`studies.err\` with its residuals and exits 0) | \`rendersim study $study --repeats 5 --markdown studies.md --json --csv studies-passes.csv\` |
| \`studies-passes.csv\` | $(rows studies-passes.csv) passes the studies measured, loop searches included (pass CSV: \`$(head -n 1 "$dir/studies-passes.csv" 2>/dev/null)\`); H1's probes and H3's layered passes have no row | as above |
| \`estimation.md\`, \`estimation.json\`, \`estimation.err\` | \`rendersim study estimation\` (exit status $est_rc): h1-h4 fitted on measured single-object passes, pos tables from table passes, both scored on multi-object passes | \`rendersim study estimation $est_args --markdown estimation.md --json --csv estimation-passes.csv\` |
| \`estimation-passes.csv\` | $(rows estimation-passes.csv) rows: one per object drawn (one per empty pass) with the pass's time and counters and each estimator's estimate | as above |
| \`profile.md\`, \`profile-passes.csv\`, \`profile.err\` | \`rendersim study profile\` (exit status $profile_rc): $(rows profile-passes.csv) designed passes for \`calibrate\` (6 meshes x 64x64, 128x128, 256x256 x 7 loads, and passes of 0, 16 and 256 draws), one process, rounds interleaved, the median kept | \`rendersim study profile ${profile_args[*]} --markdown profile.md --csv profile-passes.csv\` |
| \`load-grid.csv\` | $(rows load-grid.csv) passes: the lists of \`docs/measurements/nvidia-h200/load-grid.csv\` | \`rendersim measure MESH --size S --vs-loops V --fs-loops F [--geometry-only] $passes --csv load-grid.csv\` |
| \`load-sweep.csv\` | $(rows load-sweep.csv) passes: every mesh, size and load of \`docs/measurements/nvidia-h200/load-sweep.csv\`'s lists, held-out rows included; the capped ones are in \`skipped.txt\` | as above (the random mesh: \`$heavy\`), \`--csv load-sweep.csv\` |
| \`fixed-costs.csv\` | $(rows fixed-costs.csv) passes: no draw at each size, and each mesh at the first size in more and more draw calls (a profile's \`pass_overhead_ns\` and \`draw_ns\`: calibrate it with the load files) | \`rendersim measure MESH --size S --draws N $passes --csv fixed-costs.csv\` |
| \`vertex-reuse.csv\`, \`corpus-passes.csv\` | $(rows vertex-reuse.csv) corpus meshes: indices, unique vertices, vertex-shader invocations of one draw (compare with \`docs/measurements/nvidia-h200/vertex-reuse.csv\`) | \`rendersim measure CORPUS/X.idx --size 256x256 --repeats 1 --warmup 0 --json --csv corpus-passes.csv\` (the measured shaders; counters do not depend on them) |
| \`skipped.txt\` | $(wc -l < "$dir/skipped.txt") passes left out: capped (estimated over 30 s per pass), timed out (${PASS_TIMEOUT:-60} s), or past the ${DEADLINE:-450} s deadline | |
| \`commands.txt\`, \`stderr.txt\` | every command with its exit status and seconds; their standard error | |

Read the CSVs with \`rendersim::measure::passes::read_passes\`.
EOF
}

case "${1:-}" in
  prepare)
    cargo build --profile device --locked --features wgpu --bin rendersim
    mkdir -p dist
    cp target/device/rendersim dist/rendersim
    git rev-parse HEAD > dist/COMMIT 2>/dev/null || true
    mkdir -p .gl /tmp/amd64/partial
    o='-oAPT::Architecture=amd64 -oAPT::Architectures=amd64 -oDir::State::Lists=/tmp/amd64'
    # shellcheck disable=SC2086
    apt-get $o update -qq
    # shellcheck disable=SC2086
    (cd .gl && apt-get $o download $DEBS)
    du -sh dist .gl
    ;;
  run)
    : "${OUT:?run this on the device machine, where OUT is set}"
    for f in .gl/*.deb; do dpkg -x "$f" /; done
    ldconfig
    if [ -e /usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json ]; then
      export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
    fi
    nvidia-smi -L || true
    collect "$OUT"
    ;;
  collect)
    collect "${2:-${OUT:?give a folder: collect DIR}}"
    ;;
  *)
    echo "usage: $0 prepare|run|collect DIR   (env: QUICK=1, DRY_RUN=1, RENDERSIM, PASS_TIMEOUT, DEADLINE, CORPUS)" >&2
    exit 2
    ;;
esac
