#!/usr/bin/env bash
# Runs on the GPU machine (the `device` tool), for issues 9 and 8: (check) renders the
# analytically traced examples at 1920x1080 with the CPU, wgpu and CUDA and compares them,
# and against the CPU's sphere-traced render of the same file; (analytic) times scenes 1 and 2
# traced against marched with bench/analytic.sh on CUDA and wgpu; (scaling) times the
# scaling scenes (examples/scaling) at 1920x1080 on CUDA, marched with culling and (all
# but the compound scenes) traced. Expects the sdfc binary at .dev/sdfc and the Vulkan loader packages
# in .gl/. Writes logs under $OUT; prints tables.
# (agree) renders the scenes of the newer code paths with the CPU, CUDA and wgpu at 640x480
# and compares them.
# (pareto) draws the GPU speed-accuracy charts of the report scenes in $PARETO on
# $PARETO_BACKEND (cuda or wgpu).
# Usage: scripts/device-analytic.sh [all|check|agree|analytic|scaling|pareto]
set -u
. "$(dirname "$0")/device-env.sh"
MODE=${1:-all}

short() {
  python3 -c 'import json,sys; d=json.loads(sys.argv[1]); print("%.1f dB %.4f%%" % (d["psnr"], 100 * d["differing"]))' "$1" 2>/dev/null || echo "n/a"
}

if [ "$MODE" = all ] || [ "$MODE" = check ]; then
  echo "== traced examples at 1920x1080 (psnr dB / differing %)" | tee "$OUT/conformance.txt"
  for n in seed1 seed2 primitives; do
    f=examples/$n.sdf
    for b in cpu wgpu cuda; do
      "$B" render "$f" --backend "$b" --size 1920x1080 -o "/tmp/sdfc-img/$n-$b.png" --stats > "$OUT/render-$n-$b.txt" 2>&1 || echo "$n $b FAILED: $(tail -n 2 "$OUT/render-$n-$b.txt")"
    done
    "$B" render "$f" --backend cpu --size 1920x1080 --set method=march -o "/tmp/sdfc-img/$n-march.png" > "$OUT/render-$n-march.txt" 2>&1
    wc=$("$B" compare "/tmp/sdfc-img/$n-wgpu.png" "/tmp/sdfc-img/$n-cpu.png" --json 2>&1)
    cc=$("$B" compare "/tmp/sdfc-img/$n-cuda.png" "/tmp/sdfc-img/$n-cpu.png" --json 2>&1)
    cw=$("$B" compare "/tmp/sdfc-img/$n-cuda.png" "/tmp/sdfc-img/$n-wgpu.png" --json 2>&1)
    cm=$("$B" compare "/tmp/sdfc-img/$n-cuda.png" "/tmp/sdfc-img/$n-march.png" --json 2>&1)
    echo "$n  wgpu-cpu $(short "$wc") | cuda-cpu $(short "$cc") | cuda-wgpu $(short "$cw") | cuda traced - cpu marched $(short "$cm")" | tee -a "$OUT/conformance.txt"
  done
fi

if [ "$MODE" = all ] || [ "$MODE" = agree ]; then
  # Scenes of the newer code paths at 640x480: traced from the scene buffer (over 256
  # primitives), local bounds (temple's twisted columns), neighbouring cells (overlapping
  # repetition), far from the origin; CUDA and wgpu against the CPU.
  echo "== agreement at 640x480 (psnr dB / differing %)" | tee "$OUT/agree.txt"
  for f in examples/scaling/random_1000.sdf examples/scaling/random_10000.sdf examples/scaling/compound_1000.sdf examples/lattice.sdf examples/temple.sdf compiler/tests/in/ok/neighbours.sdf runtime/tests/stability/far.sdf; do
    n=$(basename "$f" .sdf)
    for b in cpu cuda wgpu; do
      timeout 120 "$B" render "$f" --backend "$b" --size 640x480 -o "/tmp/sdfc-img/$n-$b.png" > "$OUT/agree-$n-$b.txt" 2>&1 || echo "$n $b FAILED: $(tail -n 2 "$OUT/agree-$n-$b.txt")"
    done
    cc=$("$B" compare "/tmp/sdfc-img/$n-cuda.png" "/tmp/sdfc-img/$n-cpu.png" --json 2>&1)
    wc=$("$B" compare "/tmp/sdfc-img/$n-wgpu.png" "/tmp/sdfc-img/$n-cpu.png" --json 2>&1)
    echo "$n  cuda-cpu $(short "$cc") | wgpu-cpu $(short "$wc")" | tee -a "$OUT/agree.txt"
  done
fi

if [ "$MODE" = pareto ]; then
  # The GPU speed-accuracy charts of docs/accuracy.md for the report scenes in $PARETO
  # (default: all six) on $PARETO_BACKEND (default cuda): scripts/charts.sh, to $OUT.
  SCENES=${PARETO:-1 2 3 4 5 6} B=$B OUT=$OUT bash scripts/charts.sh "${PARETO_BACKEND:-cuda}"
fi

if [ "$MODE" = all ] || [ "$MODE" = analytic ]; then
  for b in cuda wgpu; do
    echo "== analytic against marched, $b" | tee "$OUT/analytic-$b.md"
    FRAMES=${FRAMES:-5} JSON_DIR="$OUT/json-$b" bench/analytic.sh "$b" "$B" | tee -a "$OUT/analytic-$b.md"
  done
fi

if [ "$MODE" = all ] || [ "$MODE" = scaling ]; then
  echo "== scaling on CUDA at 1920x1080, aa 1: median ms (5 frames)" | tee "$OUT/scaling.md"
  echo "| scene | marched (culled) | traced |" | tee -a "$OUT/scaling.md"
  echo "|---|---:|---:|" | tee -a "$OUT/scaling.md"
  ms() {
    "$B" bench "$1" --backend cuda --size 1920x1080 --aa 1 --frames 5 --set "method=$2" --json 2>/dev/null \
      | python3 -c 'import json,sys; print("%.2f" % (json.load(sys.stdin)[0]["median_s"] * 1e3))' 2>/dev/null || echo failed
  }
  for kind in random lattice compound; do
    for n in ${SCALING_N:-10 100 1000 10000}; do
      f=examples/scaling/${kind}_$n.sdf
      # Preparing the kernel of compound_10000 takes minutes (naga's WGSL front end is
      # quadratic in a function's length: see BENCHMARKS.md); it is left out.
      if [ "$kind" = compound ] && [ "$n" = 10000 ]; then continue; fi
      # The marched kernel of 10 000 objects takes the driver's JIT minutes: left out.
      m="-"
      if [ "$n" -le "${MARCH_MAX_N:-1000}" ]; then
        m=$(timeout 200 bash -c "$(declare -f ms); B=$B; ms $f march" || echo "timed out")
      fi
      t="-"
      if [ "$kind" != compound ]; then t=$(ms "$f" trace); fi
      echo "| ${kind}_$n | $m | $t |" | tee -a "$OUT/scaling.md"
    done
  done
fi
