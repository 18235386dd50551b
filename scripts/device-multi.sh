#!/usr/bin/env bash
# Runs on the GPU machine (the `device` tool), for issue 20 (several devices): the speed-up of
# `--devices` over one device
#   (still) seeds 3, 5, 6 and temple at 7680x4320, aa 2, with `sdfc bench` (one warm-up frame,
#           then the median host time of the whole frame: setup, launches, readback and
#           conversion, `median_frame_s`), on CUDA and on wgpu;
#   (sequence) examples/animation/orbit.sdf, 120 frames at 1920x1080 written as numbered
#           PNGs with `sdfc render --frames` (frames per second over the whole sequence);
#   (same) each still at 3840x2160, aa 2, rendered on one device and on the devices, compared
#           (`sdfc compare`: identical on GPUs of one backend);
#   (cpu) the CPU as an extra device: seed3 and seed6 at 1920x1080 with `--devices cpu,0`
#           against `--devices 0` (whether the CPU speeds a GPU render up or slows it down).
# With two GPUs or more the devices are all of them (`--devices all`); with one GPU it measures
# the split-GPU case, GPU 0 opened twice as two logical devices (`--devices 0,0`: two CUDA
# streams, or two wgpu devices on one adapter), which shows the scheduler's overhead and what
# overlapping one device's readback with the other's launches gains.
# Expects the sdfc binary at .dev/sdfc and the Vulkan loader packages in .gl/ (device-env.sh).
# Writes JSON and logs under $OUT; prints the table last.
# Usage: scripts/device-multi.sh [all|still|sequence|same|cpu]   (DEVICES=0,1 overrides the devices;
#        BACKENDS="cuda" limits the backends; FRAMES=3 sets the timed frames of a still;
#        STILL=7680x4320, SAME=3840x2160, SEQUENCE=1920x1080 and COUNT=120 set the sizes and
#        the sequence's length, for a quick try on a small machine)
set -u
. "$(dirname "$0")/device-env.sh"
MODE=${1:-all}
BACKENDS=${BACKENDS:-cuda wgpu}
TIMED=${FRAMES:-3}
STILL=${STILL:-7680x4320}
SAME=${SAME:-3840x2160}
SEQUENCE=${SEQUENCE:-1920x1080}
COUNT=${COUNT:-120}
GPUS=$(nvidia-smi -L 2>/dev/null | grep -c '^GPU' || true)
if [ -n "${DEVICES:-}" ]; then
  MULTI=$DEVICES
elif [ "${GPUS:-0}" -ge 2 ]; then
  MULTI=all
else
  MULTI=0,0
fi
echo "GPUs: ${GPUS:-0}; several devices: --devices $MULTI" | tee -a "$OUT/gpu.txt"
"$B" devices | tee "$OUT/multi-devices.txt"
SCENES="seed3 seed5 seed6 temple"
TABLE="$OUT/multi-table.txt"
: > "$TABLE"

# The median whole-frame time (ms) and the devices of a `sdfc bench --json` file.
frame_ms() {
  python3 -c '
import json, sys
t = json.load(open(sys.argv[1]))[0]
print("%.1f" % (1e3 * t["median_frame_s"]))
' "$1" 2>/dev/null || echo nan
}

