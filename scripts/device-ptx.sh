#!/usr/bin/env bash
# Runs on the GPU machine (the `device` tool): renders every example's PTX kernel (CUDA) next to
# its WGSL kernel (wgpu) on the same GPU and compares the two images, failing when they
# disagree beyond the tolerance below; then renders examples/lattice.sdf through wgpu REPEAT
# times and counts the runs that did not exit cleanly (the crash at exit once seen on an H200).
# Expects the sdfc binary at .dev/sdfc and the Vulkan loader packages in .gl/. Writes the
# table to $OUT/ptx-vs-wgsl.txt (the renders' logs stay in /tmp/sdfc-img); prints it last, and exits 1 if any pair disagrees or any run
# failed.
set -u
. "$(dirname "$0")/device-env.sh"
SIZE=${SIZE:-960x540}
REPEAT=${REPEAT:-10}
# The PTX is translated from the validated WGSL kernel, so the two compute the same IEEE
# operations up to the drivers' own code generation (fused multiply-adds, approximate
# functions): the images agree far above this, and a translation bug falls far below it.
MIN_PSNR=${MIN_PSNR:-40}
MAX_DIFFERING=${MAX_DIFFERING:-0.005}

status=0
table="$OUT/ptx-vs-wgsl.txt"
printf '%-16s %9s %10s %10s %10s\n' scene psnr_dB differing cuda_s wgpu_s | tee "$table"
# compound_1000 (4 000 marched instances walked from `scene_data`, through the shape functions
# lowered by lower/shapes.rs) and random_1000 (1 000 traced primitives read from `scene_data`)
# launch the kernel with its fifth parameter, which the CUDA launcher checks before launching.
for f in examples/*.sdf examples/scaling/compound_100.sdf examples/scaling/lattice_100.sdf examples/scaling/random_100.sdf \
    examples/scaling/compound_1000.sdf examples/scaling/random_1000.sdf; do
  n=$(basename "$f" .sdf)
  ok=1
  for b in cuda wgpu; do
    if ! "$B" render "$f" --backend "$b" --size "$SIZE" -o "/tmp/sdfc-img/$n-$b.png" --stats > "/tmp/sdfc-img/ptx-$n-$b.txt" 2>&1; then
      echo "$n: $b render FAILED: $(tail -n 2 "/tmp/sdfc-img/ptx-$n-$b.txt")"
      ok=0
    fi
  done
  if [ $ok = 0 ]; then status=1; continue; fi
  json=$("$B" compare "/tmp/sdfc-img/$n-cuda.png" "/tmp/sdfc-img/$n-wgpu.png" --json 2>&1)
  line=$(python3 - "$json" "$n" "$MIN_PSNR" "$MAX_DIFFERING" "/tmp/sdfc-img/ptx-$n-cuda.txt" "/tmp/sdfc-img/ptx-$n-wgpu.txt" <<'PY'
import json, re, sys
d = json.loads(sys.argv[1])
def secs(path):
    m = re.search(r", ([0-9.]+) s\)", open(path).read())
    return m.group(1) if m else "-"
psnr = d["psnr"]
bad = not (psnr >= float(sys.argv[3]) and d["differing"] <= float(sys.argv[4]))
print("%-16s %9.1f %9.4f%% %10s %10s%s" % (sys.argv[2], psnr, 100 * d["differing"],
      secs(sys.argv[5]), secs(sys.argv[6]), "  DISAGREE" if bad else ""))
PY
)
  echo "$line" | tee -a "$table"
  case "$line" in *DISAGREE*) status=1 ;; esac
done

crashes=0
codes=""
for i in $(seq 1 "$REPEAT"); do
  "$B" render examples/lattice.sdf --backend wgpu -o /tmp/sdfc-img/lattice-repeat.png > "/tmp/sdfc-img/lattice-run-$i.txt" 2>&1
  rc=$?
  codes="$codes $rc"
  [ $rc = 0 ] || crashes=$((crashes + 1))
done
echo "lattice.sdf through wgpu, $REPEAT runs: exit codes$codes; $crashes not clean" | tee -a "$table"
[ $crashes = 0 ] || status=1
cat "$OUT/gpu.txt"
exit $status
