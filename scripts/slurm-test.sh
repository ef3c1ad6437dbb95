#!/usr/bin/env bash
# A real Slurm on this one machine, for rendersim's job arrays:
#   - installs Debian's slurmctld, slurmd, slurm-client and munge if they are
#     missing (apt-get as root, without recommended packages; their services
#     neither started by the install nor enabled at boot);
#   - starts munged (unless one runs already), slurmctld and slurmd with a
#     minimal localhost slurm.conf written into a temp folder (no cgroups:
#     proctrack/linuxproc, task/none);
#   - submits a small experiment with `rendersim experiment --slurm --shards 4
#     --submit` (a 4-task array and a merge job after it), waits for the merge,
#     and compares the merged outputs with a single-process run of the same
#     experiment (wall-time columns and the report's timing lines aside);
#   - stops the daemons it started (trap), whatever happens.
# If the daemons cannot start, it says so and fails.
# Uses $RENDERSIM_BIN or target/release/rendersim (build it first).
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)
bin=${RENDERSIM_BIN:-$root/target/release/rendersim}
fail() { echo "slurm-test: FAILED: $*" >&2; exit 1; }
[ -x "$bin" ] || fail "no rendersim binary at $bin (run cargo build --release first)"

# What the test uses, and no more: the two daemons, the client commands and
# munge, without the packages Debian recommends beside them (slurm-wlm's
# plugin and -dev packages). The packages' own services are neither
# started by their install (a policy-rc.d that says no, the one there put
# back after) nor left enabled at boot: this script starts the daemons it
# needs and stops them at the end.
slurm_packages="slurmctld slurmd slurm-client munge"
if ! command -v slurmctld >/dev/null 2>&1 || ! command -v slurmd >/dev/null 2>&1 || ! command -v munged >/dev/null 2>&1; then
  if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then
    echo "installing $slurm_packages (without recommended packages; their services not started or enabled at boot)"
    policy=/usr/sbin/policy-rc.d
    saved_policy=""
    if [ -e "$policy" ]; then
      saved_policy=$(mktemp)
      cp -p "$policy" "$saved_policy"
    fi
    printf '#!/bin/sh\n# rendersim slurm-test: no service starts while its packages install\nexit 101\n' > "$policy"
    chmod 755 "$policy"
    installed=0
    # shellcheck disable=SC2086
    apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends $slurm_packages >/dev/null && installed=1
    if [ -n "$saved_policy" ]; then mv "$saved_policy" "$policy"; else rm -f "$policy"; fi
    [ "$installed" = 1 ] || fail "apt-get could not install $slurm_packages"
    for svc in munge slurmctld slurmd; do
      if command -v deb-systemd-helper >/dev/null 2>&1; then
        deb-systemd-helper disable "$svc.service" >/dev/null 2>&1 || true
      fi
      if [ -x "/etc/init.d/$svc" ] && command -v update-rc.d >/dev/null 2>&1; then
        update-rc.d "$svc" disable >/dev/null 2>&1 || true
      fi
    done
  else
    fail "slurmctld, slurmd and munge are not installed and cannot be installed here (needs root and apt-get)"
  fi
fi
[ "$(id -u)" = 0 ] || fail "slurmd must run as root here (SlurmdUser=root)"

work=$(mktemp -d "${TMPDIR:-/tmp}/rendersim-slurm.XXXXXX")
chmod 755 "$work"
started_munge=""
stop() {
  # The daemons this script started, by their pid files; then the temp folder.
  for f in "$work/slurmd.pid" "$work/slurmctld.pid"; do
    if [ -s "$f" ]; then kill "$(cat "$f")" 2>/dev/null || true; fi
  done
  if [ -n "$started_munge" ] && [ -s /run/munge/munged.pid ]; then
    kill "$(cat /run/munge/munged.pid)" 2>/dev/null || true
  fi
  for _ in $(seq 50); do
    alive=""
    for f in "$work/slurmd.pid" "$work/slurmctld.pid"; do
      if [ -s "$f" ] && kill -0 "$(cat "$f")" 2>/dev/null; then alive=1; fi
    done
    [ -z "$alive" ] && break
    sleep 0.1
  done
  if [ -n "${RENDERSIM_KEEP_SLURM_TEST:-}" ]; then echo "kept $work"; else rm -rf "$work"; fi
}
trap stop EXIT

# munge: a key and its folders owned by the munge user; one daemon.
if [ -s /run/munge/munged.pid ] && kill -0 "$(cat /run/munge/munged.pid)" 2>/dev/null; then
  echo "munged runs already"
else
  mkdir -p /etc/munge /run/munge /var/log/munge /var/lib/munge
  if [ ! -s /etc/munge/munge.key ]; then
    dd if=/dev/urandom of=/etc/munge/munge.key bs=1024 count=1 status=none
  fi
  chown -R munge:munge /etc/munge /run/munge /var/log/munge /var/lib/munge
  chmod 400 /etc/munge/munge.key
  chmod 700 /etc/munge
  runuser -u munge -- munged || fail "munged did not start"
  started_munge=1
