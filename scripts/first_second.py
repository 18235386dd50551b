#!/usr/bin/env python3
"""Where the first second of `sdfc render` goes (issue 23, item 1), run by
scripts/device-first-second.sh on a GPU host (and usable anywhere: `--backends wgpu` on
lavapipe).

    first_second.py SDFC [--backends cuda,wgpu] [--size WxH] [--warm N] [--scenes FILE...]
                         [--scaling FILE...] [--frames N] [--work DIR] [--modes cold,warm,sdfc,vulkan]
                         [--plain N] [--old OLD_SDFC]
    first_second.py --bare cuda|vulkan

For each backend and scene, whole `sdfc render --stats` processes: cold (sdfc's cache
directory and the driver's disk caches empty), warm (all filled; the median of N runs) and
"sdfc cache" (sdfc's cache filled, the NVIDIA driver's own disk caches turned off:
__GL_SHADER_DISK_CACHE=0, CUDA_CACHE_DISABLE=1) and, with the mode `vulkan`, warm through wgpu
with its instance limited to Vulkan (WGPU_BACKEND=vulkan: no GL backend), each phase of `--stats`'s breakdown beside
the process's wall time measured from outside (and the difference, "after": the process's end
after the image, which it cannot time itself, plus the error of `--stats`'s "start"). With
`--plain N`, whole warm processes without `--stats` (what a user waits for), N of each, the
medians; with `--old`, the same of another build, run alternately with SDFC's (a before and
after on one machine at one time). Beside them, a bare context creation in a
process of its own (`--bare`: python3 loading the driver through ctypes, no sdfc): CUDA's
cuInit and cuCtxCreate, Vulkan's instance, physical devices and a device with one queue.
Then the scaling scenes marched (`--set method=march`): whole warm runs and `sdfc bench`'s
median GPU time of `--frames` frames. The tables are printed last.
"""

import argparse
import ctypes
import json
import os
import shutil
import statistics
import subprocess
import sys
import time

PHASES = [
    "start", "arguments", "scene", "setup", "device", "kernel", "PTX", "driver compile",
    "preparation", "memory", "upload", "frame", "readback", "conversion", "render", "sRGB",
    "PNG", "encode", "write", "fsync", "rename", "image",
]
SHOWN = ["start", "scene", "device", "kernel", "PTX", "driver compile", "upload", "frame",
         "readback", "conversion", "sRGB", "PNG", "write", "fsync", "rename", "image"]


def bare_cuda():
    """Seconds to load libcuda, initialise it and create a context on device 0."""
    t = time.perf_counter()
    cu = ctypes.CDLL("libcuda.so.1")
    assert cu.cuInit(0) == 0, "cuInit"
    dev = ctypes.c_int()
    assert cu.cuDeviceGet(ctypes.byref(dev), 0) == 0, "cuDeviceGet"
    ctx = ctypes.c_void_p()
    assert cu.cuCtxCreate_v2(ctypes.byref(ctx), 0, dev) == 0, "cuCtxCreate"
    assert cu.cuCtxSynchronize() == 0, "cuCtxSynchronize"
    return time.perf_counter() - t


