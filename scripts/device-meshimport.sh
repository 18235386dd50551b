#!/usr/bin/env bash
# Runs on the GPU machine (the `device` tool), for issue 40 (`mesh(path)`): a mesh of about
# 100 000 triangles (examples/mesh/bracket.sdf meshed by `sdfc mesh` at resolution 104, as
# STL) read back with `mesh` in a scene with a floor and a point light with soft shadows;
# (load) the time to read the file and build its hierarchy (`sdfc check`, best of 3, against
# the same scene with a box in place of the mesh); (frame) the 1080p frame time, marched, on
# CUDA and wgpu with `sdfc bench` (5 frames after a warm-up), and the CPU's at 480x270 for
# scale; (agree) CUDA and wgpu against the CPU at 640x480. Expects the sdfc binary at
# .dev/sdfc and the Vulkan loader packages in .gl/ (device-env.sh). Writes logs under $OUT;
# prints a table last.
# Usage: scripts/device-meshimport.sh [all|load|frame|agree]   (RES=104 sets the resolution)
set -u
. "$(dirname "$0")/device-env.sh"
MODE=${1:-all}
RES=${RES:-104}
W=/tmp/sdfc-meshimport
mkdir -p "$W"

"$B" mesh examples/mesh/bracket.sdf --resolution "$RES" -o "$W/big.stl" > "$OUT/meshimport-mesh.txt" 2>&1 \
  || { echo "sdfc mesh FAILED: $(tail -n 2 "$OUT/meshimport-mesh.txt")"; exit 1; }
TRIS=$(grep -o '[0-9]* triangles' "$OUT/meshimport-mesh.txt" | head -n 1)
for shape in 'mesh("big.stl")' 'box((0.8, 0.3, 0.45))'; do
  name=$([ "$shape" = 'mesh("big.stl")' ] && echo scene || echo boxscene)
  cat > "$W/$name.sdf" <<EOF
material steel = phong { color: (0.62, 0.64, 0.7), specular: 0.6, shininess: 64 };
material floor = checker { a: (0.85, 0.85, 0.85), b: (0.55, 0.55, 0.55), size: 0.25 };
camera { position: (1.8, 1.5, -2.4), look_at: (0, 0.1, 0), fov: 45deg }
light point { position: (-2, 4, -3), intensity: 1.1, penumbra: 3deg }
render { width: 1920, height: 1080, max_depth: 0 }
scene {
  $shape @ steel;
  plane((0, 1, 0), -0.42) @ floor;
}
EOF
done
: > "$OUT/meshimport.txt"

if [ "$MODE" = all ] || [ "$MODE" = load ]; then
  best() {
    python3 - "$@" <<'PY'
import subprocess, sys, time
ts = []
for _ in range(3):
    t = time.perf_counter()
    subprocess.run(sys.argv[1:], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    ts.append(time.perf_counter() - t)
print("%.3f" % min(ts))
PY
  }
  tm=$(best "$B" check "$W/scene.sdf")
  tb=$(best "$B" check "$W/boxscene.sdf")
  echo "load+build ($TRIS, $(du -k "$W/big.stl" | cut -f1) KiB STL): sdfc check ${tm} s, the same scene with a box ${tb} s" | tee -a "$OUT/meshimport.txt"
fi

if [ "$MODE" = all ] || [ "$MODE" = frame ]; then
  for b in cuda wgpu; do
    "$B" bench --backend "$b" --size 1920x1080 --frames 5 --json "$W/scene.sdf" > "$OUT/meshimport-$b.json" 2> "$OUT/meshimport-$b.log" \
      || echo "$b FAILED: $(tail -n 3 "$OUT/meshimport-$b.log")"
    python3 -c '
import json, sys
for t in json.load(open(sys.argv[1])):
    print("1080p marched, soft shadows, %-4s %-32s median %.2f ms (min %.2f ms, frame with transfers %.2f ms), %.0f Mrays/s" % (
          sys.argv[2], t["device"][:32], 1e3 * t["median_s"], 1e3 * t["min_s"], 1e3 * t["median_frame_s"], t["mrays_per_s"]))
' "$OUT/meshimport-$b.json" "$b" 2>/dev/null | tee -a "$OUT/meshimport.txt"
  done
  "$B" render "$W/scene.sdf" --backend cpu --size 480x270 -o /tmp/sdfc-img/meshimport-cpu-small.png > "$OUT/meshimport-cpu.txt" 2>&1
  echo "cpu 480x270: $(tail -n 1 "$OUT/meshimport-cpu.txt")" | tee -a "$OUT/meshimport.txt"
fi

if [ "$MODE" = all ] || [ "$MODE" = agree ]; then
  for b in cpu cuda wgpu; do
    "$B" render "$W/scene.sdf" --backend "$b" --size 640x480 -o "/tmp/sdfc-img/meshimport-$b.png" > "$OUT/meshimport-agree-$b.txt" 2>&1 \
      || echo "$b FAILED: $(tail -n 2 "$OUT/meshimport-agree-$b.txt")"
  done
  cp /tmp/sdfc-img/meshimport-*.png "$OUT/" 2>/dev/null
  for b in cuda wgpu; do
    echo "640x480 $b against cpu: $("$B" compare "/tmp/sdfc-img/meshimport-$b.png" /tmp/sdfc-img/meshimport-cpu.png 2>&1 | head -n 3 | tr '\n' ' ')" | tee -a "$OUT/meshimport.txt"
  done
fi

echo "== issue 40, mesh import ($TRIS)"
cat "$OUT/meshimport.txt"
cat "$OUT/gpu.txt"
