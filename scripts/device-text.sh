#!/usr/bin/env bash
# Text on the device (issue 35, item 3): a 40-character string extruded on a plaque, and the
# same scene with one character, at 1920x1080, aa 1: `sdfc bench` medians through CUDA and
# wgpu (and the CPU, fewer frames), and the size of each kernel (WGSL and PTX bytes, and the
# scene_data bytes the glyphs take), as one Markdown table. The glyphs are data, so the
# 40-character kernel should be the size of the 1-character one.
# Runs on the GPU machine (the `device` tool), with scripts/device-env.sh's setup (the
# binary in .dev/sdfc).
# Usage: scripts/device-text.sh
set -uo pipefail
cd "$(dirname "$0")/.."
. scripts/device-env.sh
FRAMES=${FRAMES:-20}
scene() { # name string
    cat > "/tmp/sdfc-img/$1.sdf" <<SDF
material brass = phong { color: (0.85, 0.65, 0.3), specular: 0.8, shininess: 60 };
material slate = phong { color: (0.18, 0.2, 0.24), specular: 0.3, shininess: 20 };
camera { position: (0, 0.4, -9), look_at: (0, 0, 0), fov: 50deg }
light point { position: (-3, 5, -5), intensity: 1, radius: 40 }
light directional { direction: (1, -1, 1), color: (0.3, 0.3, 0.35) }
scene {
  round_box((6.3, 0.6, 0.1), 0.05).translate(0, 0, 0.15) @ slate;
  extrude(text("$2", 0.5), 0.2, 0.01) @ brass;
}
SDF
}
scene text40 "The quick brown fox jumps over a lazy do"
scene text1 "T"
median() { # scene backend frames
    "$B" bench "/tmp/sdfc-img/$1.sdf" --backend "$2" --size 1920x1080 --frames "$3" 2>/dev/null \
        | awk 'NR == 2 { print $7 }'
}
echo "| scene | backend | median ms | WGSL bytes | PTX bytes | scene_data bytes |"
echo "|---|---|---:|---:|---:|---:|"
for s in text40 text1; do
    f=/tmp/sdfc-img/$s.sdf
    wgsl=$("$B" compile "$f" --emit wgsl 2>/dev/null | wc -c)
    ptx=$("$B" compile "$f" --emit ptx 2>/dev/null | wc -c)
    data=$("$B" compile "$f" --emit scene-data -o /tmp/sdfc-img/$s.bin 2>/dev/null; stat -c %s /tmp/sdfc-img/$s.bin 2>/dev/null || echo -)
    for backend in cuda wgpu; do
        median "$s" "$backend" 3 >/dev/null # warm the kernel caches
        echo "| $s | $backend | $(median "$s" "$backend" "$FRAMES") | $wgsl | $ptx | $data |"
    done
    echo "| $s | cpu | $(median "$s" cpu 3) | | | |"
done
