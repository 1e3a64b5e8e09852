#!/bin/bash
# A real one-node SLURM cluster on this machine runs `rest-embree farm slurm`: a 4-frame film and
# a 2x2-tile still, checked byte for byte against local renders. Starts munged, slurmctld and
# slurmd with a generated configuration under a temporary directory (as root, as on the CI
# machines), and stops the daemons it started, by their pids, whatever happens.
#
#   scripts/slurm-test.sh [path/to/rest-embree]      (default: target/release/rest-embree)
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
exe=$(realpath "${1:-$root/target/release/rest-embree}")
[ -x "$exe" ] || { echo "slurm-test: no binary at $exe (cargo build --release)" >&2; exit 1; }
if [ "$(id -u)" != 0 ]; then
    echo "slurm-test: SKIPPED: starting munged, slurmctld and slurmd needs root" >&2
    exit 0
fi
if ! command -v slurmctld >/dev/null || ! command -v munged >/dev/null; then
    echo "slurm-test: installing slurm-wlm and munge" >&2
    DEBIAN_FRONTEND=noninteractive apt-get -o DPkg::Lock::Timeout=600 install -y -q slurm-wlm munge >/dev/null
fi

work=$(mktemp -d /tmp/rest-embree-slurm.XXXXXX)
pids=()
stop() {
    for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done
    for p in "${pids[@]}"; do
        for _ in $(seq 50); do kill -0 "$p" 2>/dev/null || break; sleep 0.1; done
        kill -9 "$p" 2>/dev/null || true
    done
    rm -rf "$work"
}
trap stop EXIT

# munge: a key and a socket of our own.
mkdir -p "$work/munge"
dd if=/dev/urandom of="$work/munge/munge.key" bs=1024 count=1 status=none
chmod 700 "$work/munge"
chmod 400 "$work/munge/munge.key"
munged --force --key-file="$work/munge/munge.key" --socket="$work/munge/socket" \
    --pid-file="$work/munge/munged.pid" --log-file="$work/munge/munged.log" --seed-file="$work/munge/seed"
for _ in $(seq 50); do [ -s "$work/munge/munged.pid" ] && break; sleep 0.1; done
pids+=("$(cat "$work/munge/munged.pid")")

host=$(hostname -s)
cpus=$(nproc)
# The node's memory as a real cluster's configuration gives it: farm slurm asks for --mem, and
# a node left at SLURM's default of 1 MB could satisfy none.
mem_mb=$(awk '/^MemTotal:/ { print int($2 / 1024) }' /proc/meminfo)
mkdir -p "$work/state" "$work/spool" "$work/log"
cat > "$work/slurm.conf" <<CONF
ClusterName=rest-embree-test
SlurmctldHost=$host
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$work/munge/socket
CredType=cred/munge
StateSaveLocation=$work/state
SlurmdSpoolDir=$work/spool
SlurmctldPidFile=$work/slurmctld.pid
SlurmdPidFile=$work/slurmd.pid
SlurmctldLogFile=$work/log/slurmctld.log
SlurmdLogFile=$work/log/slurmd.log
SlurmctldPort=46817
SlurmdPort=46818
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
MpiDefault=none
ReturnToService=2
SchedulerType=sched/builtin
NodeName=$host CPUs=$cpus RealMemory=$mem_mb State=UNKNOWN
PartitionName=test Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF="$work/slurm.conf"
slurmctld -f "$SLURM_CONF"
for _ in $(seq 100); do [ -s "$work/slurmctld.pid" ] && break; sleep 0.1; done
pids+=("$(cat "$work/slurmctld.pid")")
slurmd -f "$SLURM_CONF"
for _ in $(seq 100); do [ -s "$work/slurmd.pid" ] && break; sleep 0.1; done
pids+=("$(cat "$work/slurmd.pid")")
for i in $(seq 300); do
    sinfo -h -o %t 2>/dev/null | grep -qE '^idle' && break
    [ "$i" = 300 ] && { echo "slurm-test: the node never came up" >&2; cat "$work/log/"*.log >&2; exit 1; }
    sleep 0.2
done
echo "slurm-test: cluster up ($host, $cpus CPUs)"

# The film: 4 frames.
cat > "$work/film.toml" <<'SCENE'
[camera]
position = [-3.0, 0.0, 0.0]
direction = [1.0, 0.0, 0.0]
up = [0.0, 0.0, 1.0]
fov_y = 60.0

[image]
width = 64
height = 48

[film]
start = 0.0
end = 3.0
fps = 1.0

[[group]]
name = "lattice"
velocity = [-0.9, 0.0, 0.0]
[[group.object]]
type = "lattice"
counts = [4, 4, 4]
spacing = 1.0
origin = [0.0, -1.5, -1.5]
rod_radius = 0.04
sphere_radius = 0.12
SCENE
sed '/^\[film\]/,/^fps/d' "$work/film.toml" > "$work/still.toml"

mkdir -p "$work/farm" "$work/local"
"$exe" farm slurm "$work/film.toml" -o "$work/farm/frame-####.exr" > "$work/film.id"
"$exe" farm slurm "$work/still.toml" -o "$work/farm/still.exr" --tiles 2x2 --set image.samples=2 > "$work/still.ids"
echo "slurm-test: submitted jobs $(cat "$work/film.id" "$work/still.ids" | tr '\n' ' ')"
for i in $(seq 600); do
    [ -z "$(squeue -h 2>/dev/null)" ] && break
    [ "$i" = 600 ] && { echo "slurm-test: jobs still queued after 120 s" >&2; squeue >&2; exit 1; }
    sleep 0.2
done

"$exe" render "$work/film.toml" -o "$work/local/frame-####.exr" -q
"$exe" render "$work/still.toml" -o "$work/local/still.exr" -q --set image.samples=2
status=0
for f in frame-0000.exr frame-0001.exr frame-0002.exr frame-0003.exr still.exr; do
    if cmp -s "$work/farm/$f" "$work/local/$f"; then
        echo "slurm-test: $f: the farm's file is the local render's, byte for byte"
    else
        echo "slurm-test: $f: differs from the local render (or is missing)" >&2
        status=1
    fi
done
if ls "$work/farm"/still.tile-* >/dev/null 2>&1; then
    echo "slurm-test: the tiles were not removed after assembly" >&2
    status=1
fi
if [ "$status" != 0 ]; then
    ls -la "$work/farm" >&2
    cat "$work/farm/rest-embree-farm/"*.out >&2 || true
fi
exit $status
