#!/usr/bin/env bash
# The Slurm recipes of docs/guide/shards.md, run as written on a real single-node Slurm.
#
# The blocks of the page marked `<!-- slurm-recipe: NAME -->` are extracted as they are
# (the job script `sweep.sbatch`, the submissions `submit` and `submit-gcode`), so the page
# and this test cannot drift apart. Three pipelines go through one cluster at once, each in
# its own folder standing for the shared folder the page submits from:
#   plain:  `submit` with scenarios/big.toml = tests/shards/big.toml (16 runs);
#   failed: `submit` with scenarios/big.toml = tests/shards/big_lost_steps.toml (3 of its
#           16 shards hold a run that loses steps: those tasks must still exit 0 so that
#           the `afterok` merge runs);
#   gcode:  `submit-gcode` with scenarios/gcode_cube.toml and the G-code file it reads.
# Every job (16 array tasks and a merge per pipeline) must end COMPLETED with exit code 0,
# and each merged runs.csv, summary.md, report.html and plot must equal the unsharded
# sweep's (run here without Slurm) byte for byte.
#
# The cluster: Debian's slurm-wlm 22.05 (slurmctld, slurmd, slurm-client) and munge,
# installed with apt-get when missing. Everything lives in a temporary folder: munged runs
# as the `munge` user on its own socket and key there, slurmctld and slurmd as root on the
# local host name with their own ports, state, spool and logs there
# (ProctrackType=proctrack/linuxproc, TaskPlugin=task/none: no cgroups needed). The node
# declares 16 CPUs (SlurmdParameters=config_overrides) so that the page's
# `--cpus-per-task=4` fits and four tasks run at a time on any machine. On exit, success or
# failure, every job is cancelled and every process this script started is stopped (the
# daemons by their ids, then anything whose environment holds this cluster's SLURM_CONF),
# and the folder is removed; the daemons' logs are printed first on failure.
#
# Skipped, with the reason and the check that decided, only when the machine cannot run
# the daemons: SETTLE_SKIP_SLURM=1; not Linux; not root (slurmd starts jobs as their
# user) and no password-less sudo; Slurm missing and no apt-get; no `munge` user or no
# setpriv; or a process here cannot listen on 127.0.0.1. Past those checks any failure is
# a failure.
#
# Environment:
#   SETTLE_BIN          the settle binary (default ${CARGO_TARGET_DIR:-target}/ci/settle)
#   SETTLE_SKIP_SLURM=1 skip
#   SETTLE_SLURM_TIMEOUT_S  longest wait for the jobs (default 150)
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)
started=$(date +%s)

skip() {
  echo "SKIPPED: the Slurm recipes of docs/guide/shards.md were not run: $1 (check: $2)"
  exit 0
}

[[ "${SETTLE_SKIP_SLURM:-0}" == 1 ]] && skip "asked for" "SETTLE_SKIP_SLURM=1"
[[ "$(uname -s)" == Linux ]] || skip "not Linux" "uname -s = $(uname -s)"

