#!/usr/bin/env bash
# Analytic ray tracing against sphere tracing (issue 9): times the report's scenes 1 and 2
# (examples/seed1.sdf, seed2.sdf) with `sdfc bench` at the report's resolutions (640x480,
# 1024x768, 1920x1080) and aa 1, 4 and 8 (8 = an 8x8 grid, 64 samples per pixel, as in the
# report), once with `--set method=trace` and once with `--set method=march`, on one backend.
# Every `sdfc bench` times its frames after one untimed warm-up frame and reports the median
# (GPU time on GPU backends). Prints the machine, the date, then one Markdown row per
# (scene, size, aa): median milliseconds traced, marched, and marched / traced.
#
# Usage: bench/analytic.sh BACKEND [SDFC]   BACKEND: cpu, wgpu or cuda; SDFC: the binary
#        (default target/release/sdfc).
# Environment: FRAMES (timed frames per command, default 3), MAX_MARCH_SAMPLES (skip the
# marched render when width x height x aa^2 exceeds it; default: no limit; used on a slow
# CPU, where a 1920x1080 render at 64 samples per pixel takes minutes), JSON_DIR (keep each
# command's JSON there).
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$ROOT"
BACKEND=${1:?usage: bench/analytic.sh cpu|wgpu|cuda [SDFC]}
SDFC=${2:-./target/release/sdfc}
FRAMES=${FRAMES:-3}
MAX_MARCH_SAMPLES=${MAX_MARCH_SAMPLES:-0}
JSON_DIR=${JSON_DIR:-}

echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ *//')"
if command -v nvidia-smi >/dev/null 2>&1; then
    echo "gpu: $(nvidia-smi --query-gpu=name,driver_version --format=csv,noheader | head -n 1)"
fi
echo "date: $(date -u '+%Y-%m-%d %H:%M UTC'), backend $BACKEND, $FRAMES frames per command"

median() {
    # The median frame time in seconds from `sdfc bench --json` output.
    python3 -c 'import json,sys; d=json.load(sys.stdin); d=d[0] if isinstance(d,list) else d; print("%.3f" % (d["median_s"] * 1e3))'
}

time_one() {
    local file=$1 size=$2 aa=$3 method=$4
    local out
    # A crash after the JSON is printed (seen with wgpu at process exit) still gives a
    # figure; a command that printed none shows as "failed".
    out=$("$SDFC" bench "$file" --backend "$BACKEND" --size "$size" --aa "$aa" \
        --set "method=$method" --frames "$FRAMES" --json 2>/dev/null || true)
    if [ -n "$JSON_DIR" ]; then
        mkdir -p "$JSON_DIR"
        echo "$out" > "$JSON_DIR/$(basename "$file" .sdf)-$size-aa$aa-$method.json"
    fi
    echo "$out" | median 2>/dev/null || echo failed
}

echo
echo "| scene | size | aa | traced (ms) | marched (ms) | marched / traced |"
echo "|---|---|---:|---:|---:|---:|"
for scene in seed1 seed2; do
    for size in 640x480 1024x768 1920x1080; do
        for aa in 1 4 8; do
            w=${size%x*}
            h=${size#*x}
            samples=$((w * h * aa * aa))
            traced=$(time_one "examples/$scene.sdf" "$size" "$aa" trace)
            if [ "$MAX_MARCH_SAMPLES" -gt 0 ] && [ "$samples" -gt "$MAX_MARCH_SAMPLES" ]; then
                marched="not run"
                ratio=""
            else
                marched=$(time_one "examples/$scene.sdf" "$size" "$aa" march)
                ratio=$(python3 -c "print(f'{$marched / $traced:.1f}')" 2>/dev/null || echo "")
            fi
            echo "| $scene | $size | $aa | $traced | $marched | $ratio |"
        done
    done
done