def bare_vulkan():
    """Seconds to load the Vulkan loader, create an instance, enumerate the physical devices
    and create a device with one queue on the first (the floor under wgpu's device)."""
    t = time.perf_counter()
    vk = ctypes.CDLL("libvulkan.so.1")
    P, U32 = ctypes.c_void_p, ctypes.c_uint32

    class InstanceInfo(ctypes.Structure):
        _fields_ = [("sType", ctypes.c_int), ("pNext", P), ("flags", U32), ("app", P),
                    ("layers", U32), ("layer_names", P), ("exts", U32), ("ext_names", P)]

    class QueueInfo(ctypes.Structure):
        _fields_ = [("sType", ctypes.c_int), ("pNext", P), ("flags", U32), ("family", U32),
                    ("count", U32), ("priorities", ctypes.POINTER(ctypes.c_float))]

    class DeviceInfo(ctypes.Structure):
        _fields_ = [("sType", ctypes.c_int), ("pNext", P), ("flags", U32), ("queues", U32),
                    ("queue_infos", ctypes.POINTER(QueueInfo)), ("layers", U32),
                    ("layer_names", P), ("exts", U32), ("ext_names", P), ("features", P)]

    instance = P()
    info = InstanceInfo(sType=1)  # VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO
    assert vk.vkCreateInstance(ctypes.byref(info), None, ctypes.byref(instance)) == 0
    n = U32()
    vk.vkEnumeratePhysicalDevices(instance, ctypes.byref(n), None)
    devices = (P * n.value)()
    assert vk.vkEnumeratePhysicalDevices(instance, ctypes.byref(n), devices) == 0
    assert n.value > 0, "no physical device"
    priority = ctypes.c_float(1.0)
    queue = QueueInfo(sType=2, family=0, count=1, priorities=ctypes.pointer(priority))
    dinfo = DeviceInfo(sType=3, queues=1, queue_infos=ctypes.pointer(queue))
    device = P()
    assert vk.vkCreateDevice(P(devices[0]), ctypes.byref(dinfo), None, ctypes.byref(device)) == 0
    return time.perf_counter() - t


def run(cmd, env):
    """Runs `cmd`; returns (wall seconds measured outside, stdout, stderr, exit code)."""
    t = time.perf_counter()
    p = subprocess.run(cmd, env=env, capture_output=True, text=True)
    return time.perf_counter() - t, p.stdout, p.stderr, p.returncode


def breakdown(stdout):
    """The phases of `--stats`'s `run` block, in ms, with the driver compile's description,
    and the run's total. A device opened beside the front end gives its own time as the
    phase "device (own)" ("device" is then the wait for it)."""
    phases, how, total = {}, "", None
    inside = False
    for line in stdout.splitlines():
        if line.startswith("run "):
            inside = True
            total = float(line.split()[1])
            continue
        if inside and line.startswith("  "):
            name, rest = line[2:18].strip(), line[18:]
            value = rest.split(" ms")[0].strip()
            phases[name] = float(value) if value != "-" else None
            if name == "driver compile":
                how = rest.split(" ms", 1)[1].strip()
            if name == "device" and "thread of its own in " in rest:
                own = rest.split("thread of its own in ", 1)[1].split(" ms")[0]
                phases["device (own)"] = float(own)
        elif inside:
            inside = False
    return phases, how, total


def median(values):
    values = [v for v in values if v is not None]
    return statistics.median(values) if values else None