bin=${SETTLE_BIN:-${CARGO_TARGET_DIR:-target}/ci/settle}
[[ $bin = /* ]] || bin="$root/$bin"
if [[ ! -x $bin ]]; then
  echo "no settle binary at $bin: build it (cargo test --profile ci --no-run) or set SETTLE_BIN" >&2
  exit 1
fi

if [[ $(id -u) -ne 0 ]]; then
  if command -v sudo >/dev/null && sudo -n true 2>/dev/null; then
    exec sudo -n --preserve-env=SETTLE_SKIP_SLURM,SETTLE_SLURM_TIMEOUT_S \
      env SETTLE_BIN="$bin" "$0" "$@"
  fi
  skip "not root, and no password-less sudo (slurmd starts each job as its user)" \
    "id -u = $(id -u); sudo -n true"
fi

if ! command -v slurmctld >/dev/null || ! command -v slurmd >/dev/null \
  || ! command -v sbatch >/dev/null || ! command -v munged >/dev/null; then
  command -v apt-get >/dev/null \
    || skip "Slurm or munge is not installed and there is no apt-get to install them" \
      "command -v slurmctld slurmd sbatch munged apt-get"
  echo "== installing Debian's slurmctld, slurmd, slurm-client and munge (apt-get)"
  export DEBIAN_FRONTEND=noninteractive
  # The packages' own services are not started (this test starts its own daemons): a
  # policy-rc.d that denies every start, for the install only, when there is none.
  policy=""
  if [[ ! -e /usr/sbin/policy-rc.d ]]; then
    policy=/usr/sbin/policy-rc.d
    printf '#!/bin/sh\nexit 101\n' >"$policy"
    chmod 755 "$policy"
  fi
  install_status=0
  apt-get install -y -qq --no-install-recommends slurmctld slurmd slurm-client munge \
    >/dev/null 2>&1 || {
    apt-get update -qq \
      && apt-get install -y -qq --no-install-recommends slurmctld slurmd slurm-client munge \
        >/dev/null
  } || install_status=$?
  [[ -n $policy ]] && rm -f "$policy"
  if [[ $install_status -ne 0 ]]; then
    echo "apt-get could not install slurmctld, slurmd, slurm-client and munge" >&2
    exit 1
  fi
fi
id munge >/dev/null 2>&1 || skip "no munge user to run munged as" "id munge"
command -v setpriv >/dev/null || skip "no setpriv to start munged as the munge user" \
  "command -v setpriv"
if ! python3 - <<'EOF'
import socket
s = socket.socket()
s.bind(("127.0.0.1", 0))
s.listen(1)
c = socket.create_connection(s.getsockname(), timeout=2)
c.close()
s.close()
EOF
then
  skip "a process here cannot listen on and connect to 127.0.0.1" \
    "python3 socket bind/listen/connect on 127.0.0.1"
fi
echo "== $(slurmctld -V), $(munged -V 2>&1 | head -1)"

# The cluster's folder (traversable by the munge user: munged checks its socket's path).
d=$(mktemp -d)
chmod 755 "$d"
export SLURM_CONF="$d/slurm.conf"
daemons=()
ok=0

# Stop everything this script started, whatever happened.
teardown() {
  local status=$?
  set +e
  if [[ -n ${SLURM_CONF:-} && -f $SLURM_CONF ]] && [[ ${#daemons[@]} -gt 0 ]]; then
    local jobs
    jobs=$(timeout 10 squeue -h -o %A 2>/dev/null)
    if [[ -n $jobs ]]; then
      # shellcheck disable=SC2086
      timeout 10 scancel $jobs 2>/dev/null
      for _ in $(seq 1 50); do
        [[ -z $(timeout 5 squeue -h -o %A 2>/dev/null) ]] && break
        sleep 0.2
      done
    fi
  fi
  if [[ $ok -ne 1 && -d $d/log ]]; then
    for f in "$d"/log/*; do
      [[ -s $f ]] || continue
      echo "---- $f (last 30 lines)" >&2
      tail -n 30 "$f" >&2
    done
  fi
  # The daemons, last started first (slurmd, slurmctld, munged): SIGTERM, then SIGKILL.
  local i pid
  for ((i = ${#daemons[@]} - 1; i >= 0; i--)); do
    pid=${daemons[i]}
    kill "$pid" 2>/dev/null
    for _ in $(seq 1 100); do
      kill -0 "$pid" 2>/dev/null || break
      sleep 0.1
    done
    kill -9 "$pid" 2>/dev/null
    wait "$pid" 2>/dev/null
  done
  # What they left (slurmscriptd, a job step): processes with this cluster's SLURM_CONF.
  local left=()
  for env_file in /proc/[0-9]*/environ; do
    pid=${env_file#/proc/}
    pid=${pid%/environ}
    [[ $pid == "$$" || $pid == "$BASHPID" ]] && continue
    if { tr '\0' '\n' <"$env_file"; } 2>/dev/null | grep -qxF "SLURM_CONF=$d/slurm.conf"; then
      left+=("$pid")
    fi
  done
  if [[ ${#left[@]} -gt 0 ]]; then
    echo "stopping what the cluster left: ${left[*]}"
    kill -9 "${left[@]}" 2>/dev/null
  fi
  rm -rf "$d"
  if [[ $status -eq 0 ]]; then
    echo "== Slurm recipes: passed in $(($(date +%s) - started)) s; every daemon stopped"
  else
    echo "== Slurm recipes: FAILED (exit $status) after $(($(date +%s) - started)) s; every daemon stopped" >&2
  fi
  exit "$status"
}
trap teardown EXIT
trap 'exit 130' INT TERM

mkdir -p "$d/munge" "$d/state" "$d/spool" "$d/log" "$d/bin"
chown munge:munge "$d/munge"
chmod 755 "$d/munge"
head -c 1024 /dev/urandom >"$d/munge/munge.key"
chown munge:munge "$d/munge/munge.key"
chmod 400 "$d/munge/munge.key"
setpriv --reuid=munge --regid=munge --init-groups \
  munged --foreground --socket="$d/munge/socket" --key-file="$d/munge/munge.key" \
  --pid-file="$d/munge/munged.pid" --log-file="$d/munge/munged.log" \
  --seed-file="$d/munge/munged.seed" >"$d/log/munged.out" 2>&1 &
daemons+=($!)
for _ in $(seq 1 100); do
  [[ -S $d/munge/socket ]] && break
  sleep 0.1
done
[[ -S $d/munge/socket ]] || { echo "munged did not start" >&2; exit 1; }

# Two free ports on 127.0.0.1 for slurmctld and slurmd.
read -r ctld_port slurmd_port < <(python3 -c '
import socket
ss = [socket.socket() for _ in range(2)]
for s in ss:
    s.bind(("127.0.0.1", 0))
print(*[s.getsockname()[1] for s in ss])
')
host=$(hostname -s)
cat >"$SLURM_CONF" <<EOF
ClusterName=settle-test
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$ctld_port
SlurmdPort=$slurmd_port
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$d/munge/socket
CredType=cred/munge
StateSaveLocation=$d/state
SlurmdSpoolDir=$d/spool
SlurmctldPidFile=$d/slurmctld.pid
SlurmdPidFile=$d/slurmd.pid
SlurmctldLogFile=$d/log/slurmctld.log
SlurmdLogFile=$d/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
MpiDefault=none
SchedulerType=sched/builtin
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
SlurmdParameters=config_overrides
ReturnToService=2
JobCompType=jobcomp/none
AccountingStorageType=accounting_storage/none
JobAcctGatherType=jobacct_gather/none
MinJobAge=600
NodeName=$host NodeAddr=127.0.0.1 CPUs=16 State=UNKNOWN
PartitionName=test Nodes=$host Default=YES MaxTime=INFINITE State=UP
EOF
slurmctld -D -i -f "$SLURM_CONF" >"$d/log/slurmctld.out" 2>&1 &
daemons+=($!)
slurmd -D -N "$host" -f "$SLURM_CONF" >"$d/log/slurmd.out" 2>&1 &
daemons+=($!)
for _ in $(seq 1 60); do
  [[ $(timeout 5 sinfo -h -o %T 2>/dev/null) == idle ]] && break
  sleep 0.5
done
if [[ $(timeout 5 sinfo -h -o %T 2>/dev/null) != idle ]]; then
  echo "the Slurm node did not come up: $(timeout 5 sinfo 2>&1)" >&2
  exit 1
fi
echo "== single-node Slurm up on $host in $(($(date +%s) - started)) s (ports $ctld_port, $slurmd_port)"

# The page's blocks, as they are.
python3 - docs/guide/shards.md "$d/recipes" <<'EOF'
import os, re, sys
page, out = sys.argv[1], sys.argv[2]
os.makedirs(out)
lines = open(page, encoding="utf-8").read().split("\n")
found = set()
for i, line in enumerate(lines):
    m = re.match(r"^<!--\s*slurm-recipe:\s*(\S+)\s*-->$", line.strip())
    if not m:
        continue
    assert lines[i + 1].startswith("```"), f"{page}:{i + 2}: a fence must follow the marker"
    body = []
    for l in lines[i + 2:]:
        if l.startswith("```"):
            break
        body.append(l)
    open(os.path.join(out, m.group(1)), "w").write("\n".join(body) + "\n")
    found.add(m.group(1))
missing = {"sweep.sbatch", "submit", "submit-gcode"} - found
assert not missing, f"{page} has no slurm-recipe block {sorted(missing)}"
EOF

# The folders the page submits from, with `settle` on PATH (sbatch passes the environment).
ln -s "$bin" "$d/bin/settle"
export PATH="$d/bin:$PATH"
setup() {
  local w=$1 scenario=$2 as=$3
  mkdir -p "$w/scenarios"
  cp "$d/recipes/sweep.sbatch" "$w/"
  cp "$scenario" "$w/scenarios/$as"
}
setup "$d/plain" tests/shards/big.toml big.toml
setup "$d/failed" tests/shards/big_lost_steps.toml big.toml
setup "$d/gcode" scenarios/gcode_cube.toml gcode_cube.toml
mkdir -p "$d/gcode/gcode/prints"
cp gcode/prints/cube_layer.gcode "$d/gcode/gcode/prints/"

submitted=$(date +%s)
for p in plain failed; do
  (cd "$d/$p" && bash "$d/recipes/submit" >submit.log)
done
(cd "$d/gcode" && bash "$d/recipes/submit-gcode" >submit.log)

# Until the queue is empty, or holds only merges whose tasks failed (Slurm leaves those
# pending for good, reason DependencyNeverSatisfied; the check below lists them).
timeout_s=${SETTLE_SLURM_TIMEOUT_S:-150}
while true; do
  queue=$(squeue -h -o '%A %T %r')
  [[ -z $queue ]] && break
  if ! grep -qv ' PENDING DependencyNeverSatisfied$' <<<"$queue"; then
    echo "a merge can never start: a task it depends on did not exit 0" >&2
    break
  fi
  if (($(date +%s) - submitted > timeout_s)); then
    echo "jobs still queued or running after ${timeout_s} s:" >&2
    squeue >&2
    exit 1
  fi
  sleep 0.5
done
echo "== the jobs ended in $(($(date +%s) - submitted)) s"

# Every job: COMPLETED with exit code 0 (3 x 16 array tasks and 3 merges).
states=$(scontrol -o show job \
  | sed -E 's/^JobId=([0-9]+) .* JobState=([A-Z_]+) .* ExitCode=([0-9]+:[0-9]+) .* StdOut=([^ ]+).*$/job \1 \2 exit \3 \4/')
total=$(grep -c . <<<"$states")
good=$(grep -c ' COMPLETED exit 0:0 ' <<<"$states")
if [[ $total -ne 51 || $good -ne 51 ]]; then
  echo "expected 51 jobs COMPLETED with exit code 0, got $good of $total; the others:" >&2
  grep -v ' COMPLETED exit 0:0 ' <<<"$states" | while read -r _ id state _ code out; do
    echo "---- job $id: $state, exit code $code; $out:" >&2
    [[ -f $out ]] && tail -n 3 "$out" >&2
  done
  exit 1
fi
echo "== 51 jobs (3 arrays of 16 tasks, 3 merges): all COMPLETED, exit code 0"

# The merged outputs against an unsharded sweep of the same scenario.
same() {
  local p=$1 name=$2
  shift 2
  local w=$d/$p
  (cd "$w" && settle sweep "scenarios/$name.toml" "$@" --out unsharded >unsharded.log 2>&1) \
    || { echo "$p: the unsharded sweep failed:" >&2; cat "$w/unsharded.log" >&2; exit 1; }
  local want got
  want=$(cd "$w/unsharded" && find . -type f | sort)
  got=$(cd "$w/results/$name" && find . -type f -not -path './shard-*' | sort)
  if [[ $want != "$got" ]]; then
    echo "$p: the merge wrote other files than the unsharded sweep:" >&2
    diff <(echo "$want") <(echo "$got") >&2
    exit 1
  fi
  local f
  while read -r f; do
    cmp -s "$w/unsharded/$f" "$w/results/$name/$f" \
      || { echo "$p: $f differs between the merge and the unsharded sweep" >&2; exit 1; }
  done <<<"$want"
  echo "   $p: $(wc -l <<<"$want") files of results/$name equal the unsharded sweep's byte for byte"
}
same plain big
same failed big
same gcode gcode_cube --backend modal
# The rows (not the header, which names a `lost_steps` column) of runs that lost steps.
lost() { tail -n +2 "$1" | grep -c ',lost_steps,' || true; }
failed_rows=$(lost "$d/failed/results/big/runs.csv")
failed_shards=0
for f in "$d"/failed/results/big/shard-*/runs.csv; do
  [[ $(lost "$f") -gt 0 ]] && failed_shards=$((failed_shards + 1))
done
if [[ $failed_rows -lt 1 || $failed_shards -lt 1 ]]; then
  echo "failed: no run lost steps, so the test proves nothing about failed runs" >&2
  exit 1
fi
merge_log=$(find "$d/failed" -maxdepth 1 -name 'slurm-*.out' -not -name '*_*')
grep -q 'runs failed' "$merge_log" \
  || { echo "failed: the merge job's log ($merge_log) does not list the failed runs" >&2; exit 1; }
echo "   failed: $failed_rows runs lost steps in $failed_shards shards; their tasks exited 0 and the afterok merge ran"
ok=1