if [ "$MODE" = all ] || [ "$MODE" = still ]; then
  echo "== stills at $STILL, aa 2: median whole frame over $TIMED frames" | tee "$OUT/multi-still.txt"
  for b in $BACKENDS; do
    for s in $SCENES; do
      for d in 0 "$MULTI"; do
        tag=$(echo "$d" | tr ',' '-')
        # 8K at aa 2 reads back 1.6 GB a device (image and per-pixel statistics): above the
        # default memory limit.
        "$B" bench "examples/$s.sdf" --backend "$b" --devices "$d" --size "$STILL" --aa 2 \
          --limit memory=65536 --frames "$TIMED" --json > "$OUT/multi-$b-$s-$tag.json" 2> "$OUT/multi-$b-$s-$tag.log" \
          || echo "$b $s --devices $d FAILED: $(tail -n 3 "$OUT/multi-$b-$s-$tag.log")"
      done
      one=$(frame_ms "$OUT/multi-$b-$s-0.json")
      many=$(frame_ms "$OUT/multi-$b-$s-$(echo "$MULTI" | tr ',' '-').json")
      line=$(python3 -c '
import sys
b, s, one, many = sys.argv[1:5]
try:
    x = "%.2fx" % (float(one) / float(many))
except (ValueError, ZeroDivisionError):
    x = "n/a"
print("%-5s %-7s %-18s %10s ms %10s ms %8s" % (b, s, sys.argv[5] + " aa 2", one, many, x))
' "$b" "$s" "$one" "$many" "$STILL")
      echo "$line" | tee -a "$OUT/multi-still.txt" >> "$TABLE"
    done
  done
fi

if [ "$MODE" = all ] || [ "$MODE" = sequence ]; then
  echo "== examples/animation/orbit.sdf, frames 0..$COUNT at $SEQUENCE, numbered PNGs" | tee "$OUT/multi-sequence.txt"
  for b in $BACKENDS; do
    for d in 0 "$MULTI"; do
      tag=$(echo "$d" | tr ',' '-')
      rm -rf "/tmp/sdfc-img/multi-seq-$b-$tag"
      "$B" render examples/animation/orbit.sdf --backend "$b" --devices "$d" --size "$SEQUENCE" \
        --frames "0..$COUNT" --force -o "/tmp/sdfc-img/multi-seq-$b-$tag/f_###.png" \
        > "$OUT/multi-seq-$b-$tag.log" 2>&1 \
        || echo "$b sequence --devices $d FAILED: $(tail -n 3 "$OUT/multi-seq-$b-$tag.log")"
      tail -n 1 "$OUT/multi-seq-$b-$tag.log" | tee -a "$OUT/multi-sequence.txt"
    done
    one=$(grep -o '([0-9.]* frames/s)' "$OUT/multi-seq-$b-0.log" | tr -d '(' | cut -d' ' -f1)
    many=$(grep -o '([0-9.]* frames/s)' "$OUT/multi-seq-$b-$(echo "$MULTI" | tr ',' '-').log" | tr -d '(' | cut -d' ' -f1)
    line=$(python3 -c '
import sys
b, one, many = sys.argv[1:4]
try:
    x = "%.2fx" % (float(many) / float(one))
except (ValueError, ZeroDivisionError):
    x = "n/a"
print("%-5s %-7s %-18s %8s f/s %8s f/s %8s" % (b, "orbit", sys.argv[4], one, many, x))
' "$b" "${one:-nan}" "${many:-nan}" "$COUNT x $SEQUENCE")
    echo "$line" | tee -a "$OUT/multi-sequence.txt" >> "$TABLE"
    # The frames are the same on one device and on several.
    diff -rq "/tmp/sdfc-img/multi-seq-$b-0" "/tmp/sdfc-img/multi-seq-$b-$(echo "$MULTI" | tr ',' '-')" \
      > /dev/null && echo "$b: the $COUNT frames are identical" | tee -a "$OUT/multi-sequence.txt" \
      || echo "$b: FRAMES DIFFER" | tee -a "$OUT/multi-sequence.txt"
  done
fi

if [ "$MODE" = all ] || [ "$MODE" = same ]; then
  echo "== one device against --devices $MULTI at $SAME, aa 2 (sdfc compare)" | tee "$OUT/multi-same.txt"
  for b in $BACKENDS; do
    for s in $SCENES; do
      for d in 0 "$MULTI"; do
        tag=$(echo "$d" | tr ',' '-')
        "$B" render "examples/$s.sdf" --backend "$b" --devices "$d" --size "$SAME" --aa 2 \
          -o "/tmp/sdfc-img/multi-$b-$s-$tag.png" > "$OUT/multi-same-$b-$s-$tag.log" 2>&1 \
          || echo "$b $s --devices $d FAILED: $(tail -n 3 "$OUT/multi-same-$b-$s-$tag.log")"
      done
      echo "$b $s: $("$B" compare "/tmp/sdfc-img/multi-$b-$s-0.png" \
        "/tmp/sdfc-img/multi-$b-$s-$(echo "$MULTI" | tr ',' '-').png" 2>&1 | head -n 4 | tr '\n' ' ')" \
        | tee -a "$OUT/multi-same.txt"
    done
  done
fi

if [ "$MODE" = all ] || [ "$MODE" = cpu ]; then
  echo "== the CPU beside GPU 0 at $SEQUENCE, aa 1: median whole frame over $TIMED frames" | tee "$OUT/multi-cpu.txt"
  for b in $BACKENDS; do
    for s in seed3 seed6; do
      for d in 0 cpu,0; do
        tag=$(echo "$d" | tr ',' '-')
        "$B" bench "examples/$s.sdf" --backend "$b" --devices "$d" --size "$SEQUENCE" --aa 1 \
          --frames "$TIMED" --json > "$OUT/multi-cpu-$b-$s-$tag.json" 2> "$OUT/multi-cpu-$b-$s-$tag.log" \
          || echo "$b $s --devices $d FAILED: $(tail -n 3 "$OUT/multi-cpu-$b-$s-$tag.log")"
      done
      line=$(python3 -c '
import sys
b, s, one, many, size = sys.argv[1:6]
try:
    x = "%.2fx" % (float(one) / float(many))
except (ValueError, ZeroDivisionError):
    x = "n/a"
print("%-5s %-7s %-18s %10s ms %10s ms %8s" % (b, s, size + " +cpu", one, many, x))
' "$b" "$s" "$(frame_ms "$OUT/multi-cpu-$b-$s-0.json")" "$(frame_ms "$OUT/multi-cpu-$b-$s-cpu-0.json")" "$SEQUENCE")
      echo "$line" | tee -a "$OUT/multi-cpu.txt" >> "$TABLE"
    done
  done
fi

echo
echo "== speed-up over one device: --devices $MULTI (rows marked +cpu: --devices cpu,0) ($(head -n 1 "$OUT/gpu.txt"))"
printf '%-5s %-7s %-18s %13s %13s %8s\n' backend scene work "one device" "--devices" speed-up
cat "$TABLE"
