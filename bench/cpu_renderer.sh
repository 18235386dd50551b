#!/usr/bin/env bash
# CPU renderer figures for BENCHMARKS.md: prints the machine (nproc, CPU model), the date and
# the load average, then runs `sdfc bench` on the report's six scenes with the CPU backend at
# 640x480 (5 frames) and 1920x1080 (3 frames), and scene 3 at 640x480 with 1 and 2 threads.
# Every `sdfc bench` times its frames after one untimed warm-up frame and prints the median.
# Before each command it prints the load average and the kernel's CPU pressure (PSI "some":
# the share of time some task waited for a CPU), and after it the CPU share the whole process
# got (from /usr/bin/time, when present; 200% = both cores), as a measure of contention.
#
# Usage: bench/cpu_renderer.sh   (from anywhere; builds target/release/sdfc if absent)
# Environment: SCENE3_REPEATS=N repeats the two scene-3 commands N more times, SCENE3_PAUSE
# seconds apart (default 15), to show the spread of the figures on a shared machine.
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$ROOT"
SDFC=./target/release/sdfc
if [ ! -x "$SDFC" ]; then
    cargo build --release
fi

SCENES="examples/seed1.sdf examples/seed2.sdf examples/seed3.sdf examples/seed4.sdf examples/seed5.sdf examples/seed6.sdf"

pressure() {
    if [ -r /proc/pressure/cpu ]; then
        sed -n 's/^some avg10=\([0-9.]*\) avg60=\([0-9.]*\).*/, CPU pressure avg10 \1% avg60 \2%/p' /proc/pressure/cpu
    fi
}

run() {
    echo
    echo "\$ $*"
    echo "(before: load average $(cut -d' ' -f1-3 /proc/loadavg)$(pressure))"
    if [ -x /usr/bin/time ]; then
        /usr/bin/time -f "(process: wall %e s, user %U s, sys %S s, CPU %P)" "$@"
    else
        "$@"
    fi
}

echo "date: $(date -u)"
echo "nproc: $(nproc)"
echo "cpu: $(lscpu | sed -n 's/^Model name: *//p')"
echo "sdfc: built $(date -u -r "$SDFC" '+%F %T UTC'), git HEAD $(git rev-parse --short HEAD 2>/dev/null || echo '?')"
run "$SDFC" bench $SCENES --backend cpu --size 640x480 --frames 5
run "$SDFC" bench $SCENES --backend cpu --size 1920x1080 --frames 3
run "$SDFC" bench examples/seed3.sdf --backend cpu --size 640x480 --frames 5 --threads 1
run "$SDFC" bench examples/seed3.sdf --backend cpu --size 640x480 --frames 5 --threads 2

# Scene 3 again, alternating 1 and 2 threads with pauses, to show the spread on a shared machine.
for i in $(seq 1 "${SCENE3_REPEATS:-0}"); do
    sleep "${SCENE3_PAUSE:-15}"
    for t in 1 2; do
        run "$SDFC" bench examples/seed3.sdf --backend cpu --size 640x480 --frames 5 --threads "$t"
    done
done
