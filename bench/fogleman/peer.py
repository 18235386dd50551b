"""The peer's side of bench/fogleman/side_by_side.py, run by the Python that has PyPI's
`sdf-fork` (fogleman/sdf): runs one of fogleman/sdf's example files with its `save` held back,
then, timed, meshes the shape it built as that `save` would have (the same samples, its
bounds estimate, the default worker threads) and writes the binary STL; or evaluates that
shape's distance at points.

    python peer.py mesh EXAMPLE.py OUT.stl OUT.json
    python peer.py eval EXAMPLE.py POINTS.npy OUT.npy
"""

import json
import sys
import time

import numpy as np
import sdf
from sdf import mesh, stl


def shape(path):
    """The shape the example saves and the arguments of its `save`."""
    saved = {}

    def hold(self, name, *args, **kwargs):
        saved["f"], saved["kwargs"] = self, kwargs

    sdf.d3.SDF3.save = hold
    code = open(path).read()
    exec(compile(code, path, "exec"), {"__name__": "__example__"})
    return saved["f"], saved["kwargs"]


def main():
    what, example = sys.argv[1], sys.argv[2]
    f, kwargs = shape(example)
    if what == "eval":
        points = np.load(sys.argv[3])
        np.save(sys.argv[4], f(points).reshape(-1))
        return
    samples = kwargs.get("samples", mesh.SAMPLES)
    start = time.perf_counter()
    bounds = mesh._estimate_bounds(f)
    points = mesh.generate(f, bounds=bounds, samples=samples, verbose=False)
    stl.write_binary_stl(sys.argv[3], points)
    seconds = time.perf_counter() - start
    (x0, y0, z0), (x1, y1, z1) = bounds
    step = ((x1 - x0) * (y1 - y0) * (z1 - z0) / samples) ** (1 / 3)
    report = {
        "seconds": seconds,
        "samples": samples,
        "step": step,
        "bounds": [[float(x) for x in bounds[0]], [float(x) for x in bounds[1]]],
        "triangles": len(points) // 3,
        "workers": mesh.WORKERS,
    }
    with open(sys.argv[4], "w") as out:
        json.dump(report, out)


if __name__ == "__main__":
    main()
