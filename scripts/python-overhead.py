#!/usr/bin/env python3
"""Measures what the Python package adds on top of the work itself (docs/python.md): the
median wall time of `Scene.render` (uint8 sRGB, in-process) against the phases of
`sdfc render --stats` that do the same work (scene, setup, preparation, memory, frame and
sRGB; not the process start, the PNG or the file), each of the same scene, size and backend,
run alternately; and `Scene.distance` throughput on 10^6 points on each backend asked for.

    python3 scripts/python-overhead.py SDFC_BIN SCENE --size 1920x1080 --backends cpu,cuda

Prints one table; the sdfc package must be importable (the wheel installed, or on
PYTHONPATH)."""

import argparse
import re
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import sdfc

PHASES = ("scene", "setup", "preparation", "memory", "frame", "sRGB")


def cli_ms(binary: str, scene: str, size: str, backend: str, out: Path) -> float:
    """The CLI's own time for the phases a Python render also does, in milliseconds."""
    run = subprocess.run(
        [binary, "render", scene, "--backend", backend, "--size", size, "--stats", "-o", str(out)],
        check=True,
        capture_output=True,
        text=True,
    )
    total = 0.0
    for name in PHASES:
        m = re.search(rf"^\s+{re.escape(name)}\s+([0-9.]+) ms", run.stdout + run.stderr, re.M)
        if m is None:
            raise SystemExit(f"`render --stats` printed no {name!r} phase:\n{run.stderr}")
        total += float(m.group(1))
    return total


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("binary")
    ap.add_argument("scene")
    ap.add_argument("--size", default="1920x1080")
    ap.add_argument("--backends", default="cpu")
    ap.add_argument("--runs", type=int, default=7)
    ap.add_argument("--points", type=int, default=1_000_000)
    args = ap.parse_args()
    w, h = (int(x) for x in args.size.split("x"))
    scene = sdfc.Scene(path=args.scene)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "x.png"
        for backend in args.backends.split(","):
            # One of each first: JIT caches, the pool, the driver.
            scene.render(size=(w, h), backend=backend, dtype=np.uint8)
            cli_ms(args.binary, args.scene, args.size, backend, out)
            py, cli = [], []
            for _ in range(args.runs):
                t0 = time.perf_counter()
                scene.render(size=(w, h), backend=backend, dtype=np.uint8)
                py.append((time.perf_counter() - t0) * 1e3)
                cli.append(cli_ms(args.binary, args.scene, args.size, backend, out))
            p, c = statistics.median(py), statistics.median(cli)
            rows.append((f"render {args.size} {backend}", f"{p:.1f} ms", f"{c:.1f} ms", f"{p - c:+.1f} ms"))
        rng = np.random.default_rng(1)
        points = rng.uniform(-3, 3, size=(args.points, 3))
        for backend in args.backends.split(","):
            scene.distance(points[:1000], backend=backend)
            times = []
            for _ in range(3):
                t0 = time.perf_counter()
                scene.distance(points, backend=backend)
                times.append(time.perf_counter() - t0)
            t = statistics.median(times)
            rows.append((f"distance {args.points} points {backend}", f"{t * 1e3:.1f} ms", "-", f"{args.points / t / 1e6:.1f} M points/s"))
    print(f"{'':40} {'Python':>12} {'CLI phases':>12} {'difference / rate':>20}")
    for r in rows:
        print(f"{r[0]:40} {r[1]:>12} {r[2]:>12} {r[3]:>20}")


if __name__ == "__main__":
    sys.exit(main())
