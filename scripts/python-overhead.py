#!/usr/bin/env python3
"""Measures what the Python package adds on top of the work itself (docs/python.md): the
median wall time of `Scene.render` (uint8 sRGB, in-process) against the phases of
`sdfc render --stats` that do the same work (every phase but the process's start, the
arguments, the file read, the wait for the device, the PNG and the file), each of the same scene, size and backend,
run alternately, by one Scene (which keeps what it prepared) and by a new Scene each call;
and `Scene.distance` throughput on 10^6 points on each backend asked for, both ways.

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

# The phases of `sdfc render --stats` that a Python render does not do: the process's start,
# its arguments, the file read, the wait for a device (Python holds its devices open), the
# PNG and the file.
OUTSIDE = {"start", "arguments", "read", "device", "PNG", "write"}


def cli_ms(binary: str, scene: str, size: str, backend: str, out: Path) -> float:
    """The CLI's own time for the phases a Python render also does, in milliseconds."""
    run = subprocess.run(
        [binary, "render", scene, "--backend", backend, "--size", size, "--stats", "-o", str(out)],
        check=True,
        capture_output=True,
        text=True,
    )
    # The phases of the run's breakdown: two spaces, the name, its milliseconds.
    phases = re.findall(r"^  (\S[^\n]*?)\s+([0-9.]+) ms  ", run.stdout + run.stderr, re.M)
    if not phases:
        raise SystemExit(f"`render --stats` printed no phases:\n{run.stderr}")
    total = sum(float(ms) for name, ms in phases if name not in OUTSIDE)
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
            py, fresh, cli = [], [], []
            for _ in range(args.runs):
                t0 = time.perf_counter()
                scene.render(size=(w, h), backend=backend, dtype=np.uint8)
                py.append((time.perf_counter() - t0) * 1e3)
                # A new Scene each call prepares everything again (the device and the
                # pipelines the process holds excepted).
                t0 = time.perf_counter()
                sdfc.Scene(path=args.scene).render(size=(w, h), backend=backend, dtype=np.uint8)
                fresh.append((time.perf_counter() - t0) * 1e3)
                cli.append(cli_ms(args.binary, args.scene, args.size, backend, out))
            p, f, c = statistics.median(py), statistics.median(fresh), statistics.median(cli)
            rows.append((f"render {args.size} {backend}", f"{p:.1f} ms", f"{c:.1f} ms", f"{p - c:+.1f} ms"))
            rows.append((f"  the same, a new Scene each call", f"{f:.1f} ms", f"{c:.1f} ms", f"{f - c:+.1f} ms"))
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
            times = []
            for _ in range(3):
                t0 = time.perf_counter()
                sdfc.Scene(path=args.scene).distance(points, backend=backend)
                times.append(time.perf_counter() - t0)
            t = statistics.median(times)
            rows.append((f"  the same, a new Scene each call", f"{t * 1e3:.1f} ms", "-", f"{args.points / t / 1e6:.1f} M points/s"))
    print(f"{'':40} {'Python':>12} {'CLI phases':>12} {'difference / rate':>20}")
    for r in rows:
        print(f"{r[0]:40} {r[1]:>12} {r[2]:>12} {r[3]:>20}")


if __name__ == "__main__":
    sys.exit(main())
