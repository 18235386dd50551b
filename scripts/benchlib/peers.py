"""Suites beside something else: the hand-written CUDA tracer of bench/handwritten (the peer),
the Python package against the CLI's own phases, and the CPU side (the examples on the CPU,
two builds side by side)."""

import json
import os
import statistics
import tempfile
import time

from . import core
from .core import bench, fmt, ms, ratio, scene_name


# The hand-written tracer's scenes (`tracer SCENE`) and the .sdf files that say the same.
PEER_SCENES = {"spheres": "bench/handwritten/scene.sdf", "bulb": "bench/handwritten/bulb.sdf",
               "lattice": "bench/handwritten/lattice.sdf"}


def _ppm_to_png(ppm, png):
    """The tracer's binary PPM as an 8-bit RGB PNG (for `sdfc compare`), stdlib only."""
    import struct
    import zlib
    data = open(ppm, "rb").read()
    head = data.split(b"\n", 3)
    w, h = (int(v) for v in head[1].split())
    pixels = head[3]
    rows = b"".join(b"\0" + pixels[y * 3 * w:(y + 1) * 3 * w] for y in range(h))
    chunk = lambda kind, body: (struct.pack(">I", len(body)) + kind + body
                                + struct.pack(">I", zlib.crc32(kind + body) & 0xFFFFFFFF))
    with open(png, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
                + chunk(b"IDAT", zlib.compress(rows, 6)) + chunk(b"IEND", b""))


def peer(ctx):
    if "cuda" not in ctx.backends:
        raise core.Skip("the peer is a CUDA program: --backends cuda[,wgpu]")
    tracer = "/tmp/sdfc-tracer"
    _, out, err, code = core.run(["nvcc", "-O3", "-arch=" + ctx.opt("arch", "sm_90"), "-o",
                                  tracer, "bench/handwritten/tracer.cu"])
    if code:
        raise core.Skip("nvcc: %s" % (core.last_line(err) or "not found"))
    size = ctx.size_list(["1920x1080"])[0][0]
    w, h = size.split("x")
    frames = ctx.n_frames(21)
    head = ["scene, shadows", "ε, steps", "hand-written"]
    for b in ctx.backends:
        head += ["sdfc %s %s" % (b, x.name) for x in ctx.builds]
    head += ["cuda / hand", "pictures (CUDA against hand-written)"]
    t = ctx.table("bench/handwritten/tracer.cu (`nvcc -O3`, `tracer SCENE soft|hard E S`) and "
                  "`sdfc bench FILE --size %s --frames %d --set epsilon=E --set max_steps=S` of "
                  "its scenes (scene.sdf, bulb.sdf, lattice.sdf; hard: the light's penumbra "
                  "removed): median GPU ms; the pictures at the row's settings compared by "
                  "`sdfc compare` (PSNR, pixels over 0.1 apart)." % (size, frames), head)
    tmp = tempfile.mkdtemp(prefix="sdfc-peer-")
    for name in ctx.opt("scene", ["spheres", "bulb", "lattice"]):
        for shadow in ctx.opt("shadows", ["soft", "hard"]):
            scene = PEER_SCENES[name]
            if shadow == "hard":
                text = open(scene).read().replace(", penumbra: 4deg", "")
                scene = os.path.join(tmp, "%s_hard.sdf" % name)
                open(scene, "w").write(text)
            for e in ctx.opt("epsilons", ["1e-3", "1e-4", "1e-5"]):
                for s in ctx.opt("steps", ["512", "1024"]):
                    ppm = os.path.join(tmp, "hand.ppm")
                    _, out, err, code = core.run([tracer, name, shadow, e, s, w, h, frames, ppm])
                    hand = json.loads(out)["median_ms"] if code == 0 else None
                    settings = ["--set", "epsilon=" + e, "--set", "max_steps=" + s]
                    cells, cuda = [], None
                    for b in ctx.backends:
                        for x in ctx.builds:
                            got = bench(x, [scene], b, size, None, frames, settings, ctx.fails)
                            v = ms(got[0]) if got else None
                            cells.append(fmt(v, 3))
                            if b == "cuda" and x.name == "new":
                                cuda = v
                    pictures = "-"
                    if code == 0:
                        ours = os.path.join(tmp, "sdfc.png")
                        _ppm_to_png(ppm, os.path.join(tmp, "hand.png"))
                        core.render(ctx.new, scene, "cuda", ours, size, None, settings)
                        pictures = core.agreement(core.compare(ctx.new, os.path.join(tmp, "hand.png"), ours))
                    t.add("%s, %s" % (name, shadow), "%s, %s" % (e, s), fmt(hand, 3), *cells,
                          ratio(cuda, hand), pictures)


# The phases of `sdfc render --stats` a Python render does not do: the process's start, its
# arguments, the file read, the wait for a device (Python holds its devices open), the PNG and
# the file.
OUTSIDE = {"start", "arguments", "read", "device", "PNG", "write", "rename", "fsync", "exit"}


def _cli_ms(build, scene, size, backend, out):
    """The CLI's own time for the phases a Python render also does, ms."""
    wall, log, code = core.render(build, scene, backend, out, size, None, ["--stats"])
    phases = core.stats(log)
    return sum(v for k, v in phases.items() if not k.endswith(" how") and k != "run"
               and k not in OUTSIDE and v is not None)


