#!/usr/bin/env bash
# Runs on the GPU machine (the `device` tool), which has no display: measures the session of
# `sdfc view --headless --backend wgpu --timings` (the window's session without the window).
# For each scene it opens the viewer on a copy, then saves three edits one after the other, each
# once the image of the one before has converged: a numeric edit (the first light's intensity:
# uniform data, the pipeline is found in the cache), a structural edit (one more shape: a new
# kernel to compile) and a radius edit where the scene has a `sphere(` (a constant of the
# distance program, which the viewer's kernel reads from `scene_data`: the kernel is kept),
# each saved as editors do, by writing a new file and renaming it
# over the old one. The viewer prints, per load, check, lower, kernel, pipeline and
# first-frame times and the time from the file's modification to the first frame (edit to
# pixel). Then, for the report's scenes and temple.sdf, the frame rate while orbiting at
# $SIZE and the time to converge after the camera stops (--orbit-frames). $KERNEL (default
# auto) is the viewer's --kernel: with auto, a structural edit waits 50 ms (the grace period)
# for its specialised kernel, shown at once if it compiled by then, else through the
# interpreted kernel while the specialised one compiles, and a second line says when that was
# ready; a line per scene says which kernel the structural edit's first frame used and whether
# it was ready within the grace period. KERNEL=specialised measures the viewer that compiles
# before showing, to compare. Expects .dev/sdfc and .gl/ as scripts/device-run.sh does. Writes
# $OUT/view.txt.
set -u
. "$(dirname "$0")/device-env.sh"
SIZE=${SIZE:-1920x1080}
KERNEL=${KERNEL:-auto}
SCENES=${SCENES:-"examples/*.sdf examples/scaling/*_1000.sdf"}
LOG="$OUT/view.txt"
: > "$LOG"

wait_for() { # FILE PID: waits for FILE while PID runs, up to 60 s
  local i=0
  while [ ! -f "$1" ]; do
    kill -0 "$2" 2>/dev/null || return 1
    sleep 0.005
    i=$((i + 1))
    [ $i -gt 12000 ] && return 1
  done
  return 0
}

for f in $SCENES; do
  n=$(basename "$f" .sdf)
  d=$(mktemp -d)
  cp -r "$(dirname "$f")/." "$d/"
  s="$d/$(basename "$f")"
  "$B" view "$s" --headless --backend wgpu --kernel "$KERNEL" --size "$SIZE" --timings \
    --screenshot-dir "$d/shots" --exit-after-reloads 3 > "$d/log" 2>&1 &
  pid=$!
  ok=1
  wait_for "$d/shots/reload-0.png" $pid || ok=0
  # numeric: the first light's intensity
  [ $ok = 1 ] && python3 - "$s" <<'PY'
import os, re, sys
p = sys.argv[1]; t = open(p).read()
t = re.sub(r"intensity: *([0-9.]+)", lambda m: "intensity: %g" % (float(m.group(1)) * 0.9), t, count=1)
open(p + ".new", "w").write(t); os.replace(p + ".new", p)
PY
  [ $ok = 1 ] && { wait_for "$d/shots/reload-1.png" $pid || ok=0; }
  # structural: one more shape, far from everything
  [ $ok = 1 ] && python3 - "$s" <<'PY'
import os, sys
p = sys.argv[1]; t = open(p).read()
t = t.replace("scene {", "scene {\n  sphere(0.01).translate(0, 1000, 0);", 1)
open(p + ".new", "w").write(t); os.replace(p + ".new", p)
PY
  [ $ok = 1 ] && { wait_for "$d/shots/reload-2.png" $pid || ok=0; }
  # a radius (or, without a sphere, the intensity again)
  [ $ok = 1 ] && python3 - "$s" <<'PY'
import os, re, sys
p = sys.argv[1]; t = open(p).read()
u = re.sub(r"sphere\(([0-9.]+)\)(?!\.translate\(0, 1000)", lambda m: "sphere(%g)" % (float(m.group(1)) * 1.1), t, count=1)
if u == t:
    u = re.sub(r"intensity: *([0-9.]+)", lambda m: "intensity: %g" % (float(m.group(1)) * 0.9), t, count=1)
open(p + ".new", "w").write(u); os.replace(p + ".new", p)
PY
  [ $ok = 1 ] && { wait_for "$d/shots/reload-3.png" $pid || ok=0; }
  # A viewer whose edit did not arrive would wait for it: stop it.
  [ $ok = 1 ] || kill "$pid" 2>/dev/null
  wait $pid
  echo "== $n (numeric, structural, radius edits; --kernel $KERNEL)" | tee -a "$LOG"
  grep -E "timings|full-resolution|kernel ready|error" "$d/log" | tee -a "$LOG"
  # The structural edit is load 2: its first frame's kernel, and the grace period's outcome.
  s2=$(grep "load 2 timings" "$d/log")
  k=$(echo "$s2" | grep -oE "first frame [0-9.]+ ms \([0-9]+x[0-9]+, [a-z]+" | grep -oE "[a-z]+$")
  case "$s2" in
    *"specialised compiled within the grace period"*) g=", compiled within the grace period" ;;
    *"no interpreted kernel meanwhile"*) g=", compiled on another thread before it was shown" ;;
    *"not ready within"*) g=", not ready within the grace period" ;;
    *"after the"*"grace period"*) g=", ready after the grace period, before an interpreted frame" ;;
    *"on another thread"*) g="" ;;
    *) g=", compiled before it was shown" ;;
  esac
  [ -n "$s2" ] && echo "$n: structural edit's first frame: ${k:-?} kernel$g" | tee -a "$LOG"
  [ $ok = 1 ] || { echo "$n: FAILED"; tail -n 5 "$d/log"; } | tee -a "$LOG"
  rm -rf "$d"
done

for n in ${ORBIT_SCENES:-seed1 seed2 seed3 seed4 seed5 seed6 temple}; do
  echo "== orbit $n at $SIZE" | tee -a "$LOG"
  d=$(mktemp -d)
  timeout 120 "$B" view "examples/$n.sdf" --headless --backend wgpu --size "$SIZE" \
    --orbit-frames ${ORBIT_FRAMES:-120} --screenshot-dir "$d" --exit-after-reloads 0 2>&1 | grep "orbit" | tee -a "$LOG"
  rm -rf "$d"
done
