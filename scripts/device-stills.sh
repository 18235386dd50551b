#!/usr/bin/env bash
# Runs on the GPU machine (the `device` tool), for issue 36: 8K stills (7680x4320, aa 2) of
# seeds 3 and 6 and temple on one GPU and on two (`--devices 0` and `0,1`), two builds side by
# side, twice each: `sdfc bench --frames 5`'s median whole frame, ms; then seed3 and temple at
# 1920x1080 aa 2 on two GPUs, the two builds' PNGs compared byte for byte. Expects the builds
# as .dev/$BEFORE/sdfc and .dev/$AFTER/sdfc (default A=final, B=ended) and the Vulkan loader packages
# in .gl/ (device-env.sh). Prints the table last; the JSON goes to $OUT/logs.tgz.
set -u
. scripts/device-env.sh > /dev/null 2>&1
BEFORE=${BEFORE:-final}; AFTER=${AFTER:-ended}; LISTS=${LISTS:-0 0,1}; RUNS=${RUNS:-1 2}
chmod +x .dev/$BEFORE/sdfc .dev/$AFTER/sdfc; I=/tmp/sdfc-img; T=$OUT/table.txt; : > $T; mkdir -p $OUT/logs
ms() { python3 -c 'import json,sys; print("%.2f" % (1e3*json.load(open(sys.argv[1]))[0]["median_frame_s"]))' "$1" 2>/dev/null || echo nan; }
for v in $BEFORE $AFTER; do for b in cuda wgpu; do .dev/$v/sdfc render examples/seed3.sdf --backend $b --devices 0,1 --size 64x48 -o $I/w.png > /dev/null 2>&1; done; done
for r in $RUNS; do for b in cuda wgpu; do for s in seed3 seed6 temple; do for v in $BEFORE $AFTER; do line="r$r still $v $b $s 8K aa2 ms:"
  for d in $LISTS; do t=$r-$v-$b-$s-$(echo $d | tr , -)
    .dev/$v/sdfc bench examples/$s.sdf --backend $b --devices $d --size 7680x4320 --aa 2 --limit memory=65536 --frames 5 --json > $OUT/logs/$t.json 2> $OUT/logs/$t.err
    line="$line [$d] $(ms $OUT/logs/$t.json)"; done; echo "$line" >> $T; done; done; done; done
line="images 2 GPUs $AFTER=$BEFORE:"
for b in cuda wgpu; do for s in seed3 temple; do for v in $BEFORE $AFTER; do
  .dev/$v/sdfc render examples/$s.sdf --backend $b --devices 0,1 --size 1920x1080 --aa 2 -o $I/$v-$b-$s.png > /dev/null 2>&1; done
  cmp -s $I/$BEFORE-$b-$s.png $I/$AFTER-$b-$s.png && line="$line $b:$s=same" || line="$line $b:$s=DIFFER"; done; done; echo "$line" >> $T
tar czf $OUT/logs.tgz -C $OUT logs && rm -rf $OUT/logs
echo "== $(head -n1 $OUT/gpu.txt) x$(nvidia-smi -L | grep -c ^GPU), $(tail -n1 $OUT/gpu.txt)"
cat $T
