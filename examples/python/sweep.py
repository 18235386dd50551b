"""Sweep a render setting of a scene from Python, time each render, and measure how far each
picture is from the finest: time against accuracy (docs/python.md). Plots with matplotlib
when it is installed, else prints the table.

    python examples/python/sweep.py [SCENE.sdf] [--backend cpu] [--size 320x240]
"""

import argparse
import time
from pathlib import Path

import numpy as np

import sdfc

ROOT = Path(__file__).resolve().parents[2]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scene", nargs="?", default=str(ROOT / "examples" / "seed3.sdf"))
    parser.add_argument("--backend", default="auto")
    parser.add_argument("--size", default="320x240")
    parser.add_argument("--steps", default="16,32,64,128,256")
    parser.add_argument("-o", "--output", default="sweep.png", help="the chart (with matplotlib)")
    args = parser.parse_args()
    w, h = (int(x) for x in args.size.split("x"))
    steps = [int(s) for s in args.steps.split(",")]

    rows = []
    for n in steps:
        scene = sdfc.Scene(path=args.scene, set={"max_steps": n})
        scene.render(size=(w, h), backend=args.backend)  # the first render prepares the device
        start = time.perf_counter()
        image = scene.render(size=(w, h), backend=args.backend)
        rows.append((n, time.perf_counter() - start, image))
    finest = rows[-1][2]
    print(f"{'max_steps':>9} {'seconds':>9} {'PSNR dB':>8}")
    table = []
    for n, seconds, image in rows:
        mse = float(np.mean((np.clip(image, 0, 1) - np.clip(finest, 0, 1)) ** 2))
        psnr = float("inf") if mse == 0 else 10 * np.log10(1 / mse)
        table.append((n, seconds, psnr))
        print(f"{n:>9} {seconds:>9.4f} {psnr:>8.1f}")

    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("(matplotlib is not installed: no chart)")
        return
    finite = [(s, p, n) for n, s, p in table if np.isfinite(p)]
    fig, ax = plt.subplots()
    ax.plot([s for s, _, _ in finite], [p for _, p, _ in finite], "o-")
    for s, p, n in finite:
        ax.annotate(f"max_steps {n}", (s, p))
    ax.set_xlabel("seconds per render")
    ax.set_ylabel(f"PSNR against max_steps {steps[-1]} (dB)")
    ax.set_title(Path(args.scene).name)
    fig.savefig(args.output, dpi=100)
    print(f"wrote {args.output}")


if __name__ == "__main__":
    main()
