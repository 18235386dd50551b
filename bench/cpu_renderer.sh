#!/usr/bin/env bash
# CPU renderer figures for BENCHMARKS.md: prints the machine (nproc, CPU model), the date and
# the load average, then runs `sdfc bench` on the report's six scenes with the CPU backend at
# 640x480 (5 frames) and 1920x1080 (3 frames), and scene 3 at 640x480 with 1 and 2 threads.
# Every `sdfc bench` times its frames after one untimed warm-up frame and prints the median.
#
# Usage: bench/cpu_renderer.sh   (from anywhere; builds target/release/sdfc if absent)
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$ROOT"
SDFC=./target/release/sdfc
if [ ! -x "$SDFC" ]; then
    cargo build --release
fi

SCENES="examples/seed1.sdf examples/seed2.sdf examples/seed3.sdf examples/seed4.sdf examples/seed5.sdf examples/seed6.sdf"

run() {
    echo
    echo "\$ $*   (load average before: $(cut -d' ' -f1-3 /proc/loadavg))"
    "$@"
}

echo "date: $(date -u)"
echo "nproc: $(nproc)"
echo "cpu: $(lscpu | sed -n 's/^Model name: *//p')"
run "$SDFC" bench $SCENES --backend cpu --size 640x480 --frames 5
run "$SDFC" bench $SCENES --backend cpu --size 1920x1080 --frames 3
run "$SDFC" bench examples/seed3.sdf --backend cpu --size 640x480 --frames 5 --threads 1
run "$SDFC" bench examples/seed3.sdf --backend cpu --size 640x480 --frames 5 --threads 2