fi

host=$(hostname -s)
cpus=$(nproc)
mem=$(( $(free -m | awk '/^Mem:/ {print $2}') * 9 / 10 ))
mkdir -p "$work/state" "$work/spool"
export SLURM_CONF="$work/slurm.conf"
cat > "$SLURM_CONF" <<CONF
ClusterName=rendersim-test
SlurmctldHost=$host
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
StateSaveLocation=$work/state
SlurmdSpoolDir=$work/spool
SlurmctldPidFile=$work/slurmctld.pid
SlurmdPidFile=$work/slurmd.pid
SlurmctldLogFile=$work/slurmctld.log
SlurmdLogFile=$work/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
SwitchType=switch/none
MpiDefault=none
MailProg=/bin/true
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
NodeName=$host CPUs=$cpus RealMemory=$mem State=UNKNOWN
PartitionName=test Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF

slurmctld || { tail -n 20 "$work/slurmctld.log" 2>/dev/null; fail "slurmctld did not start"; }
slurmd || { tail -n 20 "$work/slurmd.log" 2>/dev/null; fail "slurmd did not start"; }
state=""
for _ in $(seq 60); do
  state=$(sinfo -h -o %t 2>/dev/null | head -n 1 || true)
  [ "$state" = idle ] && break
  sleep 0.5
done
if [ "$state" != idle ]; then
  tail -n 20 "$work/slurmctld.log" "$work/slurmd.log" 2>/dev/null || true
  fail "the Slurm node did not become idle (state: '${state:-none}'): the daemons could not start here"
fi
echo "Slurm $(sinfo -V | awk '{print $2}') up on $host ($cpus CPUs)"

# The shared small noisy experiment (tests/fixtures/sharded/, also run by
# tests/it/shards.rs with a stand-in sbatch): 3 x 2 points x 2 seeds = 12
# runs, with per-frame data (histogram, derived spread), line and scatter
# plots and a check.
cp "$root/tests/fixtures/sharded/m.toml" "$root/tests/fixtures/sharded/e.toml" "$work/"

said=$("$bin" experiment "$work/e.toml" --out "$work/sharded" --slurm --shards 4 --submit)
echo "$said"
array=$(echo "$said" | sed -n 's/.*submitted array job \([0-9]*\).*/\1/p')
merge=$(echo "$said" | sed -n 's/.*merge job \([0-9]*\).*/\1/p')
[ -n "$array" ] && [ -n "$merge" ] || fail "no job ids in rendersim's output"
for _ in $(seq 240); do
  [ -z "$(squeue -h -j "$array,$merge" 2>/dev/null)" ] && break
  sleep 0.5
done
if [ -n "$(squeue -h -j "$array,$merge" 2>/dev/null)" ]; then
  fail "jobs $array and $merge still queued after 2 minutes"
fi
merge_state=$(scontrol show job "$merge" 2>/dev/null | sed -n 's/.*JobState=\([A-Z_]*\).*/\1/p')
if [ "$merge_state" != COMPLETED ]; then
  cat "$work"/sharded/logs/*.out 2>/dev/null | tail -n 20 || true
  fail "merge job $merge ended $merge_state"
fi
shards=$(ls "$work/sharded/shards" | grep -c '^shard-.*\.json$' || true)
[ "$shards" = 4 ] || fail "expected 4 shard files, found $shards"
echo "array job $array: 4 shards; merge job $merge: $merge_state"

"$bin" experiment "$work/e.toml" --out "$work/single" --quiet > /dev/null
# Compare: CSVs with the wall_seconds* columns emptied, report.md without
# its Timing and Provenance sections, everything else byte for byte.
mask() { awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) w[i] = ($i ~ /^wall_seconds/) } { for (i = 1; i <= NF; i++) if (w[i]) $i = ""; print }' OFS=, "$1"; }
notiming() { awk '/^## / { skip = ($0 == "## Timing" || $0 == "## Provenance") } !skip' "$1"; }
n=0
for f in "$work"/single/*; do
  name=$(basename "$f")
  g="$work/sharded/$name"
  [ -f "$g" ] || fail "merged outputs lack $name"
  case "$name" in
    *.csv) cmp -s <(mask "$f") <(mask "$g") || { diff <(mask "$f") <(mask "$g") | head; fail "$name differs"; } ;;
    report.md) cmp -s <(notiming "$f") <(notiming "$g") || { diff <(notiming "$f") <(notiming "$g") | head; fail "$name differs"; } ;;
    *) cmp -s "$f" "$g" || fail "$name differs" ;;
  esac
  n=$((n + 1))
done
grep -q 'total CPU time over all shards' "$work/sharded/report.md" || fail "the merged report gives no CPU time over the shards"
grep -E '^- (array wall time|total CPU time)' "$work/sharded/report.md"
echo "slurm-test: passed ($n merged files equal a single-process run's)"
