#!/usr/bin/env bash
# Runs on the GPU machine (the `device` tool), for issue 36: one, two and four GPUs side by side
# (`--devices 0`, `0,1`, `0,1,2,3`, as many as the host has), the build before and after:
#   (sequence) examples/animation/orbit.sdf, 120 and 480 frames at 1920x1080 as numbered PNGs
#           with `sdfc render --frames --stats` (frames per second of the whole process; the
#           frames of several devices compared with one's, and the two builds' with each other);
#   (still) seeds 3, 5, 6 and temple at 7680x4320, aa 2, `sdfc bench --frames 3` (the median
#           whole frame);
#   (stats) `sdfc render --stats` of seed3 at 7680x4320, aa 2, on every device.
# Expects the binaries in $DIR (default .dev/gpu2: sdfc, and sdfc-before when given in BINS)
# and the Vulkan loader packages in .gl/ (device-env.sh). The logs go to $OUT/logs.tgz (one
# file: the device tool returns a few files only); prints the table last.
# Usage: BINS="sdfc-before sdfc" SEQ=1 STILL=1 STATS=1 scripts/device-scaling.sh
set -u
. scripts/device-env.sh > /dev/null 2>&1
D=${DIR:-.dev/gpu2}; chmod +x $D/sdfc* 2>/dev/null
BINS=${BINS:-sdfc-before sdfc}
GPUS=$(nvidia-smi -L | grep -c '^GPU')
LISTS="0"; [ "$GPUS" -ge 2 ] && LISTS="$LISTS 0,1"; [ "$GPUS" -ge 4 ] && LISTS="$LISTS 0,1,2,3"
SEQ=${SEQ:-1}; STILL=${STILL:-1}; STATS=${STATS:-1}
T=$OUT/table.txt; : > $T; mkdir -p $OUT/logs
fps() { grep -o '([0-9.]* frames/s)' "$1" | tr -d '(' | cut -d' ' -f1; }
fms() { python3 -c 'import json,sys; print("%.1f" % (1e3*json.load(open(sys.argv[1]))[0]["median_frame_s"]))' "$1" 2>/dev/null || echo nan; }
for v in $BINS; do X=$D/$v
  for b in cuda wgpu; do
    "$X" render examples/animation/orbit.sdf --backend $b --size 1920x1080 --frames 0..4 --force -o /tmp/sdfc-img/warm-$b/f_###.png > /dev/null 2>&1
  done
done
if [ "$SEQ" = 1 ]; then
for n in 120 480; do for b in cuda wgpu; do for v in $BINS; do X=$D/$v; line="seq $v $b orbit ${n}x1080p f/s:"
  for d in $LISTS; do tag=$v-$b-$n-$(echo $d | tr , -)
    rm -rf /tmp/sdfc-img/s-$v-$b-$(echo $d | tr , -)
    "$X" render examples/animation/orbit.sdf --backend $b --devices $d --size 1920x1080 --frames 0..$n --force --stats -o /tmp/sdfc-img/s-$v-$b-$(echo $d | tr , -)/f_###.png > $OUT/logs/seq-$tag.log 2>&1
    line="$line [$d] $(fps $OUT/logs/seq-$tag.log)"
    [ "$d" != 0 ] && { diff -rq /tmp/sdfc-img/s-$v-$b-0 /tmp/sdfc-img/s-$v-$b-$(echo $d | tr , -) > /dev/null && line="$line same" || line="$line DIFFER"; }
  done
  echo "$line" | tee -a $T
done
  diff -rq /tmp/sdfc-img/s-sdfc-before-$b-0 /tmp/sdfc-img/s-sdfc-$b-0 > /dev/null && echo "seq $b $n: before and after identical" | tee -a $T
done; done
fi
if [ "$STILL" = 1 ]; then
for b in cuda wgpu; do for s in seed3 seed5 seed6 temple; do for v in $BINS; do X=$D/$v; line="still $v $b $s 8K aa2 ms:"
  for d in $LISTS; do tag=$v-$b-$s-$(echo $d | tr , -)
    "$X" bench examples/$s.sdf --backend $b --devices $d --size 7680x4320 --aa 2 --limit memory=65536 --frames 3 --json > $OUT/logs/b-$tag.json 2> $OUT/logs/b-$tag.log
    line="$line [$d] $(fms $OUT/logs/b-$tag.json)"
  done
  echo "$line" | tee -a $T
done; done; done
fi
if [ "$STATS" = 1 ]; then
for b in cuda wgpu; do for v in $BINS; do X=$D/$v; d=$(echo $LISTS | awk '{print $NF}')
  "$X" render examples/seed3.sdf --backend $b --devices $d --size 7680x4320 --aa 2 --limit memory=65536 --stats -o /tmp/sdfc-img/st.png > $OUT/logs/st-$v-$b.log 2>&1
done; done
fi
echo "== $(head -n 1 $OUT/gpu.txt) x$GPUS, $(tail -n 1 $OUT/gpu.txt); $(cat $D/commits.txt 2>/dev/null | tr '\n' ' ')"
tar czf $OUT/logs.tgz -C $OUT logs && rm -rf $OUT/logs
cat $T
