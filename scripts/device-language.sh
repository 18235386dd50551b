#!/usr/bin/env bash
# The GPU frame of the language's new examples, and the old examples with the build before
# the language work beside this one (a scene that uses nothing new must not slow down):
# `sdfc bench` medians at 1920x1080, aa 1, through CUDA and wgpu, as one Markdown table.
# Runs on the GPU machine (the `device` tool), with scripts/device-env.sh's setup; the new
# binary in .dev/sdfc, the old one in .dev/sdfc-old.
# Usage: scripts/device-language.sh "NEW EXAMPLES..." "OLD EXAMPLES..."
set -uo pipefail
cd "$(dirname "$0")/.."
. scripts/device-env.sh
OLD=./.dev/sdfc-old
chmod +x "$OLD"
FRAMES=${FRAMES:-20}
median() { # binary scene backend
    "$1" bench "examples/$2.sdf" --backend "$3" --size 1920x1080 --frames "$FRAMES" 2>/dev/null \
        | awk 'NR == 2 { print $7 }'
}
echo "| scene | backend | old median ms | new median ms | new / old |"
echo "|---|---|---:|---:|---:|"
for backend in cuda wgpu; do
    for s in $2; do
        median "$OLD" "$s" "$backend" >/dev/null # warm the kernel caches
        a=$(median "$OLD" "$s" "$backend"); b=$(median "$B" "$s" "$backend")
        r=$(awk -v a="$a" -v b="$b" 'BEGIN { if (a > 0) printf "%.2f", b / a; else print "-" }')
        echo "| $s | $backend | $a | $b | $r |"
    done
    for s in $1; do
        median "$B" "$s" "$backend" >/dev/null
        b=$(median "$B" "$s" "$backend")
        echo "| $s | $backend | (new) | $b | |"
    done
done
