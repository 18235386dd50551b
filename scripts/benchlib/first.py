"""The first second of a whole `sdfc render`: every example rendered as whole processes with
--stats, cold (sdfc's cache directory and the NVIDIA driver's disk caches empty), warm (all
filled; the median of --runs) and with sdfc's cache alone (the driver's disk caches off:
__GL_SHADER_DISK_CACHE=0, CUDA_CACHE_DISABLE=1) and, with the mode `vulkan`, warm through wgpu
with its instance limited to Vulkan (WGPU_BACKEND=vulkan); each phase of --stats beside the
wall time measured outside ("after": wall − run, the process's end after the image plus the
error of --stats' "start"). With `plain=N`, N whole warm processes without --stats of each
build, alternating (what a user waits for). Beside them a bare CUDA context and Vulkan device
(bare.py). Then the marched scaling scenes named by `scaling=`: whole runs and `sdfc bench`'s
median GPU time. Also the warm first picture (`first_picture`) of the render-path and devices
suites."""

import os
import shutil
import sys

from . import core
from .core import IMG, fmt, median, render, run, scene_name

SHOWN = ["start", "scene", "device", "kernel", "PTX", "driver compile", "upload", "frame",
         "readback", "conversion", "sRGB", "PNG", "write", "fsync", "rename", "image"]
WORK = "/tmp/first-second"
DIRS = {k: os.path.join(WORK, k) for k in ["sdfc", "gl", "cuda"]}


def _env(driver_caches=True, extra=None):
    e = dict(os.environ, **(extra or {}))
    e["SDFC_CACHE_DIR"], e["__GL_SHADER_DISK_CACHE_PATH"] = DIRS["sdfc"], DIRS["gl"]
    e["CUDA_CACHE_PATH"] = DIRS["cuda"]
    if not driver_caches:
        e["__GL_SHADER_DISK_CACHE"], e["CUDA_CACHE_DISABLE"] = "0", "1"
    return e


def _empty_caches():
    for d in DIRS.values():
        shutil.rmtree(d, ignore_errors=True)
        os.makedirs(d, exist_ok=True)


def _own_device(how):
    """The device's own time on its thread, from the `device` phase's description."""
    if "thread of its own in " not in how:
        return None
    return float(how.split("thread of its own in ", 1)[1].split(" ms")[0])


def first_second(ctx):
    scenes = ctx.scene_list(core.examples())
    modes = ctx.opt("modes", ["cold", "warm", "sdfc"])
    warm = ctx.n_runs(3)
    size = ctx.size_list(["1920x1080"])[0][0]
    image = os.path.join(WORK, "image.png")
    os.makedirs(WORK, exist_ok=True)
    rows = []

    def measure(label, backend, mode, cmd, times, driver_caches=True, extra=None):
        walls, phases = [], []
        for _ in range(times):
            wall, out, err, code = run(cmd, _env(driver_caches, extra))
            if code != 0:
                ctx.fails.note("%s %s %s" % (label, backend, mode), err)
                return
            walls.append(wall * 1e3)
            phases.append(core.stats(out))
        row = {"label": label, "backend": backend, "mode": mode, "wall": median(walls),
               "run": median([p.get("run") for p in phases]),
               "how": phases[-1].get("driver compile how", ""),
               "own": median([_own_device(p.get("device how", "")) for p in phases])}
        row["after"] = median([w - p["run"] for w, p in zip(walls, phases) if p.get("run")])
        row["phases"] = {k: median([p.get(k) for p in phases]) for k in SHOWN}
        rows.append(row)

    bare = {}
    for kind in (["cuda"] if "cuda" in ctx.backends else []) + (
            ["vulkan"] if "wgpu" in ctx.backends else []):
        inside, outside = [], []
        for _ in range(3):
            wall, out, err, code = run([sys.executable, os.path.join(os.path.dirname(__file__),
                                                                      "bare.py"), kind])
            if code != 0:
                ctx.fails.note("bare %s" % kind, err)
                break
            inside.append(float(out) * 1e3)
            outside.append(wall * 1e3)
        if inside:
            bare[kind] = (median(inside), median(outside))

    for backend in ctx.backends:
        for f in scenes:
            cmd = [ctx.new.path, "render", f, "--backend", backend, "--size", size, "--stats",
                   "-o", image]
            _empty_caches()
            if "cold" in modes:
                measure(scene_name(f), backend, "cold", cmd, 1)
            else:
                run(cmd, _env())
            if "warm" in modes:
                measure(scene_name(f), backend, "warm", cmd, warm)
            if "sdfc" in modes:
                measure(scene_name(f), backend, "sdfc cache", cmd, warm, driver_caches=False)
            if "vulkan" in modes and backend == "wgpu":
                measure(scene_name(f), backend, "Vulkan alone", cmd, warm,
                        extra={"WGPU_BACKEND": "vulkan"})
    for f in ctx.opt("scaling", []):
        label = scene_name(f) + " marched"
        for backend in ctx.backends:
            cmd = [ctx.new.path, "render", f, "--backend", backend, "--size", size, "--set",
                   "method=march", "--stats", "-o", image]
            _empty_caches()
            measure(label, backend, "cold", cmd, 1)
            measure(label, backend, "warm", cmd, warm)
    ctx.data["stats"] = rows
    head = (["scene", "backend", "mode", "wall", "run", "after"] + SHOWN[:3] + ["device (own)"]
            + SHOWN[3:] + ["other", "driver compile: how"])
    t = ctx.table(
        "Whole `sdfc render FILE --size %s --stats` processes of the new build, ms (warm and "
        "sdfc cache: median of %d). *run*: the process's start to the image written, by "
        "--stats; *after*: wall − run; *device*: the wait for it, *(own)* its time on its "
        "thread beside the front end." % (size, warm), head,
        ["---"] * 3 + ["---:"] * (len(head) - 4) + ["---"])
    for r in rows:
        known = sum(r["phases"][k] or 0 for k in SHOWN)
        other = None if r["run"] is None else r["run"] - known
        t.add(r["label"], r["backend"], r["mode"], *[fmt(r[k], 1) for k in ("wall", "run",
                                                                           "after")],
              *[fmt(r["phases"][k], 1) for k in SHOWN[:3]], fmt(r["own"], 1),
              *[fmt(r["phases"][k], 1) for k in SHOWN[3:]], fmt(other, 1), r["how"])
    for kind, (inside, outside) in bare.items():
        ctx.data["bare " + kind] = {"create_ms": inside, "process_ms": outside}
    if bare:
        t = ctx.table("A bare driver context (python3 + ctypes, scripts/benchlib/bare.py), "
                      "median of 3 processes, ms.", ["context", "created", "whole process"])
        for kind, (inside, outside) in bare.items():
            t.add(kind, fmt(inside, 1), fmt(outside, 1))
    plain = ctx.opt("plain", 0)
    if plain:
        _plain(ctx, scenes, size, plain, image)


