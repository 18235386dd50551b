#!/usr/bin/env bash
# GPU meshing figures for BENCHMARKS.md ("Meshing on a GPU"): `sdfc mesh --backend B` on the
# bracket (examples/mesh/bracket.sdf) and the knob (examples/knob.sdf above its floor, in
# -1.1,0.01,-1.1 … 1.1,1.25,1.1) at resolutions 256, 512 and 1024, each backend given. Per
# run, from `--stats`: the meshing (octree to mesh) and the part of it spent evaluating
# points (on a GPU: launches, transfers, f32 conversions), what came before it (reading, checking,
# lowering, opening the device and compiling its kernel), their sum (the whole command but
# the file's write and the distance measured for `--stats`), and the launches. Medians of
# RUNS runs; the file is written to a temporary folder and not timed.
#
# usage: bench/mesh_gpu.sh [SDFC] [RUNS] [BACKENDS] [RESOLUTIONS]
#        (default target/release/sdfc, 5 runs, "cuda cpu", "256 512 1024")
#   e.g. bench/mesh_gpu.sh target/release/sdfc 5 "cuda wgpu cpu"
set -euo pipefail
SDFC=${1:-target/release/sdfc}
RUNS=${2:-5}
BACKENDS=${3:-cuda cpu}
RESOLUTIONS=${4:-256 512 1024}
OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT
echo "# $(date -u '+%Y-%m-%d %H:%M UTC'), $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs)"
command -v nvidia-smi >/dev/null && nvidia-smi --query-gpu=name,driver_version --format=csv,noheader | sed 's/^/# GPU: /'

median() { sort -g | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}'; }

# Large grids need more than the default limits (1024³ of the bracket holds about 2.4 million
# surface cells).
LIMITS=(--limit memory=65536 --limit cells=1000000000)

measure() { # name backend resolution file extra-args...
  local name=$1 backend=$2 r=$3 file=$4; shift 4
  local mesh=() before=() total=() evaluating=() stats
  for _ in $(seq "$RUNS"); do
    if ! stats=$("$SDFC" mesh "$file" -o "$OUT/m.ply" --stats --backend "$backend" \
      --resolution "$r" "${LIMITS[@]}" "$@" 2>"$OUT/err"); then
      printf '| %s | %s | %s | failed: %s | | | | | |\n' "$name" "$r" "$backend" "$(tail -1 "$OUT/err")"
      return
    fi
    local m b
    m=$(echo "$stats" | awk '/^time/ {print $2}')
    b=$(echo "$stats" | awk '/^before meshing/ {print $3}')
    mesh+=("$m"); before+=("$b"); total+=("$(awk -v m="$m" -v b="$b" 'BEGIN { printf "%.4f", m + b }')")
    evaluating+=("$(echo "$stats" | awk '/^evaluations/ {print $(NF-1)}')")
  done
  local tris launches
  tris=$(grep -a -m1 'element face' "$OUT/m.ply" | awk '{print $3}')
  launches=$(echo "$stats" | awk '/^evaluations/ {for (i = 1; i <= NF; i++) if ($i ~ /^launches/) print $(i-1)}')
  printf '| %s | %s | %s | %s | %s | %s | %s | %s | %s |\n' "$name" "$r" "$backend" \
    "$(printf '%s\n' "${mesh[@]}" | median)" "$(printf '%s\n' "${evaluating[@]}" | median)" \
    "$(printf '%s\n' "${before[@]}" | median)" \
    "$(printf '%s\n' "${total[@]}" | median | xargs printf '%.3f')" "$tris" "${launches:-0}"
}

echo
echo "| scene | resolution | backend | meshing s | of which evaluating s | before meshing s | sum s | triangles | launches |"
echo "|---|---:|---|---:|---:|---:|---:|---:|---:|"
for r in $RESOLUTIONS; do
  for b in $BACKENDS; do
    measure bracket "$b" "$r" examples/mesh/bracket.sdf
    measure knob "$b" "$r" examples/knob.sdf --bounds=-1.1,0.01,-1.1,1.1,1.25,1.1
  done
done
