"""fogleman/sdf's README examples beside the same shapes in sdfc's Python (this folder's
example.py, gearlike.py, knurling.py, blobby.py, weave.py), meshed at the same cell size
(BENCHMARKS.md, "Python modelling beside fogleman/sdf"; bench/fogleman/README.md).

For each example: the peer's `save` as the example calls it (its samples, its bounds
estimate, its threads; binary STL), timed, once; sdfc's `Shape.save` of the port at the
peer's cell size over the peer's bounds (binary STL), timed, the median of `--runs`; the
triangles; the triangles of zero area (as written, in f32); whether each mesh is closed
(every edge, its vertices welded by position, in exactly two triangles) and whether
manifold3d (PyPI `manifold3d`) takes it as a manifold; how far each mesh's vertices lie from the surfaces, by the peer's
field and by sdfc's, and its triangles' centres by sdfc's, in cells (mean, 99th percentile,
largest).

    python bench/fogleman/side_by_side.py --peer-python /path/to/venv-with-sdf-fork/bin/python \\
        --examples /path/to/fogleman-sdf/examples [--runs 3] [--only example,gearlike]
"""

import argparse
import json
import os
import platform
import runpy
import statistics
import subprocess
import tempfile
import time
from pathlib import Path

import manifold3d
import numpy as np

import sdfc  # noqa: F401 (the ports import it: a Python without it stops here)

HERE = Path(__file__).resolve().parent
NAMES = ["example", "gearlike", "knurling", "blobby", "weave"]
# The peer's finest examples (2^26 samples) announce more than the default 4 GiB to mesh.
LIMITS = {"memory": 16384}


def read_stl(path):
    """The triangles of a binary STL file, (m, 3, 3) float32."""
    data = Path(path).read_bytes()
    n = int.from_bytes(data[80:84], "little")
    rows = np.frombuffer(data, dtype=np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")]), count=n, offset=84)
    return rows["v"].astype(np.float64)


def open_edges(triangles):
    """Edges not in exactly two triangles, the vertices welded where their positions are
    equal (as an STL reader welds them)."""
    flat = triangles.reshape(-1, 3)
    _, ids = np.unique(flat, axis=0, return_inverse=True)
    f = ids.reshape(-1, 3)
    edges = np.sort(np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]]), axis=1)
    _, counts = np.unique(edges, axis=0, return_counts=True)
    return int((counts != 2).sum())


def zero_area(triangles):
    """Triangles whose cross product is exactly zero, at the f32 coordinates written."""
    t = triangles.astype(np.float64)
    c = np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0])
    return int((np.abs(c).sum(axis=1) == 0).sum())


def manifold(triangles):
    """manifold3d's verdict on the mesh, its vertices welded by position: `ok`, or the name
    of the error it reports (`NotManifold`, ...)."""
    flat = triangles.reshape(-1, 3).astype(np.float32)
    vertices, ids = np.unique(flat, axis=0, return_inverse=True)
    mesh = manifold3d.Mesh(np.ascontiguousarray(vertices), np.ascontiguousarray(ids.reshape(-1, 3).astype(np.uint32)))
    status = manifold3d.Manifold(mesh).status()
    return "ok" if status == manifold3d.Error.NoError else status.name


def stats(d, step):
    a = np.abs(d) / step
    return {"mean": float(a.mean()), "p99": float(np.percentile(a, 99)), "max": float(a.max())}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--peer-python", required=True, help="a Python with PyPI's sdf-fork installed")
    ap.add_argument("--examples", required=True, help="fogleman/sdf's examples folder")
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--only", default=",".join(NAMES))
    args = ap.parse_args()
    out = Path(tempfile.mkdtemp(prefix="sdfc-fogleman-"))
    peer = [args.peer_python, str(HERE / "peer.py")]
    load = os.getloadavg()
    print(f"# {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, {os.cpu_count()} cores, {platform.processor() or platform.machine()}, load {load[0]:.2f} {load[1]:.2f} {load[2]:.2f}")
    print("| example | lines (peer / sdfc) | samples | cell | peer s | sdfc s | speed-up | triangles (peer / sdfc) | zero-area triangles (peer / sdfc) | open edges (peer / sdfc) | manifold3d (peer / sdfc) | peer's vertices from the surface, cells: by peer / by sdfc (mean, p99, max) | sdfc's vertices: by sdfc / by peer | triangle centres by sdfc's field: peer / sdfc |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for name in args.only.split(","):
        example = Path(args.examples) / f"{name}.py"
        ours = HERE / f"{name}.py"
        # The peer: meshed as its example saves it.
        stl_peer, info_path = out / f"{name}-peer.stl", out / f"{name}-peer.json"
        subprocess.run(peer + ["mesh", str(example), str(stl_peer), str(info_path)], check=True)
        info = json.loads(info_path.read_text())
        step, bounds = info["step"], info["bounds"]
        # sdfc: the port, at the peer's cell size over the peer's bounds.
        shape = runpy.run_path(str(ours))["f"]
        stl_ours = out / f"{name}-sdfc.stl"
        times = []
        for _ in range(args.runs):
            fresh = runpy.run_path(str(ours))["f"]  # compiled anew for every run
            t0 = time.perf_counter()
            fresh.save(stl_ours, voxel=step, bounds=bounds, limits=LIMITS)
            times.append(time.perf_counter() - t0)
        ours_s = statistics.median(times)
        v, f, _ = shape.mesh(voxel=step, bounds=bounds, limits=LIMITS)
        tri_peer = read_stl(stl_peer)
        tri_ours = read_stl(stl_ours)
        # Distances at the vertices, by both fields.
        peer_vertices = np.unique(tri_peer.reshape(-1, 3), axis=0)
        np.save(out / "pv.npy", peer_vertices)
        np.save(out / "ov.npy", v)
        subprocess.run(peer + ["eval", str(example), str(out / "pv.npy"), str(out / "pv-d.npy")], check=True)
        subprocess.run(peer + ["eval", str(example), str(out / "ov.npy"), str(out / "ov-d.npy")], check=True)
        peer_by_peer = stats(np.load(out / "pv-d.npy"), step)
        peer_by_ours = stats(shape.distance(peer_vertices), step)
        ours_by_ours = stats(shape.distance(v), step)
        ours_by_peer = stats(np.load(out / "ov-d.npy"), step)
        # The triangles' centres, by sdfc's field: how far the faces, not only their
        # corners, stray from the surface.
        centres_peer = stats(shape.distance(tri_peer.mean(axis=1)), step)
        centres_ours = stats(shape.distance(tri_ours.mean(axis=1)), step)

        def three(s):
            return f"{s['mean']:.3f}, {s['p99']:.3f}, {s['max']:.3f}"

        lines = [sum(1 for line in p.read_text().splitlines() if line.strip() and not line.lstrip().startswith("#")) for p in (example, ours)]
        print(
            f"| {name} | {lines[0]} / {lines[1]} | 2^{int(np.log2(info['samples']))} | {step:.4f} | {info['seconds']:.2f} | {ours_s:.3f} | {info['seconds'] / ours_s:.1f}× "
            f"| {info['triangles']} / {len(tri_ours)} | {zero_area(tri_peer)} / {zero_area(tri_ours)} "
            f"| {open_edges(tri_peer)} / {open_edges(tri_ours)} | {manifold(tri_peer)} / {manifold(tri_ours)} "
            f"| {three(peer_by_peer)} / {three(peer_by_ours)} | {three(ours_by_ours)} / {three(ours_by_peer)} "
            f"| {three(centres_peer)} / {three(centres_ours)} |",
            flush=True,
        )


if __name__ == "__main__":
    main()
