#!/usr/bin/env bash
# Runs on the GPU machine (the `device` tool), for issue 23, item 3: the interpreted kernel
# (docs/interpreted.md) against the specialised one, per example and backend (CUDA, wgpu), all
# marched (`--set method=march`, which changes nothing for a scene marched already):
#   ready   the whole `sdfc render` of a 64x64 image, in seconds (the kernel's generation, the
#           drivers' compile, one tiny frame): cold, every cache empty (sdfc's PTX cache, the
#           CUDA JIT cache, the NVIDIA driver's shader disk cache, each pointed at a new
#           folder), then warm, the same command again with those caches kept;
#   frame   `sdfc bench` at $SIZE (default 1920x1080), median of $FRAMES frames (default 5)
#           after a warm-up, in ms, and interpreted / specialised.
# The kernel that actually ran is checked (`render --stats` line `kernel`, bench's JSON field
# `kernel`); a run that fails or exceeds $LIMIT seconds (default 300) shows as FAIL or TIME.
# Expects the sdfc binary at .dev/sdfc and the Vulkan loader packages in .gl/ (device-env.sh).
# Writes the logs and JSON under $OUT/interp/, the table to $OUT/interp.txt, and prints the
# table last.
# Usage: scripts/device-interp.sh [SCENE.sdf...]   (default: examples/*.sdf and
#        examples/scaling/compound_100.sdf, lattice_1000.sdf, random_1000.sdf)
set -u
. "$(dirname "$0")/device-env.sh"
SIZE=${SIZE:-1920x1080}
FRAMES=${FRAMES:-5}
LIMIT=${LIMIT:-300}
if [ $# -gt 0 ]; then
  SCENES="$*"
else
  SCENES="$(ls examples/*.sdf) examples/scaling/compound_100.sdf examples/scaling/lattice_1000.sdf examples/scaling/random_1000.sdf"
fi
LOG="$OUT/interp"
mkdir -p "$LOG"
TABLE="$OUT/interp.txt"

# Points every cache at the folder $1 (made empty when $2 is "cold").
caches() {
  [ "$2" = cold ] && rm -rf "$1"
  mkdir -p "$1/sdfc" "$1/cuda" "$1/gl"
  export SDFC_CACHE_DIR="$1/sdfc" CUDA_CACHE_PATH="$1/cuda" __GL_SHADER_DISK_CACHE_PATH="$1/gl"
  export __GL_SHADER_DISK_CACHE=1 __GL_SHADER_DISK_CACHE_SKIP_CLEANUP=1
}

# ready SCENE BACKEND KERNEL STATE: the wall seconds of a 64x64 render, or FAIL/TIME/WRONG.
ready() {
  local n log start end rc
  n=$(basename "$1" .sdf)
  log="$LOG/ready-$n-$2-$3-$4.txt"
  start=$(date +%s.%N)
  timeout "$LIMIT" "$B" render "$1" --backend "$2" --kernel "$3" --set method=march \
    --size 64x64 --stats -o "/tmp/sdfc-img/interp-$n-$2-$3.png" > "$log" 2>&1
  rc=$?
  end=$(date +%s.%N)
  if [ $rc = 124 ]; then echo TIME; return; fi
  if [ $rc != 0 ]; then echo FAIL; return; fi
  if ! grep -q "^kernel *$3" "$log"; then echo WRONG; return; fi
  python3 -c "print('%.2f' % ($end - $start))"
}

# frame SCENE BACKEND KERNEL: the median frame in ms, or FAIL/TIME/WRONG.
frame() {
  local n json rc
  n=$(basename "$1" .sdf)
  json="$LOG/bench-$n-$2-$3.json"
  timeout "$LIMIT" "$B" bench "$1" --backend "$2" --kernel "$3" --set method=march \
    --size "$SIZE" --frames "$FRAMES" --json > "$json" 2> "$LOG/bench-$n-$2-$3.log"
  rc=$?
  if [ $rc = 124 ]; then echo TIME; return; fi
  if [ $rc != 0 ]; then echo FAIL; return; fi
  python3 - "$json" "$3" <<'PY'
import json, sys
t = json.load(open(sys.argv[1]))[0]
print("%.2f" % (1e3 * t["median_s"]) if t.get("kernel") == sys.argv[2] else "WRONG")
PY
}

ratio() {
  python3 -c "
import sys
try: print('%.2f' % (float(sys.argv[1]) / float(sys.argv[2])))
except Exception: print('-')" "$1" "$2"
}

rows=""
for f in $SCENES; do
  n=$(basename "$f" .sdf)
  ops=$("$B" compile "$f" --emit program 2>/dev/null | head -n 1 | grep -o '[0-9][0-9]*' | head -n 1)
  for b in cuda wgpu; do
    row="$n $b $ops"
    for k in specialised interpreted; do
      caches "/tmp/sdfc-interp-cache-$n-$b-$k" cold
      cold=$(ready "$f" "$b" "$k" cold)
      caches "/tmp/sdfc-interp-cache-$n-$b-$k" warm
      warm=$(ready "$f" "$b" "$k" warm)
      row="$row $cold $warm"
    done
    caches "/tmp/sdfc-interp-cache-bench" warm
    fs=$(frame "$f" "$b" specialised)
    fi=$(frame "$f" "$b" interpreted)
    row="$row $fs $fi $(ratio "$fi" "$fs")"
    echo "$row" | tee -a "$LOG/rows.txt"
    rows="$rows$row
"
  done
done

{
  echo "Interpreted against specialised kernel, marched, both backends ($(head -n 1 "$OUT/gpu.txt"))."
  echo "ready: whole 'sdfc render --size 64x64' in s, cold (caches empty) / warm; frame: 'sdfc bench --size $SIZE', median ms of $FRAMES."
  printf '%-16s %-5s %7s | %8s %8s | %8s %8s | %9s %9s %7s\n' scene backend instr \
    spec_cold spec_warm int_cold int_warm spec_ms int_ms int/spec
  printf '%s' "$rows" | while read -r n b ops sc sw ic iw fs fi r; do
    [ -n "$n" ] || continue
    printf '%-16s %-5s %7s | %8s %8s | %8s %8s | %9s %9s %7s\n' "$n" "$b" "$ops" "$sc" "$sw" "$ic" "$iw" "$fs" "$fi" "$r"
  done
  cat "$OUT/gpu.txt"
} > "$TABLE"
cat "$TABLE"
