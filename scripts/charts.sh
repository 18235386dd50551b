#!/usr/bin/env bash
# Draws the speed-against-accuracy charts of docs/accuracy.md: `sdfc pareto` of the report's
# scenes (examples/seed1.sdf … seed6.sdf) on each backend named, over ε 1e-2…1e-6 ×
# max_steps 32…1024 × ω 1…1.8 (270 points a scene), each scene at its own aa.
#
#   scripts/charts.sh cpu          here, with $SDFC (default target/release/sdfc): 320×240,
#                                  median of 3 frames, to $DIR/pareto-seedN.svg (DIR=docs);
#                                  hours on 2 cores
#   scripts/charts.sh cuda wgpu    on the GPU machine: the runner's `pareto` suite
#                                  (scripts/bench.py --suite pareto, .dev/sdfc and .gl/
#                                  carried): 640×480, median of 5 frames, to
#                                  $OUT/pareto-gpu-seedN.svg (CUDA) and
#                                  $OUT/pareto-wgpu-seedN.svg; copy the ones docs show to docs/
#
# The repository keeps only the charts a page shows (README.md and docs/accuracy.md:
# pareto-seed3.svg and pareto-wgpu-seed3.svg); .gitignore leaves out the others this draws.
# Each chart's data goes to $JSON_DIR/NAME.json (default /tmp/pareto) with its log beside it,
# and a line per chart says where the defaults stand.
# Settings for a quick check: SCENES="1 2 …", SIZE=WxH, FRAMES=N, SWEEPS="--sweep K=RANGE …".
set -u
[ $# -gt 0 ] || { sed -n '2,20p' "$0"; exit 2; }
cd "$(dirname "$0")/.."
SWEEPS=${SWEEPS:---sweep epsilon=1e-2..1e-6 --sweep max_steps=32..1024 --sweep relaxation=1..1.8}
JSON_DIR=${JSON_DIR:-/tmp/pareto}
mkdir -p "$JSON_DIR"
status=0

for backend in "$@"; do
  case "$backend" in
    cpu)
      bin=${SDFC:-target/release/sdfc}
      dir=${DIR:-docs}
      prefix=pareto
      size=${SIZE:-320x240}
      frames=${FRAMES:-3}
      ;;
    cuda | wgpu)
      # The runner sets the GPU machine up (the Vulkan loader of .gl/, the NVIDIA driver).
      python3 scripts/bench.py --suite pareto --backends "$backend" \
        --with scenes="${SCENES:-1 2 3 4 5 6}" ${SIZE:+--size "$SIZE"} \
        ${FRAMES:+--frames "$FRAMES"} || status=1
      continue
      ;;
    *)
      echo "unknown backend '$backend': cpu, cuda or wgpu" >&2
      exit 2
      ;;
  esac
  mkdir -p "$dir"
  for i in ${SCENES:-1 2 3 4 5 6}; do
    name=$prefix-seed$i
    # seed6's area-averaged reference asks for more memory than the default limit (5.2 GB on
    # 16 threads).
    limit=()
    [ "$i" = 6 ] && limit=(--limit memory=12000)
    # shellcheck disable=SC2086 # SWEEPS is a list of arguments
    if "$bin" pareto "examples/seed$i.sdf" --backend "$backend" --size "$size" \
      --frames "$frames" $SWEEPS "${limit[@]}" -o "$dir/$name.svg" --json \
      > "$JSON_DIR/$name.json" 2> "$JSON_DIR/$name.log"; then
      python3 -c '
import json, sys
d = json.load(open(sys.argv[1]))
p = [x for x in d["points"] if x["default"]][0]
print("%s: defaults %.2f dB, %.1f steps/px, %.3f ms, on the time front %s, steps front %s"
      % (sys.argv[2], p["psnr"], p["steps_mean"], p["median_s"] * 1e3, p["front_time"], p["front_steps"]))
' "$JSON_DIR/$name.json" "$dir/$name.svg" || echo "$dir/$name.svg written"
    else
      echo "$name FAILED: $(tail -n 2 "$JSON_DIR/$name.log")" >&2
      status=1
    fi
  done
done
exit $status