def fmt(x):
    return "-" if x is None else "%.0f" % x if x >= 100 else "%.1f" % x


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("sdfc", nargs="?")
    ap.add_argument("--bare", choices=["cuda", "vulkan"])
    ap.add_argument("--backends", default="cuda,wgpu")
    ap.add_argument("--size", default="1920x1080")
    ap.add_argument("--warm", type=int, default=3)
    ap.add_argument("--scenes", nargs="*")
    ap.add_argument("--scaling", nargs="*", default=[])
    ap.add_argument("--frames", type=int, default=5)
    ap.add_argument("--work", default="/tmp/first-second")
    ap.add_argument("--modes", default="cold,warm,sdfc")  # and vulkan
    ap.add_argument("--plain", type=int, default=0)
    ap.add_argument("--old")
    a = ap.parse_args()
    if a.bare:
        print("%.6f" % (bare_cuda() if a.bare == "cuda" else bare_vulkan()))
        return 0
    scenes = a.scenes if a.scenes is not None else sorted(
        os.path.join("examples", f) for f in os.listdir("examples") if f.endswith(".sdf"))
    backends = a.backends.split(",")
    dirs = {k: os.path.join(a.work, k) for k in ["sdfc", "gl", "cuda"]}
    image = os.path.join(a.work, "image.png")

    def env(driver_caches=True, extra=None):
        e = dict(os.environ, **(extra or {}))
        e["SDFC_CACHE_DIR"] = dirs["sdfc"]
        e["__GL_SHADER_DISK_CACHE_PATH"] = dirs["gl"]
        e["CUDA_CACHE_PATH"] = dirs["cuda"]
        if not driver_caches:
            e["__GL_SHADER_DISK_CACHE"] = "0"
            e["CUDA_CACHE_DISABLE"] = "1"
        return e

    def empty_caches():
        for d in dirs.values():
            shutil.rmtree(d, ignore_errors=True)
            os.makedirs(d, exist_ok=True)

    rows, failures = [], []

    def measure(label, backend, mode, cmd, times, driver_caches=True, extra=None):
        walls, phases, totals, how = [], [], [], ""
        for _ in range(times):
            wall, out, err, code = run(cmd, env(driver_caches, extra))
            if code != 0:
                failures.append("%s %s %s: exit %d: %s" % (label, backend, mode, code,
                                                           err.strip().splitlines()[-1:]))
                return
            p, how, total = breakdown(out)
            walls.append(wall * 1e3)
            phases.append(p)
            totals.append(total)
        row = {"label": label, "backend": backend, "mode": mode, "wall": median(walls),
               "total": median(totals), "how": how,
               "after": median([w - t for w, t in zip(walls, totals) if t is not None]),
               "phases": {k: median([p.get(k) for p in phases])
                          for k in PHASES + ["device (own)"]}}
        rows.append(row)
        print(json.dumps(row), flush=True)

    bare = {}
    for kind in (["cuda"] if "cuda" in backends else []) + (["vulkan"] if "wgpu" in backends else []):
        inside, outside = [], []
        for _ in range(3):
            wall, out, err, code = run([sys.executable, __file__, "--bare", kind], env())
            if code != 0:
                failures.append("bare %s: %s" % (kind, err.strip().splitlines()[-1:]))
                break
            inside.append(float(out) * 1e3)
            outside.append(wall * 1e3)
        if inside:
            bare[kind] = (median(inside), median(outside))
            print("bare %s context: %.1f ms inside, %.1f ms process" % (kind, *bare[kind]), flush=True)

    for backend in backends:
        for f in scenes:
            label = os.path.splitext(os.path.basename(f))[0]
            cmd = [a.sdfc, "render", f, "--backend", backend, "--size", a.size, "--stats", "-o", image]
            modes = a.modes.split(",")
            empty_caches()
            if "cold" in modes:
                measure(label, backend, "cold", cmd, 1)
            else:
                run(cmd, env())  # fills the caches, untimed
            if "warm" in modes:
                measure(label, backend, "warm", cmd, a.warm)
            if "sdfc" in modes:
                measure(label, backend, "sdfc cache", cmd, a.warm, driver_caches=False)
            if "vulkan" in modes and backend == "wgpu":
                # wgpu's instance without its GL backend (EGL): what that backend costs the
                # device's opening.
                measure(label, backend, "Vulkan alone", cmd, a.warm,
                        extra={"WGPU_BACKEND": "vulkan"})

    # Whole processes without --stats, warm (one untimed run of each build first), the builds
    # alternating.
    plain = []
    builds = [("new", a.sdfc)] + ([("old", a.old)] if a.old else [])
    for backend in backends if a.plain else []:
        for f in scenes:
            label = os.path.splitext(os.path.basename(f))[0]
            walls = {name: [] for name, _ in builds}
            for i in range(a.plain + 1):
                for name, binary in builds:
                    cmd = [binary, "render", f, "--backend", backend, "--size", a.size, "-o", image]
                    wall, out, err, code = run(cmd, env())
                    if code != 0:
                        failures.append("plain %s %s %s: exit %d: %s" % (
                            label, backend, name, code, err.strip().splitlines()[-1:]))
                    elif i > 0:
                        walls[name].append(wall * 1e3)
            row = (label, backend, {k: median(v) for k, v in walls.items()},
                   {k: (min(v), max(v)) if v else None for k, v in walls.items()})
            plain.append(row)
            print(json.dumps(row), flush=True)

    scaling = []
    for f in a.scaling:
        label = os.path.splitext(os.path.basename(f))[0] + " marched"
        for backend in backends:
            cmd = [a.sdfc, "render", f, "--backend", backend, "--size", a.size, "--set",
                   "method=march", "--stats", "-o", image]
            empty_caches()
            measure(label, backend, "cold", cmd, 1)
            measure(label, backend, "warm", cmd, a.warm)
            bench = [a.sdfc, "bench", f, "--backend", backend, "--size", a.size, "--set",
                     "method=march", "--frames", str(a.frames), "--json"]
            wall, out, err, code = run(bench, env())
            if code == 0:
                d = json.loads(out)[0]
                scaling.append((label, backend, d["median_s"] * 1e3, d["median_wall_s"] * 1e3,
                                d["stats"]["steps_mean"]))
            else:
                failures.append("bench %s %s: %s" % (label, backend, err.strip().splitlines()[-1:]))

    print()
    print("Whole `sdfc render --size %s --stats` processes, ms (warm and sdfc cache: median of %d):"
          % (a.size, a.warm))
    print("(run: from the process's start to the image written, by --stats; after: wall - run; "
          "device: the wait for it, and its own time on its thread beside the front end)")
    head = (["scene", "backend", "mode", "wall", "run", "after"] + SHOWN[:3] + ["device (own)"]
            + SHOWN[3:] + ["other", "driver compile: how"])
    print("| " + " | ".join(head) + " |")
    print("|" + "---|" * 3 + "---:|" * (len(head) - 4) + "---|")
    for r in rows:
        known = sum(r["phases"][k] or 0 for k in SHOWN)
        other = None if r["total"] is None else r["total"] - known
        cells = [r["label"], r["backend"], r["mode"], fmt(r["wall"]), fmt(r["total"]),
                 fmt(r["after"])]
        cells += [fmt(r["phases"][k]) for k in SHOWN[:3]] + [fmt(r["phases"]["device (own)"])]
        cells += [fmt(r["phases"][k]) for k in SHOWN[3:]] + [fmt(other), r["how"]]
        print("| " + " | ".join(cells) + " |")
    if plain:
        print()
        print("Whole warm `sdfc render --size %s` processes without --stats, wall ms, median of %d "
              "after one untimed run (min-max)%s:" % (
                  a.size, a.plain, ", the builds alternating" if a.old else ""))
        names = [n for n, _ in builds]
        print("| scene | backend | " + " | ".join(names) + " |")
        print("|---|---|" + "---:|" * len(names))
        for label, backend, med, spread in plain:
            cells = ["%s (%s-%s)" % (fmt(med[n]), fmt(spread[n][0]), fmt(spread[n][1]))
                     if spread[n] else "-" for n in names]
            print("| %s | %s | %s |" % (label, backend, " | ".join(cells)))
    for kind, (inside, outside) in bare.items():
        print("bare %s context (python3 + ctypes, median of 3 processes): %.1f ms to create it, "
              "%.1f ms for the whole process" % (kind, inside, outside))
    if scaling:
        print()
        print("Marched scaling scenes, `sdfc bench --size %s --set method=march --frames %d`:"
              % (a.size, a.frames))
        print("| scene | backend | median GPU ms | median wall ms | steps/pixel |")
        print("|---|---|---:|---:|---:|")
        for s in scaling:
            print("| %s | %s | %.2f | %.2f | %.1f |" % s)
    for f in failures:
        print("FAILED: " + f)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
