#!/usr/bin/env bash
# Runs the Slurm recipe on a one-node cluster on this machine, by hand (CI runs the merge tests,
# not Slurm): installs slurm-wlm and munge from Debian's packages, starts munged, slurmctld and
# slurmd with a private configuration, renders a shipped scene as N = 4 slices through
# submit.sh, kills one task's render mid-way (SIGKILL: the task fails, retry.sbatch resubmits
# the slice `obscura merge --list-missing` names) and requeues another (scontrol requeue, as on
# preemption: --requeue runs it again), checks the merged image against a one-machine render
# byte for byte, and stops what it started.
#
#   sudo deploy/slurm/test-local.sh 2>&1 | tee deploy/slurm/test-local.log
#
# Needs root (apt-get, the daemons). OBSCURA=path skips the release build.
set -euo pipefail
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
deploy="$repo/deploy/slurm"
work=$(mktemp -d /tmp/obscura-slurm.XXXXXX)
say() { printf '[%s] %s\n' "$(date -u +%H:%M:%S)" "$*"; }
# Waits up to $1 seconds for the command after it to succeed (daemons and jobs change state
# on their own; there is nothing to block on but polling).
wait_for() {
  local limit=$1; shift
  local end=$((SECONDS + limit))
  until "$@" >/dev/null 2>&1; do
    if [ "$SECONDS" -ge "$end" ]; then say "timed out after ${limit}s: $*"; return 1; fi
    sleep 0.2
  done
}

say "== install: slurm-wlm and munge (Debian packages)"
if ! command -v slurmctld >/dev/null || ! command -v munged >/dev/null; then
  apt-get update -qq
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends slurm-wlm munge
fi
say "$(slurmctld -V), munge $(dpkg-query -W -f '${Version}' munge)"

if [ -z "${OBSCURA:-}" ]; then
  say "== build: cargo build --release --bin obscura"
  (cd "$repo" && cargo build --release --quiet --bin obscura)
  OBSCURA="$repo/target/release/obscura"
fi

started_munge=no
stop_all() {
  set +e
  if [ -n "${SLURM_CONF:-}" ] && [ -f "$work/slurmctld.pid" ]; then
    squeue -h -o %A | xargs -r scancel
    for d in slurmd slurmctld; do
      [ -f "$work/$d.pid" ] && kill "$(cat "$work/$d.pid")"
    done
    say "stopped slurmd and slurmctld"
  fi
  if [ "$started_munge" = yes ] && [ -f /run/munge/munged.pid ]; then
    kill "$(cat /run/munge/munged.pid)"
    say "stopped munged"
  fi
}
trap stop_all EXIT

say "== start munged"
if munge -n 2>/dev/null | unmunge >/dev/null 2>&1; then
  say "munged already running"
else
  [ -s /etc/munge/munge.key ] || mungekey --create --keyfile=/etc/munge/munge.key
  install -d -o munge -g munge -m 0755 /run/munge
  runuser -u munge -- munged
  started_munge=yes
  wait_for 10 bash -c 'munge -n | unmunge'
fi

say "== start a one-node cluster (configuration in $work)"
host=$(hostname -s)
mkdir -p "$work/state" "$work/spool" "$work/shared"
cat > "$work/slurm.conf" <<CONF
ClusterName=obscura-local
SlurmctldHost=$host
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
StateSaveLocation=$work/state
SlurmdSpoolDir=$work/spool
SlurmctldPidFile=$work/slurmctld.pid
SlurmdPidFile=$work/slurmd.pid
SlurmctldLogFile=$work/slurmctld.log
SlurmdLogFile=$work/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
MpiDefault=none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
ReturnToService=2
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
MinJobAge=3600
NodeName=$host CPUs=$(nproc) State=UNKNOWN
PartitionName=local Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF="$work/slurm.conf"
slurmctld -f "$SLURM_CONF"
slurmd -f "$SLURM_CONF"
wait_for 30 bash -c 'scontrol ping | grep -q UP'
wait_for 30 bash -c "sinfo -h -o %T | grep -q idle"
sinfo

scene="$repo/scenes/cornell-box.toml"
flags="--resolution ${RES:-320x240} --spp ${SPP:-64}"
say "== one-machine render: obscura render cornell-box.toml $flags --threads $(nproc)"
# shellcheck disable=SC2086
"$OBSCURA" render "$scene" $flags --threads "$(nproc)" -o "$work/one.exr"

say "== submit: N = 4 slices by passes, merge afterok, retry afternotok"
export OBSCURA SCENE="$scene" OUT_DIR="$work/shared" SLICES=4 OUTPUT="$work/shared/merged.exr"
export RENDER_FLAGS="$flags" RETRIES=2
read -r _ array _ _ merge _ retry < <("$deploy/submit.sh")
say "array $array, merge $merge, retry $retry"

task_pid() { # the obscura process of array task $1, once it runs
  local job pid
  job=$(squeue -h -t R -j "${array}_$1" -o %A) || return 1
  [ -n "$job" ] || return 1
  for pid in $(scontrol listpids "$job" | awk 'NR > 1 { print $1 }'); do
    [ "$(cat "/proc/$pid/comm" 2>/dev/null)" = obscura ] && { echo "$pid"; return 0; }
  done
  return 1
}
cpu_ticks() { awk '{ print $14 + $15 }' "/proc/$1/stat"; } # user + system, 1/100 s
wait_for 60 task_pid 1
pid=$(task_pid 1)
# Mid-way: once it has rendered for a second of CPU (a slice takes about three).
wait_for 60 bash -c "[ \$(awk '{ print \$14 + \$15 }' /proc/$pid/stat) -ge 100 ]"
say "task ${array}_1 runs obscura as pid $pid, $(cpu_ticks "$pid")/100 CPU s in; killing it (SIGKILL)"
kill -KILL "$pid"
wait_for 120 bash -c "squeue -h -t R -j ${array}_3 | grep -q ."
say "task ${array}_3 runs; scontrol requeue (as a preemption would): Slurm runs it again"
scontrol requeue "${array}_3"

say "== wait for the rounds to finish"
wait_for 600 bash -c '[ -z "$(squeue -h)" ]'
squeue -t all -o "%.8i %.16j %.10T %.24r %E" | sort -n
for t in 1 3; do
  say "task ${array}_$t: $(scontrol show job "${array}_$t" | grep -o 'JobState=[A-Z]* \|Restarts=[0-9]*\|ExitCode=[0-9:]*' | tr '\n' ' ')"
done
for f in "$work"/shared/obscura-*.out; do
  say "--- $(basename "$f")"
  cat "$f"
done
ls -l "$work/shared"

say "== compare"
"$OBSCURA" merge --list-missing --slices 4 "$work"/shared/slice-*.part | sed 's/^/missing after the retry: [/; s/$/]/'
if cmp "$work/one.exr" "$work/shared/merged.exr"; then
  say "PASS: merged.exr equals the one-machine render byte for byte ($(sha256sum < "$work/one.exr" | cut -c1-16))"
else
  say "FAIL: merged.exr differs from the one-machine render"
  exit 1
fi
