#!/usr/bin/env bash
# Two builds of sdfc side by side on the CPU renderer: for each round and scene, runs
# `sdfc bench SCENE --backend cpu --size 640x480` with the old binary and then the new one
# (with 2 threads, and scene 3 with 1 thread too), and prints a Markdown table of the two
# medians and their ratio (new / old). On a shared machine whose speed moves from minute to
# minute, only neighbouring runs compare: the rounds show the spread.
#
# Usage: bench/ab_cpu.sh OLD_SDFC NEW_SDFC
# Environment: AB_ROUNDS (default 3), AB_FRAMES (frames per bench, default 5), AB_SCENES
# (default the report scenes that are sphere traced: seed3 … seed6), AB_SIZE (640x480).
set -euo pipefail

OLD="$1"
NEW="$2"
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$ROOT"
ROUNDS="${AB_ROUNDS:-3}"
FRAMES="${AB_FRAMES:-5}"
SIZE="${AB_SIZE:-640x480}"
SCENES="${AB_SCENES:-seed3 seed4 seed5 seed6}"

# The median column of `sdfc bench`'s table for one run.
median() {
    "$1" bench "examples/$2.sdf" --backend cpu --size "$SIZE" --frames "$FRAMES" --threads "$3" \
        | awk 'NR == 2 { print $7 }'
}

echo "date: $(date -u); $(nproc) cores, $(lscpu | sed -n 's/^Model name: *//p'); load average $(cut -d' ' -f1-3 /proc/loadavg)"
echo "old: $OLD ($("$OLD" --version 2>/dev/null || echo '?')); new: $NEW ($("$NEW" --version 2>/dev/null || echo '?'))"
echo
echo "| scene | threads | round | old median ms | new median ms | new / old |"
echo "|---|---:|---:|---:|---:|---:|"
for round in $(seq 1 "$ROUNDS"); do
    for s in $SCENES "seed3:1"; do
        scene="${s%%:*}"
        threads=2
        [ "$s" != "$scene" ] && threads="${s#*:}"
        a=$(median "$OLD" "$scene" "$threads")
        b=$(median "$NEW" "$scene" "$threads")
        ratio=$(awk -v a="$a" -v b="$b" 'BEGIN { printf "%.2f", b / a }')
        echo "| $scene | $threads | $round | $a | $b | $ratio |"
    done
done
