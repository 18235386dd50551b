#!/usr/bin/env bash
# Runs on the GPU machine (the `device` tool), for issue 36 (frames finished on the GPU): where
# a frame's time goes on the host, before and after, side by side in one run:
#   (stats) `sdfc render --stats` of examples/seed3.sdf at 1920x1080 and at 7680x4320 aa 2,
#           through CUDA and wgpu: upload, frame (launches), readback, conversion, sRGB, PNG,
#           and the whole run from the process's start;
#   (sequence) examples/animation/orbit.sdf, 120 frames at 1920x1080 written as numbered PNGs
#           with `sdfc render --frames` (frames per second over the whole sequence);
#   (same) the PNGs of seeds 1-6 at 1920x1080 of the two binaries compared byte for byte (the
#           pixels the kernel finishes against the host's sRGB encoding of its linear colours);
#   (first) the warm first picture: `sdfc render` of seed3 at 320x240, the whole process.
# Expects the binaries at .dev/frames/sdfc (after) and .dev/frames/sdfc-before (before; left
# out when missing) and the Vulkan loader packages in .gl/ (device-env.sh).
# Writes the logs under $OUT; prints the table last.
# Usage: scripts/device-render-path.sh [all|stats|sequence|same|first]
set -u
. "$(dirname "$0")/device-env.sh"
MODE=${1:-all}
DIR=${DIR:-.dev/frames}
BACKENDS=${BACKENDS:-cuda wgpu}
BINS=after
[ -x "$DIR/sdfc-before" ] && BINS="before after"
chmod +x "$DIR"/sdfc* 2>/dev/null
bin() { if [ "$1" = before ]; then echo "$DIR/sdfc-before"; else echo "$DIR/sdfc"; fi; }
TABLE="$OUT/path-table.txt"
: > "$TABLE"
ms() { grep -E "^  $1 " "$2" | head -n 1 | awk '{print $2}'; }

if [ "$MODE" = all ] || [ "$MODE" = stats ]; then
  for b in $BACKENDS; do
    for v in $BINS; do
      X=$(bin $v)
      # Warm: the kernels compiled and cached (the driver's JIT, the pipeline cache).
      "$X" render examples/seed3.sdf --backend "$b" --size 1920x1080 -o /tmp/sdfc-img/warm.png > /dev/null 2>&1
      "$X" render examples/seed3.sdf --backend "$b" --size 7680x4320 --aa 2 --limit memory=65536 -o /tmp/sdfc-img/warm.png > /dev/null 2>&1
      for size in 1920x1080 "7680x4320 --aa 2"; do
        tag="$v-$b-$(echo "$size" | cut -d' ' -f1)"
        # shellcheck disable=SC2086
        "$X" render examples/seed3.sdf --backend "$b" --size $size --limit memory=65536 --stats \
          -o "/tmp/sdfc-img/$tag.png" > "$OUT/path-$tag.log" 2>&1 || echo "$tag FAILED: $(tail -n 3 "$OUT/path-$tag.log")"
        run=$(grep -o '^run *[0-9.]*' "$OUT/path-$tag.log" | awk '{print $2}')
        printf '%-6s %-5s %-16s upload %7s  frame %7s  readback %8s  conversion %7s  sRGB %6s  PNG %7s  run %8s ms\n' \
          "$v" "$b" "$size" "$(ms upload "$OUT/path-$tag.log")" "$(ms frame "$OUT/path-$tag.log")" \
          "$(ms readback "$OUT/path-$tag.log")" "$(ms conversion "$OUT/path-$tag.log")" \
          "$(ms sRGB "$OUT/path-$tag.log")" "$(ms PNG "$OUT/path-$tag.log")" "$run" | tee -a "$TABLE"
      done
    done
  done
fi

if [ "$MODE" = all ] || [ "$MODE" = sequence ]; then
  for b in $BACKENDS; do
    for v in $BINS; do
      X=$(bin $v)
      rm -rf "/tmp/sdfc-img/seq-$v-$b"
      "$X" render examples/animation/orbit.sdf --backend "$b" --size 1920x1080 --frames 0..120 --force \
        -o "/tmp/sdfc-img/seq-$v-$b/f_###.png" > "$OUT/path-seq-$v-$b.log" 2>&1 \
        || echo "$v $b sequence FAILED: $(tail -n 3 "$OUT/path-seq-$v-$b.log")"
      fps=$(grep -o '([0-9.]* frames/s)' "$OUT/path-seq-$v-$b.log" | tr -d '(' | cut -d' ' -f1)
      printf '%-6s %-5s orbit.sdf 120 frames at 1920x1080: %s frames/s\n' "$v" "$b" "${fps:-n/a}" | tee -a "$TABLE"
    done
    if [ "$BINS" = "before after" ]; then
      diff -rq "/tmp/sdfc-img/seq-before-$b" "/tmp/sdfc-img/seq-after-$b" > /dev/null \
        && echo "$b: the 120 frames of the two binaries are identical" | tee -a "$TABLE" \
        || echo "$b: FRAMES DIFFER between the binaries" | tee -a "$TABLE"
    fi
  done
fi

if { [ "$MODE" = all ] || [ "$MODE" = same ]; } && [ "$BINS" = "before after" ]; then
  for b in $BACKENDS; do
    same=0; differ=""
    for s in seed1 seed2 seed3 seed4 seed5 seed6; do
      for v in before after; do
        "$(bin $v)" render "examples/$s.sdf" --backend "$b" --size 1920x1080 -o "/tmp/sdfc-img/same-$v-$b-$s.png" > /dev/null 2>&1
      done
      if cmp -s "/tmp/sdfc-img/same-before-$b-$s.png" "/tmp/sdfc-img/same-after-$b-$s.png"; then
        same=$((same + 1))
      else
        differ="$differ $s($("$(bin after)" compare "/tmp/sdfc-img/same-before-$b-$s.png" "/tmp/sdfc-img/same-after-$b-$s.png" 2>&1 | head -n 2 | tr '\n' ' '))"
      fi
    done
    echo "$b: seeds 1-6 at 1080p, PNG bytes identical before and after: $same of 6${differ:+; differ:$differ}" | tee -a "$TABLE"
  done
fi

if [ "$MODE" = all ] || [ "$MODE" = first ]; then
  for b in $BACKENDS; do
    for v in $BINS; do
      X=$(bin $v)
      "$X" render examples/seed3.sdf --backend "$b" --size 320x240 -o /tmp/sdfc-img/first.png > /dev/null 2>&1
      t=""
      for i in 1 2 3; do
        s=$(date +%s.%N)
        "$X" render examples/seed3.sdf --backend "$b" --size 320x240 -o /tmp/sdfc-img/first.png > /dev/null 2>&1
        t="$t $(python3 -c "import sys; print('%.3f' % (float(sys.argv[2]) - float(sys.argv[1])))" "$s" "$(date +%s.%N)")"
      done
      printf '%-6s %-5s warm first picture (seed3 320x240, whole process, 3 runs): %s s\n' "$v" "$b" "$t" | tee -a "$TABLE"
    done
  done
fi

echo
echo "== the render path ($(head -n 1 "$OUT/gpu.txt"); $(sed -n 2p "$OUT/gpu.txt"))"
cat "$TABLE"
