#!/usr/bin/env bash
# Runs on the GPU machine (the `device` tool), for issue 19 (animation): (fps) the sustained
# frame rate of the animated examples at 1920x1080 with `sdfc bench --frames-per-second` on
# CUDA and wgpu, with the distance program's constants read from the kernel's buffer (one
# kernel per sequence when only numbers change) and written as literals (a kernel per frame
# whose numbers change), and the kernels each prepared; (agree) a few frames of each example
# rendered as a sequence on CUDA, wgpu and the CPU at 640x480 and compared, frame by frame.
# Expects the sdfc binary at .dev/sdfc and the Vulkan loader packages in .gl/ (device-env.sh).
# Writes JSON and logs under $OUT; prints tables.
# (cost) what reading constants from the buffer costs a frame: `sdfc bench` of the still
# examples at 1920x1080 on CUDA and wgpu with `--constants literal` and `--constants parameters`.
# Usage: scripts/device-anim.sh [all|fps|agree|cost]   (FRAMES=0..60 sets the timed sequence)
set -u
. "$(dirname "$0")/device-env.sh"
MODE=${1:-all}
SEQ=${FRAMES:-0..60}
SCENES="examples/animation/orbit.sdf examples/animation/bounce.sdf"

if [ "$MODE" = all ] || [ "$MODE" = fps ]; then
  echo "== sequence throughput at 1920x1080, frames $SEQ (first frame untimed)" | tee "$OUT/anim-fps.txt"
  for b in cuda wgpu; do
    for c in parameters literal; do
      echo "-- $b, constants $c" | tee -a "$OUT/anim-fps.txt"
      "$B" bench --frames-per-second --backend "$b" --constants "$c" --size 1920x1080 \
        --sequence "$SEQ" $SCENES --json > "$OUT/anim-$b-$c.json" 2> "$OUT/anim-$b-$c.log" \
        || echo "$b $c FAILED: $(tail -n 3 "$OUT/anim-$b-$c.log")"
      python3 -c '
import json, sys
for t in json.load(open(sys.argv[1])):
    n = t["timed"]
    print("%-12s %-5s %-28s %8.2f frames/s  kernels %3d  per frame: check %.2f ms, prepare %.2f ms, render %.2f ms" % (
        t["scene"].split("/")[-1], t["backend"], t["device"][:28], t["frames_per_s"], t["kernels"],
        1e3 * t["check_s"] / n, 1e3 * t["prepare_s"] / n, 1e3 * t["render_s"] / n))
' "$OUT/anim-$b-$c.json" 2>/dev/null | tee -a "$OUT/anim-fps.txt"
    done
  done
fi

if [ "$MODE" = all ] || [ "$MODE" = agree ]; then
  echo "== frames 0..8 as sequences at 640x480: worst PSNR over the frames against the CPU" | tee "$OUT/anim-agree.txt"
  for f in $SCENES; do
    n=$(basename "$f" .sdf)
    for b in cpu cuda wgpu; do
      "$B" render "$f" --backend "$b" --size 640x480 --frames 0..8 --force \
        -o "/tmp/sdfc-img/anim-$n-$b/f_##.png" > "$OUT/anim-agree-$n-$b.log" 2>&1 \
        || echo "$n $b FAILED: $(tail -n 2 "$OUT/anim-agree-$n-$b.log")"
      echo "$n $b: $(tail -n 1 "$OUT/anim-agree-$n-$b.log")" | tee -a "$OUT/anim-agree.txt"
    done
    for b in cuda wgpu; do
      worst=$(for k in 00 01 02 03 04 05 06 07; do
        "$B" compare "/tmp/sdfc-img/anim-$n-$b/f_$k.png" "/tmp/sdfc-img/anim-$n-cpu/f_$k.png" --json 2>/dev/null \
          | python3 -c 'import json,sys; p=json.load(sys.stdin)["psnr"]; print("inf" if p is None else p)' 2>/dev/null || echo 0
      done | sort -g | head -n 1)
      echo "$n $b-cpu worst ${worst} dB" | tee -a "$OUT/anim-agree.txt"
    done
  done
fi

if [ "$MODE" = all ] || [ "$MODE" = cost ]; then
  echo "== GPU ms per frame at 1920x1080 (median of 5): constants as literals / read from the buffer" | tee "$OUT/anim-cost.txt"
  for b in cuda wgpu; do
    for f in examples/seed1.sdf examples/seed2.sdf examples/seed3.sdf examples/seed4.sdf examples/seed5.sdf examples/seed6.sdf examples/temple.sdf examples/lattice.sdf examples/blends.sdf; do
      n=$(basename "$f" .sdf)
      ms() {
        "$B" bench "$f" --backend "$b" --size 1920x1080 --frames 5 --set method=march --constants "$1" --json 2>/dev/null \
          | python3 -c 'import json,sys; print("%.3f" % (json.load(sys.stdin)[0]["median_s"] * 1e3))' 2>/dev/null || echo failed
      }
      l=$(ms literal); p=$(ms parameters)
      echo "$b $n literal $l ms, parameters $p ms" | tee -a "$OUT/anim-cost.txt"
    done
  done
fi