def python(ctx):
    try:
        import numpy as np
        import sdfc
    except ImportError as e:
        raise core.Skip("%s (install the wheel, or put the package on PYTHONPATH)" % e)
    scene_path = ctx.scene_list(["examples/seed3.sdf"])[0]
    size = ctx.size_list(["1920x1080"])[0][0]
    w, h = (int(v) for v in size.split("x"))
    runs, points = ctx.n_runs(5), ctx.opt("points", 1_000_000)
    t = ctx.table(
        "`Scene.render(size, backend, dtype=np.uint8)` of %s at %s (one Scene, which keeps what "
        "it prepared, and a new Scene each call) against the phases of `sdfc render --stats` "
        "that do the same work (all but start, arguments, read, device, PNG, write), run "
        "alternately, median of %d, ms; `Scene.distance` on %d random points, median of 3." % (
            scene_path, size, runs, points),
        ["what", "backend", "Python", "CLI phases", "difference / rate"])
    scene = sdfc.Scene(path=scene_path)
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "x.png")
        for b in ctx.backends:
            scene.render(size=(w, h), backend=b, dtype=np.uint8)
            _cli_ms(ctx.new, scene_path, size, b, out)
            kept, fresh, cli = [], [], []
            for _ in range(runs):
                t0 = time.perf_counter()
                scene.render(size=(w, h), backend=b, dtype=np.uint8)
                kept.append((time.perf_counter() - t0) * 1e3)
                t0 = time.perf_counter()
                sdfc.Scene(path=scene_path).render(size=(w, h), backend=b, dtype=np.uint8)
                fresh.append((time.perf_counter() - t0) * 1e3)
                cli.append(_cli_ms(ctx.new, scene_path, size, b, out))
            p, f, c = (statistics.median(v) for v in (kept, fresh, cli))
            t.add("render", b, fmt(p, 1), fmt(c, 1), "%+.1f ms" % (p - c))
            t.add("render, a new Scene each call", b, fmt(f, 1), fmt(c, 1), "%+.1f ms" % (f - c))
        rng = np.random.default_rng(1)
        pts = rng.uniform(-3, 3, size=(points, 3))
        for b in ctx.backends:
            for label, make in (("distance", lambda: scene),
                                ("distance, a new Scene each call",
                                 lambda: sdfc.Scene(path=scene_path))):
                scene.distance(pts[:1000], backend=b)
                times = []
                for _ in range(3):
                    t0 = time.perf_counter()
                    make().distance(pts, backend=b)
                    times.append(time.perf_counter() - t0)
                d = statistics.median(times)
                t.add(label, b, fmt(d * 1e3, 1), "-", "%.1f M points/s" % (points / d / 1e6))


def cpu_ab(ctx):
    """The examples on the CPU, the builds alternating round by round (on a shared machine
    only neighbouring runs compare: the rounds show the spread)."""
    scenes = ctx.scene_list(["examples/seed%d.sdf" % i for i in range(1, 7)])
    threads = ctx.opt("threads", ["2"])
    head = ["scene", "size", "threads", "round"] + [x.name for x in ctx.builds]
    if ctx.side_by_side:
        head.append("new / old")
    head += ["Mrays/s", "steps/px"]
    load = open("/proc/loadavg").read().split()[:3]
    t = ctx.table("`sdfc bench SCENE --backend cpu --size S --frames N --threads T` (N = %d at "
                  "640x480 and below, else %d): median ms; Mrays/s and steps/px of the new "
                  "build; load average at the start %s." % (
                      ctx.n_frames(5), ctx.n_frames(3), " ".join(load)), head,
                  ["---"] * 4 + ["---:"] * (len(head) - 4))
    for r in range(ctx.n_runs(1)):
        for size, aa in ctx.size_list(["640x480", "1920x1080"]):
            w, h = map(int, size.split("x"))
            frames = ctx.n_frames(5 if w * h <= 640 * 480 else 3)
            for f in scenes:
                for th in threads:
                    got = {}
                    for x in ctx.builds:
                        e = bench(x, [f], "cpu", size, aa, frames, ["--threads", th], ctx.fails)
                        got[x.name] = e[0] if e else None
                    cells = [ms(got[x.name]) for x in ctx.builds]
                    if ctx.side_by_side:
                        cells.append(ratio(ms(got["new"]), ms(got["old"])))
                    n = got["new"]
                    t.add(scene_name(f), size, th, str(r + 1), *cells,
                          fmt(n and n["mrays_per_s"]), fmt(n and n["stats"]["steps_mean"], 1))


SUITES = {
    "peer": (peer, "beside bench/handwritten's CUDA tracer (nvcc): spheres, a Mandelbulb and a "
             "lattice, soft and hard shadows, at ε 1e-3..1e-5, 512 and 1 024 steps, and the "
             "pictures compared; --with arch=sm_90, scene=spheres,bulb,lattice, shadows=soft,hard, "
             "epsilons=..., steps=..."),
    "python": (python, "import sdfc: Scene.render against the CLI's phases, Scene.distance "
               "throughput (the package importable)"),
    "cpu": (cpu_ab, "the CPU renderer: the report scenes at 640x480 and 1080p, median ms, the "
            "builds alternating; --runs rounds, --with threads=1,2"),
}
