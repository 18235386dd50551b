#!/usr/bin/env bash
# Runs one cargo-fuzz target for a number of seconds, starting from the kept seeds
# (fuzz/seeds/*/) and the files of examples/, compiler/tests/in/ and runtime/tests/in/; or, with `seeds`, minimises what
# the runs found (fuzz/corpus/TARGET/, not kept) with the target's seeds into new seeds
# (fuzz/seeds/TARGET/), keeping only what reaches beyond the examples and the other seeds.
# Usage: scripts/fuzz.sh TARGET SECONDS   (TARGET: check, front_end, kernel, lsp or mesh_file)
#        scripts/fuzz.sh TARGET seeds
set -euo pipefail
cd "$(dirname "$0")/.."
target=${1:-check}
seconds=${2:-60}
corpus=fuzz/corpus/$target
seeds=fuzz/seeds/$target
mkdir -p "$corpus" "$seeds"
find examples compiler/tests/in runtime/tests/in -name '*.sdf' -exec cp {} "$corpus/" \;
export RUSTC_BOOTSTRAP=1
cd fuzz
# No sanitizer: the code the targets reach is safe Rust (the compiler's only `unsafe`, the AVX2
# loops of eval/wide.rs, is not reached), and without AddressSanitizer a run executes about
# ten times the inputs. Panics, stack overflows, hangs and memory beyond the limit are caught
# all the same.
flags=(-s none)
options=(-timeout=30 -rss_limit_mb=4096 -max_len=8192)
# Every run starts from the seeds of all targets: the inputs of one are inputs of the others.
others=()
for dir in seeds/*/; do
  [ "$dir" = "seeds/$target/" ] || others+=("${dir%/}")
done
if [ "$seconds" = seeds ]; then
  # libFuzzer's merge adds to its first folder the smallest inputs that reach an edge not yet
  # reached there (edges only, not how often: a few hundred inputs, not thousands). It starts
  # with the examples, which every run copies anyway, and the other targets' seeds, which
  # every run reads: they are removed again, leaving what reaches beyond them.
  fresh=$(mktemp -d)
  cp "corpus/$target"/*.sdf "$fresh/"
  for dir in "${others[@]}"; do cp "$dir"/* "$fresh/" 2>/dev/null || true; done
  known=$(ls "$fresh")
  cargo fuzz run "${flags[@]}" "$target" "$fresh" "seeds/$target" "corpus/$target" -- \
    -merge=1 -use_counters=0 "${options[@]}"
  (cd "$fresh" && rm -f $known)
  rm -rf "seeds/$target"
  mv "$fresh" "seeds/$target"
  echo "fuzz: $(ls "seeds/$target" | wc -l) seeds of $target, $(du -sh --apparent-size "seeds/$target" | cut -f1)"
else
  cargo fuzz run "${flags[@]}" "$target" "corpus/$target" "seeds/$target" "${others[@]}" -- \
    -max_total_time="$seconds" -print_final_stats=1 "${options[@]}"
fi
