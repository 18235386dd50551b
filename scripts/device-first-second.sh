#!/usr/bin/env bash
# Runs on the GPU machine (the `device` tool): where the first second of a whole
# `sdfc render` goes (issue 23, item 1), and the marched scaling scenes of item 5.
# Every example (examples/*.sdf: the six report scenes seed1..6 among them) is rendered at
# SIZE (default 1920x1080) through CUDA and through wgpu as whole processes with --stats:
# cold (sdfc's cache directory and the NVIDIA driver's disk caches empty), warm (all filled;
# median of WARM runs) and with sdfc's cache alone (the driver's disk caches turned off), each
# phase of --stats beside the wall time measured outside; beside them a bare CUDA context
# and a bare Vulkan device created by python3 through ctypes. Then examples/scaling/
# compound_1000.sdf, jittered_1024.sdf (1 024 spheres on a jittered 16x4x16 lattice) and the
# 10 000-sphere scenes, marched (--set method=march), whole runs and `sdfc bench`'s median
# GPU time of FRAMES frames. With PLAIN=N, every example also as N whole warm processes
# without --stats (what a user waits for; medians), alternating with the build at OLD (default
# .dev/sdfc-old, when present) for a before and after. MODES (default cold,warm,sdfc; also
# vulkan: warm with wgpu's instance limited to Vulkan) picks the --stats runs; SCALING=""
# skips the scaling scenes. The measuring is scripts/first_second.py; its tables go to
# $OUT/first-second.md and are printed last. Expects the sdfc binary at .dev/sdfc and the
# Vulkan loader packages in .gl/ (scripts/device-env.sh).
# The first second alone, before and after, in one run (about 5 minutes on an H100):
#   SCALING="" MODES=warm,vulkan WARM=5 PLAIN=7 scripts/device-first-second.sh
set -u
. "$(dirname "$0")/device-env.sh"
SIZE=${SIZE:-1920x1080}
WARM=${WARM:-3}
FRAMES=${FRAMES:-5}
MODES=${MODES:-cold,warm,sdfc}
PLAIN=${PLAIN:-0}
OLD=${OLD:-./.dev/sdfc-old}
SCALING=${SCALING-"examples/scaling/compound_1000.sdf examples/scaling/jittered_1024.sdf examples/scaling/lattice_10000.sdf examples/scaling/random_10000.sdf"}
old=()
if [ -f "$OLD" ]; then
  chmod +x "$OLD"
  old=(--old "$OLD")
fi
# shellcheck disable=SC2086
python3 "$(dirname "$0")/first_second.py" "$B" --backends "${BACKENDS:-cuda,wgpu}" \
  --size "$SIZE" --warm "$WARM" --frames "$FRAMES" --modes "$MODES" --plain "$PLAIN" \
  ${old[@]+"${old[@]}"} --scaling $SCALING > "$OUT/first-second.log" 2>&1
status=$?
sed -n '/^Whole/,$p' "$OUT/first-second.log" > "$OUT/first-second.md"
cat "$OUT/first-second.md"
cat "$OUT/gpu.txt"
exit $status
