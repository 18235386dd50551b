#!/usr/bin/env bash
# Runs on the GPU machine (the `device` tool): the distance conformance suite
# (runtime/tests/render/distance_conformance.rs) on its GPU, through wgpu and CUDA, with a CUDA device
# required (SDFC_REQUIRE_CUDA=1: the suite fails, rather than skips, without one). Expects the
# test binary at .dev/render (the `render` test binary, whose `distance_conformance` module
# this runs), built where the sources are:
#   cargo test --release --test render --no-run
#   cp target/release/deps/render-<hash> .dev/render
# and the Vulkan loader packages in .gl/ (device-env.sh). The test reads ../compiler/tests/in/feature
# and tests/in/conformance from runtime/, as cargo runs it. Writes the suite's report (worst ulps per evaluator) to
# $OUT/distance-conformance.txt and exits with the suite's status.
set -u
. "$(dirname "$0")/device-env.sh"
T=$(pwd)/.dev/render
chmod +x "$T"
cd runtime || exit 2
SDFC_REQUIRE_CUDA=1 "$T" distance_conformance:: --nocapture --test-threads 1 2>&1 | tee "$OUT/distance-conformance.txt"
status=${PIPESTATUS[0]}
cat "$OUT/gpu.txt"
exit "$status"
