#!/usr/bin/env bash
# Runs on the GPU machine (the `device` tool), for issue 36 (items 5 and 6): builds side by
# side on one, two and four GPUs (`--devices 0`, `0,1`, `0,1,2,3`, as many as the host has):
#   (first)  the warm first picture: `sdfc render examples/seed3.sdf --size 320x240`, the
#            whole process in s, `--devices auto` through both backends (3 runs, then one
#            with `--stats` for the log) and each list through CUDA (2 runs);
#   (still)  seeds 3, 6 and temple at 7680x4320, aa 2: `sdfc bench --frames 3 --json`, the
#            median whole frame in ms; the JSON of several devices says what each did in
#            the last frame;
#   (seq)    examples/animation/orbit.sdf, 120 and 480 frames at 1920x1080 to numbered PNGs
#            with `sdfc render --frames --stats`, frames/s of the whole process;
#   (same)   seed3 and temple at 1920x1080, aa 2, to PNG on each list through both backends
#            (bands of unequal height on two and four devices).
# Every list's images (the sequences' frames and the `same` stills) are compared with the
# first build's on one device: "same", "DIFFER", or "failed" (no image) in the table.
# Expects the binaries under .dev/ ($BINS: paths below .dev, the first the "before"; default
# "base/sdfc several/sdfc") and the Vulkan loader packages in .gl/ (device-env.sh). The logs
# go to $OUT/logs.tgz; prints the table last.
# Usage: BINS="base/sdfc several/sdfc" FIRST=1 STILL=1 SEQ=1 SAME=1 scripts/device-scaling.sh
set -u
. scripts/device-env.sh > /dev/null 2>&1
BINS=${BINS:-base/sdfc several/sdfc}
for v in $BINS; do chmod +x .dev/$v; done
FIRSTBIN=$(echo $BINS | awk '{print $1}')
GPUS=$(nvidia-smi -L | grep -c '^GPU')
LISTS="0"; [ "$GPUS" -ge 2 ] && LISTS="$LISTS 0,1"; [ "$GPUS" -ge 4 ] && LISTS="$LISTS 0,1,2,3"
FIRST=${FIRST:-1}; STILL=${STILL:-1}; SEQ=${SEQ:-1}; SAME=${SAME:-1}
T=$OUT/table.txt; : > $T; mkdir -p $OUT/logs
I=/tmp/sdfc-img
tag() { echo "$1" | tr ',/' '-_'; }
fps() { grep -o '([0-9.]* frames/s)' "$1" | tr -d '(' | cut -d' ' -f1; }
fms() { python3 -c 'import json,sys; print("%.1f" % (1e3*json.load(open(sys.argv[1]))[0]["median_frame_s"]))' "$1" 2>/dev/null || echo nan; }
wall() { local t0=$EPOCHREALTIME; "$@" > /dev/null 2>&1; local rc=$?; local t1=$EPOCHREALTIME
  [ $rc = 0 ] && python3 -c "print('%.3f' % ($t1 - $t0))" || echo "rc$rc"; }
# Warm: every kernel compiled and cached (the CUDA JIT's cache, the driver's pipeline cache).
for v in $BINS; do for b in cuda wgpu; do
  for s in seed3 seed6 temple; do .dev/$v render examples/$s.sdf --backend $b --size 64x48 -o $I/warm.png > /dev/null 2>&1; done
  .dev/$v render examples/animation/orbit.sdf --backend $b --size 64x48 --frames 0..2 --force -o $I/warm-$b/f_###.png > /dev/null 2>&1
done; done
if [ "$FIRST" = 1 ]; then
for v in $BINS; do X=.dev/$v
  for b in cuda wgpu; do line="first $v $b auto s:"
    for r in 1 2 3; do line="$line $(wall $X render examples/seed3.sdf --backend $b --size 320x240 -o $I/first.png)"; done
    echo "$line" | tee -a $T
    $X render examples/seed3.sdf --backend $b --size 320x240 --stats -o $I/first.png > $OUT/logs/first-$(tag $v-$b).log 2>&1
  done
  line="first $v cuda lists s:"
  for d in $LISTS; do line="$line [$d]"
    for r in 1 2; do line="$line $(wall $X render examples/seed3.sdf --backend cuda --devices $d --size 320x240 -o $I/first.png)"; done
  done
  echo "$line" | tee -a $T
done
fi
if [ "$STILL" = 1 ]; then
for b in cuda wgpu; do for s in seed3 seed6 temple; do for v in $BINS; do X=.dev/$v; line="still $v $b $s 8K aa2 ms:"
  for d in $LISTS; do t=$(tag $v-$b-$s-$d)
    $X bench examples/$s.sdf --backend $b --devices $d --size 7680x4320 --aa 2 --limit memory=65536 --frames 3 --json > $OUT/logs/b-$t.json 2> $OUT/logs/b-$t.log
    line="$line [$d] $(fms $OUT/logs/b-$t.json)"
  done
  echo "$line" | tee -a $T
done; done; done
fi
if [ "$SEQ" = 1 ]; then
for n in 120 480; do for b in cuda wgpu; do for v in $BINS; do X=.dev/$v; line="seq $v $b orbit ${n}x1080p f/s:"
  for d in $LISTS; do t=$(tag $v-$b-$n-$d); dir=$I/s-$t
    rm -rf $dir
    $X render examples/animation/orbit.sdf --backend $b --devices $d --size 1920x1080 --frames 0..$n --force --stats -o $dir/f_###.png > $OUT/logs/seq-$t.log 2>&1
    line="$line [$d] $(fps $OUT/logs/seq-$t.log)"
    diff -rq $I/s-$(tag $FIRSTBIN-$b-$n-0) $dir > /dev/null && line="$line same" || line="$line DIFFER"
  done
  echo "$line" | tee -a $T
done; done; done
fi
if [ "$SAME" = 1 ]; then
for b in cuda wgpu; do for s in seed3 temple; do for v in $BINS; do X=.dev/$v; line="same $v $b $s 1080p aa2:"
  for d in $LISTS; do t=$(tag $v-$b-$s-$d)
    rm -f $I/p-$t.png
    $X render examples/$s.sdf --backend $b --devices $d --size 1920x1080 --aa 2 -o $I/p-$t.png > $OUT/logs/p-$t.log 2>&1
    if [ ! -f $I/p-$t.png ]; then line="$line [$d] failed"
    else cmp -s $I/p-$(tag $FIRSTBIN-$b-$s-0).png $I/p-$t.png && line="$line [$d] same" || line="$line [$d] DIFFER"; fi
  done
  echo "$line" | tee -a $T
done; done; done
fi
echo "== $(head -n 1 $OUT/gpu.txt) x$GPUS, $(tail -n 1 $OUT/gpu.txt); transparent huge pages: $(cat /sys/kernel/mm/transparent_hugepage/enabled), defrag $(cat /sys/kernel/mm/transparent_hugepage/defrag)" | tee -a $T
tar czf $OUT/logs.tgz -C $OUT logs && rm -rf $OUT/logs
cat $T
