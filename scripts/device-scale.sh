#!/usr/bin/env bash
# Runs on the GPU machine (the `device` tool), for issue 23: (hand) times sdfc beside the
# hand-written CUDA tracer of bench/handwritten at three epsilons; (scale) times every example
# and the scaling scenes at 1920x1080 through CUDA and wgpu (GPU time and wall time, medians of
# `sdfc bench`), marched where the scene allows it, and prints the wgpu/CUDA ratios. Expects
# the sdfc binary at .dev/sdfc and the Vulkan loader packages in .gl/; nvcc on PATH for (hand).
# (walk) times the marched scaling scenes (compound_1000, jittered_1024, random_10000) at
# 1920x1080 through CUDA and wgpu with each of several sdfc binaries, WALK_BINS="label:path
# ..." (a path ending in .gz is unpacked first; default: main:.dev/sdfc-main.gz
# hint:.dev/sdfc-hint.gz new:.dev/sdfc), and checks that every binary's CUDA image equals the
# first's (PSNR inf); WALK_SCENES names other scenes of examples/scaling.
# Usage: scripts/device-scale.sh [all|hand|scale|walk]
set -u
. "$(dirname "$0")/device-env.sh"
MODE=${1:-all}
FRAMES=${FRAMES:-21}

# Median GPU ms, median wall ms and mean steps of one `sdfc bench --json` entry.
med() {
  python3 -c 'import json,sys
try:
    d = json.load(sys.stdin)[0]
    print("%.3f %.3f %.1f" % (d["median_s"] * 1e3, d["median_wall_s"] * 1e3, d["stats"]["steps_mean"]))
except Exception:
    print("n/a n/a n/a")'
}
bench() { "$B" bench "$@" --frames "$FRAMES" --json 2>>"$OUT/bench-errors.txt" | med; }

if [ "$MODE" = all ] || [ "$MODE" = hand ]; then
  nvcc -O3 -arch=sm_90 -o /tmp/tracer bench/handwritten/tracer.cu
  printf '%-28s %10s %10s %10s %10s %8s\n' "hand-written scene" "hand ms" "cuda ms" "wgpu ms" "wgpu wall" "cuda/hand" > "$OUT/hand.txt"
  for e in 1e-3 1e-4 1e-5; do
    for s in 512 1024; do
      h=$(/tmp/tracer "$e" "$s" 1920 1080 "$FRAMES" | python3 -c 'import json,sys; print("%.3f" % json.load(sys.stdin)["median_ms"])')
      read -r c cw _ <<<"$(bench bench/handwritten/scene.sdf --backend cuda --set epsilon=$e --set max_steps=$s)"
      read -r w ww _ <<<"$(bench bench/handwritten/scene.sdf --backend wgpu --set epsilon=$e --set max_steps=$s)"
      r=$(python3 -c "print('%.2f' % ($c / $h))" 2>/dev/null || echo n/a)
      printf '%-28s %10s %10s %10s %10s %8s\n' "eps $e, $s steps" "$h" "$c" "$w" "$ww" "$r" >> "$OUT/hand.txt"
    done
  done
  cat "$OUT/hand.txt"
fi

if [ "$MODE" = all ] || [ "$MODE" = scale ]; then
  printf '%-28s %9s %9s %9s %9s %7s %9s\n' "scene (1920x1080)" "cuda ms" "wgpu ms" "cuda wall" "wgpu wall" "w/c" "w wall-gpu" > "$OUT/scale.txt"
  row() {
    name=$1; shift
    read -r c cw _ <<<"$(bench "$@" --backend cuda --size 1920x1080)"
    read -r w ww _ <<<"$(bench "$@" --backend wgpu --size 1920x1080)"
    r=$(python3 -c "print('%.2f' % ($w / $c))" 2>/dev/null || echo n/a)
    o=$(python3 -c "print('%.3f' % ($ww - $w))" 2>/dev/null || echo n/a)
    printf '%-28s %9s %9s %9s %9s %7s %9s\n' "$name" "$c" "$w" "$cw" "$ww" "$r" "$o" >> "$OUT/scale.txt"
  }
  for f in examples/*.sdf; do row "$(basename "$f" .sdf)" "$f"; done
  for n in compound_100 compound_1000 lattice_1000 random_1000 random_10000; do
    row "$n march" "examples/scaling/$n.sdf" --set method=march
  done
  row "jittered_1024 march" examples/scaling/jittered_1024.sdf --set method=march
  row "jittered_1024 traced" examples/scaling/jittered_1024.sdf
  cat "$OUT/scale.txt"
fi

if [ "$MODE" = walk ]; then
  bins=()
  for spec in ${WALK_BINS:-main:.dev/sdfc-main.gz hint:.dev/sdfc-hint.gz new:.dev/sdfc}; do
    label=${spec%%:*}; path=${spec#*:}
    case "$path" in
      *.gz) gunzip -c "$path" > "/tmp/sdfc-$label" || continue; path=/tmp/sdfc-$label ;;
    esac
    [ -f "$path" ] || { echo "no binary $path" >&2; continue; }
    chmod +x "$path"
    bins+=("$label:$path")
  done
  {
    printf '%-22s %-5s' "scene (1920x1080)" "api"
    for spec in "${bins[@]}"; do printf ' %12s' "${spec%%:*} ms"; done
    printf '\n'
  } > "$OUT/walk.txt"
  for n in ${WALK_SCENES:-compound_1000 jittered_1024 random_10000}; do
    for api in cuda wgpu; do
      printf '%-22s %-5s' "$n march" "$api" >> "$OUT/walk.txt"
      for spec in "${bins[@]}"; do
        B=${spec#*:}
        read -r g _ _ <<<"$(bench "examples/scaling/$n.sdf" --set method=march --backend $api --size 1920x1080)"
        printf ' %12s' "$g" >> "$OUT/walk.txt"
      done
      printf '\n' >> "$OUT/walk.txt"
    done
    first=
    for spec in "${bins[@]}"; do
      label=${spec%%:*}
      "${spec#*:}" render "examples/scaling/$n.sdf" --set method=march --backend cuda --size 1920x1080 \
        -o "/tmp/sdfc-img/walk-$n-$label.png" >/dev/null 2>>"$OUT/bench-errors.txt"
      if [ -z "$first" ]; then first=$label; continue; fi
      psnr=$("$B" compare "/tmp/sdfc-img/walk-$n-$first.png" "/tmp/sdfc-img/walk-$n-$label.png" 2>&1 | awk '/^psnr/ {print $2, $3}')
      echo "$n: $label against $first, CUDA image: PSNR $psnr" >> "$OUT/walk.txt"
    done
  done
  cat "$OUT/walk.txt"
fi
