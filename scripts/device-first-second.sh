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
# GPU time of FRAMES frames. The measuring is scripts/first_second.py; its tables go to
# $OUT/first-second.md and are printed last. Expects the sdfc binary at .dev/sdfc and the
# Vulkan loader packages in .gl/ (scripts/device-env.sh).
set -u
. "$(dirname "$0")/device-env.sh"
SIZE=${SIZE:-1920x1080}
WARM=${WARM:-3}
FRAMES=${FRAMES:-5}
SCALING=${SCALING:-"examples/scaling/compound_1000.sdf examples/scaling/jittered_1024.sdf examples/scaling/lattice_10000.sdf examples/scaling/random_10000.sdf"}
# shellcheck disable=SC2086
python3 "$(dirname "$0")/first_second.py" "$B" --backends "${BACKENDS:-cuda,wgpu}" \
  --size "$SIZE" --warm "$WARM" --frames "$FRAMES" --scaling $SCALING \
  > "$OUT/first-second.log" 2>&1
status=$?
sed -n '/^Whole/,$p' "$OUT/first-second.log" > "$OUT/first-second.md"
cat "$OUT/first-second.md"
cat "$OUT/gpu.txt"
exit $status
