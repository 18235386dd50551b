#!/usr/bin/env bash
# How preparing a scene grows with its objects (issue 37): N spheres placed by a `for` loop
# (examples/scaling/random_10000.sdf with `n` replaced), for N from 1 000 to 200 000, each
# rendered once traced and once marched on the CPU at a small size with `--stats`, the
# limits raised so that every N passes. Prints a Markdown table of the phases `--stats`
# names, in ms: the check, the lowering (expansion, simplify, analysis, bounds, program,
# primitives, media), the tapes, the memory bound, the frame and the whole run; and the
# ratio of each run to the one of a tenth as many objects, where there is one (10× the
# objects at linear growth is 10×). One process at a time, one run per row.
#
# Usage: bench/prep_scaling.sh [SDFC]   (default target/release/sdfc)
# Environment: PREP_SIZES (default "1000 2000 5000 10000 20000 50000 100000 200000"),
# PREP_METHODS (default "trace march"), PREP_SIZE (image size, default 64x48).
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
SDFC="$(realpath "${1:-$ROOT/target/release/sdfc}")"
SIZES="${PREP_SIZES:-1000 2000 5000 10000 20000 50000 100000 200000}"
METHODS="${PREP_METHODS:-trace march}"
IMAGE="${PREP_SIZE:-64x48}"
WORK="$(mktemp -d)"
trap 'rm -rf "$WORK"' EXIT

echo "date: $(date -u); $(nproc) cores, $(lscpu | sed -n 's/^Model name: *//p'); load average $(cut -d' ' -f1-3 /proc/loadavg)"
echo "sdfc: $SDFC; commit $(git -C "$ROOT" rev-parse --short HEAD 2>/dev/null || echo '?')"
echo
echo "| objects | method | check | lowering | of which program | tapes | memory | frame | run | run / run at a tenth |"
echo "|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|"
declare -A RUN
for n in $SIZES; do
    scene="$WORK/spheres_$n.sdf"
    sed "s/^let n = 10000;/let n = $n;/" "$ROOT/examples/scaling/random_10000.sdf" > "$scene"
    for method in $METHODS; do
        stats="$WORK/stats_${n}_$method.txt"
        "$SDFC" render "$scene" --backend cpu --size "$IMAGE" --set "method=$method" \
            --limit "objects=$((n + 1))" --limit program=100000000 --limit expansion=100000000 \
            --stats -o "$WORK/out.png" > "$stats" 2> "$WORK/err.txt" || {
            echo "| $n | $method | failed: $(tail -1 "$WORK/err.txt") |"
            continue
        }
        # The phases of `--stats`' run: "  NAME   TIME ms  WHAT".
        row=$(awk '
            /^run / { run = $2 }
            /^  [a-z]/ && $3 == "ms" { t[$1] = $2 }
            END {
                lower = t["expansion"] + t["simplify"] + t["analysis"] + t["bounds"] + t["program"] + t["primitives"] + t["media"]
                printf "%.0f|%.0f|%.0f|%.0f|%.0f|%.0f|%.0f", t["check"], lower, t["program"], t["tapes"], t["memory"], t["frame"], run
            }' "$stats")
        IFS='|' read -r check lower program tapes memory frame run <<< "$row"
        RUN[$n,$method]=$run
        tenth=$((n / 10))
        ratio=""
        if [[ -n "${RUN[$tenth,$method]:-}" ]]; then
            ratio=$(awk -v a="$run" -v b="${RUN[$tenth,$method]}" 'BEGIN { printf "%.1f", a / b }')
        fi
        echo "| $n | $method | $check | $lower | $program | $tapes | $memory | $frame | $run | $ratio |"
    done
done
