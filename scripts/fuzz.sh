#!/usr/bin/env bash
# Runs one cargo-fuzz target for a number of seconds, seeded from examples/ and tests/in/.
# Usage: scripts/fuzz.sh TARGET SECONDS   (TARGET: front_end or kernel)
set -euo pipefail
cd "$(dirname "$0")/.."
target=${1:-front_end}
seconds=${2:-60}
corpus=fuzz/corpus/$target
mkdir -p "$corpus"
find examples tests/in -name '*.sdf' -exec cp {} "$corpus/" \;
export RUSTC_BOOTSTRAP=1
cd fuzz
cargo fuzz run "$target" "corpus/$target" -- -max_total_time="$seconds" -timeout=30 -rss_limit_mb=4096 -max_len=8192
