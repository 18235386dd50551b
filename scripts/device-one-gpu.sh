#!/usr/bin/env bash
# Runs on the GPU machine (the `device` tool), for issue 36 (items 2 and 4 on one GPU): the
# build before and after side by side, every command with `--devices 0`:
#   (bench) `sdfc bench examples/seed3.sdf` at 1920x1080 (20 frames) and 7680x4320 aa 2 (5):
#           the median GPU time, wall time and whole-frame host time (launch to pixels in
#           memory), through CUDA and wgpu;
#   (stats) `sdfc render --stats` of seed3 at both sizes: where the run's time goes;
#   (sequence) examples/animation/orbit.sdf, 120 frames at 1920x1080 to numbered PNGs, twice
#           each (frames per second of the whole process), then once with --stats (the tally
#           of where the sequence's time went); the two builds' frames compared;
#   (same) the PNGs of seeds 1-6 at 1920x1080 and of seeds 3 and 6 at 7680x4320 aa 2 of the
#           two builds compared byte for byte.
# Expects the binaries $BEFORE (default .dev/base/sdfc) and $AFTER (default .dev/onegpu/sdfc)
# and the Vulkan loader packages in .gl/ (device-env.sh). The logs go to $OUT/logs.tgz;
# prints the table last.
set -u
. scripts/device-env.sh > /dev/null 2>&1
BEFORE=${BEFORE:-.dev/base/sdfc}; AFTER=${AFTER:-.dev/onegpu/sdfc}
chmod +x "$BEFORE" "$AFTER"
bin() { if [ "$1" = before ]; then echo "$BEFORE"; else echo "$AFTER"; fi; }
T=$OUT/table.txt; : > "$T"; L=$OUT/logs; mkdir -p "$L"; I=/tmp/sdfc-img
fms() { python3 -c 'import json,sys; t=json.load(open(sys.argv[1]))[0]; print("GPU %.2f  wall %.2f  host %.2f ms" % (1e3*t["median_s"], 1e3*t["median_wall_s"], 1e3*t["median_frame_s"]))' "$1" 2>/dev/null || echo "failed: $(tail -n 2 "${1%.json}.log")"; }
fps() { grep -o '([0-9.]* frames/s)' "$1" | tr -d '(' | cut -d' ' -f1; }
ms() { grep -E "^  $1 " "$2" | head -n 1 | awk '{print $2}'; }
# Warm: the kernels compiled and cached (the CUDA JIT's cache, the driver's pipeline cache).
for v in before after; do for b in cuda wgpu; do
  "$(bin $v)" render examples/animation/orbit.sdf --backend $b --devices 0 --size 1920x1080 --frames 0..4 --force -o $I/warm-$b/f_###.png > /dev/null 2>&1
  "$(bin $v)" render examples/seed3.sdf --backend $b --devices 0 --size 1920x1080 -o $I/warm.png > /dev/null 2>&1
done; done
for b in cuda wgpu; do for size in 1920x1080 "7680x4320 --aa 2"; do for v in before after; do
  tag=$v-$b-$(echo "$size" | cut -d' ' -f1); n=20; [ "$size" = 1920x1080 ] || n=5
  # shellcheck disable=SC2086
  "$(bin $v)" bench examples/seed3.sdf --backend $b --devices 0 --size $size --limit memory=65536 --frames $n --json > "$L/b-$tag.json" 2> "$L/b-$tag.log"
  echo "bench $v $b seed3 $size: $(fms "$L/b-$tag.json")" | tee -a "$T"
done; done; done
for b in cuda wgpu; do for size in 1920x1080 "7680x4320 --aa 2"; do for v in before after; do
  tag=$v-$b-$(echo "$size" | cut -d' ' -f1)
  # shellcheck disable=SC2086
  "$(bin $v)" render examples/seed3.sdf --backend $b --devices 0 --size $size --limit memory=65536 --stats -o "$I/st-$tag.png" > "$L/st-$tag.log" 2>&1
  printf 'stats %-6s %-4s %-16s upload %6s frame %6s readback %7s conversion %6s sRGB %6s PNG %7s run %7s ms; %s\n' $v $b "$size" \
    "$(ms upload "$L/st-$tag.log")" "$(ms frame "$L/st-$tag.log")" "$(ms readback "$L/st-$tag.log")" "$(ms conversion "$L/st-$tag.log")" \
    "$(ms sRGB "$L/st-$tag.log")" "$(ms PNG "$L/st-$tag.log")" "$(grep -o '^run *[0-9.]*' "$L/st-$tag.log" | awk '{print $2}')" \
    "$(grep '^frame on host' "$L/st-$tag.log" | cut -c17-)" | tee -a "$T"
done; done; done
for b in cuda wgpu; do for v in before after; do line="sequence $v $b orbit 120 at 1080p f/s:"
  for r in 1 2; do
    rm -rf $I/s-$v-$b
    "$(bin $v)" render examples/animation/orbit.sdf --backend $b --devices 0 --size 1920x1080 --frames 0..120 --force -o $I/s-$v-$b/f_###.png > "$L/seq-$v-$b-$r.log" 2>&1
    line="$line $(fps "$L/seq-$v-$b-$r.log")"
  done
  "$(bin $v)" render examples/animation/orbit.sdf --backend $b --devices 0 --size 1920x1080 --frames 0..120 --force --stats -o $I/t-$v-$b/f_###.png > "$L/seqstats-$v-$b.log" 2>&1
  line="$line (--stats: $(fps "$L/seqstats-$v-$b.log"))"
  echo "$line" | tee -a "$T"
done
  diff -rq $I/s-before-$b $I/s-after-$b > /dev/null && echo "sequence $b: the 120 frames of the two builds are identical" | tee -a "$T" || echo "sequence $b: FRAMES DIFFER" | tee -a "$T"
done
for b in cuda wgpu; do same=0; differ=""; total=0
  for s in "seed1 1920x1080" "seed2 1920x1080" "seed3 1920x1080" "seed4 1920x1080" "seed5 1920x1080" "seed6 1920x1080" "seed3 7680x4320 --aa 2" "seed6 7680x4320 --aa 2"; do
    set -- $s; name=$1-$2; total=$((total + 1))
    for v in before after; do
      # shellcheck disable=SC2086
      "$(bin $v)" render examples/$1.sdf --backend $b --devices 0 --size ${s#* } --limit memory=65536 -o "$I/same-$v-$b-$name.png" > /dev/null 2>&1
    done
    if cmp -s "$I/same-before-$b-$name.png" "$I/same-after-$b-$name.png"; then same=$((same + 1)); else differ="$differ $name"; fi
  done
  echo "same $b: PNG bytes identical before and after: $same of $total${differ:+; DIFFER:$differ}" | tee -a "$T"
done
grep -h -A12 "where the sequence's time went" "$L"/seqstats-*.log > "$OUT/tally.txt"
echo "== $(head -n 1 "$OUT/gpu.txt"), $(tail -n 1 "$OUT/gpu.txt"); $(cat .dev/onegpu/commits.txt 2>/dev/null | tr '\n' ' ')"
tar czf "$OUT/logs.tgz" -C "$OUT" logs && rm -rf "$L"
cat "$T"
