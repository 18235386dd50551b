#!/usr/bin/env bash
# Runs on the GPU machine (the `device` tool): renders every example at 1920x1080 with wgpu,
# CUDA and the CPU, compares them, and times the report's six scenes on both GPU backends at
# the report's resolutions with aa 1 and 4. Expects the sdfc binary at .dev/sdfc and the
# Vulkan loader packages in .gl/. Writes logs and JSON under $OUT; prints a table last.
set -u
. "$(dirname "$0")/device-env.sh"
MODE=${1:-all}

if [ "$MODE" = all ] || [ "$MODE" = check ]; then
  echo "== conformance at 1920x1080 (psnr dB / differing %)" | tee "$OUT/conformance.txt"
  for f in examples/*.sdf; do
    n=$(basename "$f" .sdf)
    for b in cpu wgpu cuda; do
      "$B" render "$f" --backend "$b" --size 1920x1080 -o "/tmp/sdfc-img/$n-$b.png" --stats > "$OUT/render-$n-$b.txt" 2>&1 || echo "$n $b FAILED: $(tail -n 2 "$OUT/render-$n-$b.txt")"
    done
    wc=$("$B" compare "/tmp/sdfc-img/$n-wgpu.png" "/tmp/sdfc-img/$n-cpu.png" --json 2>&1)
    cc=$("$B" compare "/tmp/sdfc-img/$n-cuda.png" "/tmp/sdfc-img/$n-cpu.png" --json 2>&1)
    cw=$("$B" compare "/tmp/sdfc-img/$n-cuda.png" "/tmp/sdfc-img/$n-wgpu.png" --json 2>&1)
    short() { python3 -c 'import json,sys; d=json.loads(sys.argv[1]); print("%.1f dB %.4f%%" % (d["psnr"], 100 * d["differing"]))' "$1" 2>/dev/null || echo "n/a"; }
    echo "$n  wgpu-cpu $(short "$wc") | cuda-cpu $(short "$cc") | cuda-wgpu $(short "$cw")" | tee -a "$OUT/conformance.txt"
  done
  cp /tmp/sdfc-img/seed3-cuda.png /tmp/sdfc-img/seed5-wgpu.png "$OUT/" 2>/dev/null
  echo "== CUDA JIT: cold, then warm cache" | tee "$OUT/jit.txt"
  # Cold means the driver compiles too: it keeps a compute cache of its own unless told not to.
  rm -rf /tmp/sdfc-jit
  CUDA_CACHE_DISABLE=1 "$B" render examples/seed3.sdf --backend cuda --size 64x64 -o /tmp/j.png --stats 2>&1 | grep -E "^  (PTX|driver compile) " | tee -a "$OUT/jit.txt"
  "$B" render examples/seed3.sdf --backend cuda --size 64x64 -o /tmp/j.png --stats 2>&1 | grep -E "^  (PTX|driver compile) " | tee -a "$OUT/jit.txt"
fi

if [ "$MODE" = all ] || [ "$MODE" = bench ]; then
  SEEDS="examples/seed1.sdf examples/seed2.sdf examples/seed3.sdf examples/seed4.sdf examples/seed5.sdf examples/seed6.sdf"
  for size in 640x480 1024x768 1920x1080; do
    for aa in 1 4; do
      for b in wgpu cuda; do
        "$B" bench $SEEDS --backend "$b" --size "$size" --aa "$aa" --frames 10 --json > "/tmp/bench-$b-$size-aa$aa.json" 2> "/tmp/bench-$b-$size-aa$aa.err" || echo "bench $b $size aa$aa FAILED: $(tail -n 3 "/tmp/bench-$b-$size-aa$aa.err")"
      done
    done
  done
  {
  python3 - "$OUT" <<'PY'
import json, sys, glob, os
out = sys.argv[1]
rows = {}
merged = []
for path in sorted(glob.glob("/tmp/bench-*.json")):
    try:
        data = json.load(open(path))
    except Exception:
        continue
    merged.extend(data)
    for t in data:
        key = (os.path.basename(t["scene"]), f'{t["width"]}x{t["height"]}', t["aa"])
        rows.setdefault(key, {})[t["backend"]] = t["median_s"] * 1e3
        rows[key][t["backend"] + "_wall"] = t.get("median_wall_s", 0) * 1e3
json.dump(merged, open(os.path.join(out, "bench.json"), "w"), indent=1)
print(f'{"scene":<11}{"size":>10}{"aa":>3}  {"wgpu gpu":>9}{"cuda gpu":>9}{"ratio":>6}  {"wgpu wall":>9}{"cuda wall":>10}{"ratio":>6}')
def f(x):
    return "-" if not x else f"{x:.2f}"
for key in sorted(rows, key=lambda k: (k[0], int(k[1].split("x")[0]), k[2])):
    r = rows[key]
    w, c, ww, cw = r.get("wgpu"), r.get("cuda"), r.get("wgpu_wall"), r.get("cuda_wall")
    ratio = f"{c / w:.2f}" if w and c else "-"
    wratio = f"{cw / ww:.2f}" if ww and cw else "-"
    print(f'{key[0]:<11}{key[1]:>10}{key[2]:>3}  {f(w):>9}{f(c):>9}{ratio:>6}  {f(ww):>9}{f(cw):>10}{wratio:>6}')
PY
  } | tee "$OUT/table.txt"
fi
cat "$OUT/conformance.txt" 2>/dev/null | tail -n 12
cat "$OUT/jit.txt" 2>/dev/null

if [ "$MODE" = lattice ]; then
  # The wgpu render of the 400-sphere lattice crashed once at exit on an H200: repeat it with
  # backtraces to see where.
  for i in 1 2; do
    RUST_BACKTRACE=1 "$B" render examples/lattice.sdf --backend wgpu --size 1920x1080 -o /tmp/l.png --stats > "$OUT/lattice-$i.txt" 2>&1
    echo "lattice wgpu run $i exit $?" | tee -a "$OUT/lattice.txt"
  done
fi
