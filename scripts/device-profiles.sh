#!/usr/bin/env bash
# Runs on the GPU machine (the `device` tool), for issue 35 (profiles): the examples made of
# profiles (pawn, star, bolt with its screw thread, bracket2d with its lofted chamfers) timed
# at 1920x1080 with `sdfc bench` on CUDA and wgpu, and rendered at 640x480 on the CPU, CUDA
# and wgpu and compared (PSNR, differing pixels). Expects the sdfc binary at .dev/sdfc and the
# Vulkan loader packages in .gl/ (device-env.sh). Writes logs under $OUT; prints a table last.
# Usage: scripts/device-profiles.sh
set -u
. "$(dirname "$0")/device-env.sh"
SCENES="pawn star bolt bracket2d"

short() {
  python3 -c 'import json,sys; d=json.loads(sys.argv[1]); print("%.1f dB %.4f%%" % (d["psnr"], 100 * d["differing"]))' "$1" 2>/dev/null || echo "n/a"
}

for b in cuda wgpu; do
  for n in $SCENES; do
    "$B" bench --backend "$b" --size 1920x1080 "examples/$n.sdf" > "$OUT/bench-$n-$b.txt" 2>&1 \
      || echo "$n $b bench FAILED: $(tail -n 2 "$OUT/bench-$n-$b.txt")"
  done
done
{
  echo "== agreement at 640x480 against the CPU (psnr dB / differing %)"
  for n in $SCENES; do
    for b in cpu cuda wgpu; do
      "$B" render "examples/$n.sdf" --backend "$b" --size 640x480 -o "/tmp/sdfc-img/$n-$b.png" \
        > "$OUT/render-$n-$b.txt" 2>&1 || echo "$n $b render FAILED"
    done
    c=$("$B" compare "/tmp/sdfc-img/$n-cuda.png" "/tmp/sdfc-img/$n-cpu.png" --json 2>&1)
    w=$("$B" compare "/tmp/sdfc-img/$n-wgpu.png" "/tmp/sdfc-img/$n-cpu.png" --json 2>&1)
    printf '%-10s cuda %-22s wgpu %s\n' "$n" "$(short "$c")" "$(short "$w")"
  done
  echo "== sdfc bench at 1920x1080 (the last lines of each)"
  for b in cuda wgpu; do
    for n in $SCENES; do
      printf '%-10s %-5s %s\n' "$n" "$b" "$(tail -n 1 "$OUT/bench-$n-$b.txt")"
    done
  done
} | tee "$OUT/profiles.txt"
