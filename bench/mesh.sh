#!/usr/bin/env bash
# Meshing figures for BENCHMARKS.md ("Meshing"): time of `sdfc mesh` at resolutions 64, 128
# and 256 for the benchmark scene (examples/mesh/parts.sdf over [-1, 1]³) and the bracket,
# with sharp features on and off, and the cells evaluated against the dense grid at 256 for
# the report scenes' bounded parts. Run it on an otherwise idle machine: the figures are
# wall-clock times.
#
# usage: bench/mesh.sh [SDFC] [RUNS]   (default target/release/sdfc, 5 runs; median reported)
#        FIDGET=path/to/fidget-mesh-bench bench/mesh.sh ...   also runs the peer, fidget 0.5.1's
#        Manifold Dual Contouring on the same scene (bench/fidget-mesh), side by side
set -euo pipefail
SDFC=${1:-target/release/sdfc}
RUNS=${2:-5}
OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT
echo "# $(date -u '+%Y-%m-%d %H:%M UTC'), $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs), load $(cut -d' ' -f1-3 /proc/loadavg)"

# median of the "time" line of --stats (octree and contouring; the meshing itself) and of
# the whole command's wall time (reading, lowering, meshing, writing the STL)
measure() { # name file extra-args...
  local name=$1 file=$2; shift 2
  local inner=() wall=() stats
  for _ in $(seq "$RUNS"); do
    local t0 t1
    t0=$(date +%s.%N)
    stats=$("$SDFC" mesh "$file" -o "$OUT/m.stl" --stats --threads 2 "$@" 2>/dev/null)
    t1=$(date +%s.%N)
    inner+=("$(echo "$stats" | awk '/^time/ {print $2}')")
    wall+=("$(echo "$t1 - $t0" | bc -l)")
  done
  local mi mw tris
  mi=$(printf '%s\n' "${inner[@]}" | sort -g | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}')
  mw=$(printf '%s\n' "${wall[@]}" | sort -g | awk '{a[NR]=$1} END {printf "%.3f", a[int((NR+1)/2)]}')
  tris=$(( ($(stat -c %s "$OUT/m.stl") - 84) / 50 ))
  local evals
  evals=$(echo "$stats" | awk '/^evaluations/ {print $2, $4}')
  printf '| %s | %s | %s | %s | %s | %s |\n' "$name" "$*" "$mi" "$mw" "$tris" "$evals"
}

echo
echo "| scene | arguments | meshing s (median) | command s (median) | triangles | points evaluated (% of dense grid) |"
echo "|---|---|---|---|---|---|"
for r in 64 128 256; do
  measure parts examples/mesh/parts.sdf --bounds=-1,-1,-1,1,1,1 --resolution "$r"
  measure parts examples/mesh/parts.sdf --bounds=-1,-1,-1,1,1,1 --resolution "$r" --set sharp=off
done
for r in 64 128 256; do
  measure bracket examples/mesh/bracket.sdf --resolution "$r"
done

if [ -n "${FIDGET:-}" ]; then
  echo
  echo "Side by side with fidget 0.5.1 (Manifold Dual Contouring, rayon's pool on $(nproc) cores):"
  echo
  for depth in 7 8; do
    RAYON_NUM_THREADS=2 "$FIDGET" jit "$depth" "$RUNS" "$OUT/fidget-jit-$depth.stl"
    RAYON_NUM_THREADS=2 "$FIDGET" vm "$depth" "$RUNS"
    measure parts examples/mesh/parts.sdf --bounds=-1,-1,-1,1,1,1 --resolution $((1 << depth))
  done
  for depth in 7 8; do
    echo "fidget jit depth $depth STL by positions: $(python3 - "$OUT/fidget-jit-$depth.stl" <<'PY'
import struct, sys
from collections import Counter
d = open(sys.argv[1], "rb").read()
n = struct.unpack("<I", d[80:84])[0]
ids, tris = {}, []
for k in range(n):
    v = struct.unpack("<9f", d[84 + 50 * k + 12 : 84 + 50 * k + 48])
    tris.append([ids.setdefault(v[3 * i : 3 * i + 3], len(ids)) for i in range(3)])
directed = Counter((t[i], t[(i + 1) % 3]) for t in tris for i in range(3) if t[i] != t[(i + 1) % 3])
undirected = Counter(tuple(sorted(e)) for e in directed.elements())
print(f"{n} triangles, {len(ids)} distinct positions, {sum(1 for c in undirected.values() if c != 2)} edges not in exactly two triangles, {sum(1 for t in tris if len(set(t)) < 3)} triangles with a repeated position")
PY
)"
  done
fi

echo
echo "Cells at resolution 256: the report scenes' bounded parts (their floor planes left out; seed4's"
echo "infinite repetition cut to the box -4,-1,-4 … 4,2,4), the parts scene over [-1, 1]³, the bracket:"
echo
echo "| scene | grid | octree cells evaluated | % of dense cells | candidates | surface cells | points evaluated | % of dense points | meshing s |"
echo "|---|---|---|---|---|---|---|---|---|"
for f in examples/seed{1,2,3,4,5,6}.sdf examples/mesh/parts.sdf examples/mesh/bracket.sdf; do
  scene="$OUT/$(basename "$f")"
  grep -v '^[[:space:]]*plane(' "$f" > "$scene"
  args=(--resolution 256)
  case "$f" in
    *seed4.sdf) args+=(--bounds=-4,-1,-4,4,2,4) ;;
    *parts.sdf) args+=(--bounds=-1,-1,-1,1,1,1) ;;
  esac
  s=$("$SDFC" mesh "$scene" -o "$OUT/m.stl" --stats --threads 2 "${args[@]}" 2>/dev/null)
  grid=$(echo "$s" | awk '/^grid/ {print $2}')
  oct=$(echo "$s" | awk '/^octree cells/ {print $3}')
  cand=$(echo "$s" | awk '/^candidates/ {print $2}')
  surf=$(echo "$s" | awk '/^surface cells/ {print $3}')
  ev=$(echo "$s" | awk '/^evaluations/ {print $2}')
  evp=$(echo "$s" | awk '/^evaluations/ {print $4}' | tr -d '(')
  t=$(echo "$s" | awk '/^time/ {print $2}')
  dense=$(echo "$grid" | awk -Fx '{print $1*$2*$3}')
  printf '| %s | %s | %s | %.2f | %s | %s | %s | %s | %s |\n' "$(basename "$f" .sdf)" "$grid" "$oct" \
    "$(echo "100 * $oct / $dense" | bc -l)" "$cand" "$surf" "$ev" "$evp" "$t"
done