def _plain(ctx, scenes, size, n, image):
    """Whole warm processes without --stats, the builds alternating, n of each after one
    untimed run: median (min–max) wall ms."""
    t = ctx.table(
        "Whole warm `sdfc render FILE --backend B --size %s` processes without --stats, wall "
        "ms, median of %d after one untimed run (min–max), the builds alternating." % (size, n),
        ["scene", "backend"] + [x.name for x in ctx.builds], ["---", "---"] + ["---:"] *
        len(ctx.builds))
    for backend in ctx.backends:
        for f in scenes:
            walls = {x.name: [] for x in ctx.builds}
            for i in range(n + 1):
                for x in ctx.builds:
                    wall, out, err, code = run([x.path, "render", f, "--backend", backend,
                                                "--size", size, "-o", image], _env())
                    if code:
                        ctx.fails.note("plain %s %s %s" % (scene_name(f), backend, x), err)
                    elif i > 0:
                        walls[x.name].append(wall * 1e3)
            ctx.data.setdefault("plain", []).append({"scene": f, "backend": backend,
                                                     "walls_ms": walls})
            t.add(scene_name(f), backend, *["%s (%s–%s)" % (fmt(median(v), 0), fmt(min(v), 0),
                                                             fmt(max(v), 0)) if v else "-"
                                             for v in walls.values()])


def first_picture(ctx, backends, scene, lists=None):
    """The warm first picture: whole `sdfc render SCENE --size 320x240` processes, s, through
    each backend with `--devices auto` (3 runs) and, given `lists`, through the first GPU
    backend with each list (2 runs)."""
    size = ctx.opt("first_size", "320x240")
    head = ["build"] + ["%s auto" % b for b in backends]
    head += ["%s [%s]" % (backends[0], d) for d in lists or []]
    t = ctx.table("The warm first picture: whole `sdfc render %s --size %s [--devices LIST]` "
                  "processes, s (auto: %d runs; a list: %d runs)." % (
                      scene, size, ctx.n_runs(3), ctx.n_runs(2)), head)
    for x in ctx.builds:
        for b in backends:
            render(x, scene, b, IMG + "/first.png", size)  # warm
    for x in ctx.builds:
        cells = [x.name]
        for b in backends:
            cells.append(", ".join(fmt(render(x, scene, b, IMG + "/first.png", size)[0])
                                   for _ in range(ctx.n_runs(3))))
        for d in lists or []:
            cells.append(", ".join(fmt(render(x, scene, backends[0], IMG + "/first.png", size,
                                              None, ["--devices", d])[0])
                                   for _ in range(ctx.n_runs(2))))
        t.add(*cells)

