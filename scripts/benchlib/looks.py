"""Suites of scenes of one feature: analytic tracing against marching, text, a triangle mesh
as a shape, the live preview (`sdfc view --headless`), and the speed-accuracy charts."""

import json
import os
import re
import subprocess
import tempfile
import time

from . import core
from .core import IMG, bench, fmt, ms, ratio, render, scene_name


def analytic(ctx):
    scenes = ctx.scene_list(["examples/seed1.sdf", "examples/seed2.sdf"])
    aas = ctx.opt("aa", ["1", "4", "8"])
    frames = ctx.n_frames(5)
    max_samples = ctx.opt("max_march_samples", 0)
    head = ["scene", "size", "aa", "build"]
    for b in ctx.backends:
        head += ["%s traced" % b, "%s marched" % b, "%s marched / traced" % b]
    t = ctx.table("`sdfc bench SCENE --size S --aa A --frames %d --set method=trace|march`: "
                  "median GPU ms (the CPU: frame ms)%s." % (frames, "; marched renders above "
                                                            "%d samples not run" % max_samples
                                                            if max_samples else ""), head,
                  ["---"] * 4 + ["---:"] * (len(head) - 4))
    for f in scenes:
        for size, _ in ctx.size_list(["1920x1080"]):
            w, h = map(int, size.split("x"))
            for aa in aas:
                for x in ctx.builds:
                    cells = []
                    for b in ctx.backends:
                        v = {}
                        for method in ("trace", "march"):
                            if method == "march" and max_samples and w * h * int(aa) ** 2 > \
                                    max_samples:
                                v[method] = None
                                continue
                            e = bench(x, [f], b, size, aa, frames, ["--set", "method=" + method],
                                      ctx.fails)
                            v[method] = ms(e[0]) if e else None
                        cells += [fmt(v["trace"], 3), fmt(v["march"], 3),
                                  ratio(v["march"], v["trace"])]
                    t.add(scene_name(f), size, aa, x.name, *cells)
    if ctx.opt("check", True):
        size = ctx.size_list(["1920x1080"])[0][0]
        gpus = ctx.gpu_backends()
        pairs = [(b, "cpu") for b in gpus] + [(b, "cpu marched") for b in gpus]
        t = ctx.table("The traced examples at %s: each backend's `sdfc render` against the "
                      "CPU's, traced and marched (`--set method=march`)." % size,
                      ["scene", "build"] + ["%s vs %s" % p for p in pairs], ["---"] *
                      (2 + len(pairs)))
        for f in ctx.opt("check_scenes", ["examples/seed1.sdf", "examples/seed2.sdf",
                                          "examples/primitives.sdf"]):
            for x in ctx.builds:
                p = lambda b: "%s/an-%s-%s-%s.png" % (IMG, x, scene_name(f), b)  # noqa: E731
                for b in ["cpu"] + gpus:
                    render(x, f, b, p(b), size)
                render(x, f, "cpu", p("cpu marched"), size, None, ["--set", "method=march"])
                t.add(scene_name(f), x.name, *[core.agreement(core.compare(x, p(a), p(c)))
                                               for a, c in pairs])


TEXT = """material brass = phong { color: (0.85, 0.65, 0.3), specular: 0.8, shininess: 60 };
material slate = phong { color: (0.18, 0.2, 0.24), specular: 0.3, shininess: 20 };
camera { position: (0, 0.4, -9), look_at: (0, 0, 0), fov: 50deg }
light point { position: (-3, 5, -5), intensity: 1, radius: 40 }
light directional { direction: (1, -1, 1), color: (0.3, 0.3, 0.35) }
scene {
  round_box((6.3, 0.6, 0.1), 0.05).translate(0, 0, 0.15) @ slate;
  extrude(text("%s", 0.5), 0.2, 0.01) @ brass;
}
"""


def text(ctx):
    size = ctx.size_list(["1920x1080"])[0][0]
    frames = ctx.n_frames(20)
    t = ctx.table("examples/plaque.sdf (\"HELLO\"), and a 40-character string and a "
                  "1-character one extruded on a plaque: `sdfc bench --size %s --frames %d` "
                  "median ms (the CPU: 3 frames), and the kernels' sizes (`sdfc compile --emit "
                  "wgsl|ptx|scene-data`)." % (size, frames),
                  ["scene", "build", *["%s ms" % b for b in ctx.backends], "WGSL bytes",
                   "PTX bytes", "scene_data bytes"])
    scenes = [("plaque", "examples/plaque.sdf")]
    for name, s in (("40 characters", "The quick brown fox jumps over a lazy do"),
                    ("1 character", "T")):
        f = "%s/text%d.sdf" % (IMG, len(s))
        open(f, "w").write(TEXT % s)
        scenes.append((name, f))
    for name, f in scenes:
        for x in ctx.builds:
            sizes = []
            for emit in ("wgsl", "ptx"):
                _, out, _, code = core.run([x.path, "compile", f, "--emit", emit])
                sizes.append(str(len(out.encode())) if code == 0 else "-")
            data = "%s/%s-%s.bin" % (IMG, scene_name(f), x.name)
            _, _, _, code = core.run([x.path, "compile", f, "--emit", "scene-data", "-o", data])
            sizes.append(str(os.path.getsize(data)) if code == 0 else "-")
            cells = []
            for b in ctx.backends:
                e = bench(x, [f], b, size, None, 3 if b == "cpu" else frames, (), ctx.fails)
                cells.append(ms(e[0]) if e else None)
            t.add(name, x.name, *cells, *sizes)


MESH_SCENE = """material steel = phong { color: (0.62, 0.64, 0.7), specular: 0.6, shininess: 64 };
material floor = checker { a: (0.85, 0.85, 0.85), b: (0.55, 0.55, 0.55), size: 0.25 };
camera { position: (1.8, 1.5, -2.4), look_at: (0, 0.1, 0), fov: 45deg }
light point { position: (-2, 4, -3), intensity: 1.1%s }
render { width: 1920, height: 1080, max_depth: 0 }
scene {
  %s @ steel;
  plane((0, 1, 0), -0.42) @ floor;
}
"""


def mesh_import(ctx):
    res = ctx.opt("resolution", 104)
    work = core.fresh("/tmp/sdfc-meshimport")
    _, out, err, code = core.run([ctx.new.path, "mesh", "examples/mesh/bracket.sdf",
                                  "--resolution", res, "-o", work + "/big.stl"])
    if code:
        raise core.Skip("sdfc mesh failed: %s" % core.last_line(err))
    tris = re.search(r"([0-9]+) triangles", out + err)
    # The light's penumbra (0: a hard light, which lets the mesh as read be traced), and the
    # mesh as read or rounded and shelled (shell=1, marched).
    penumbra = ctx.opt("penumbra", "3deg")
    light = "" if penumbra in ("0", "0deg") else ", penumbra: " + penumbra
    big = 'mesh("big.stl")' + (".round(0.02).shell(0.03)" if ctx.opt("shell", False) else "")
    for name, shape in (("scene", big), ("box", "box((0.8, 0.3, 0.45))")):
        open("%s/%s.sdf" % (work, name), "w").write(MESH_SCENE % (light, shape))
    scene = work + "/scene.sdf"
    size = ctx.size_list(["1920x1080"])[0][0]
    frames = ctx.n_frames(5)
    t = ctx.table("The bracket meshed by `sdfc mesh --resolution %d` (%s triangles, %d KiB STL) "
                  "read back with `mesh(...)`%s beside a floor and a light of penumbra %s: *load*: "
                  "`sdfc check`, best of 3, s (the same scene with a box); *frame*: `sdfc bench "
                  "--size %s --frames %d`, median GPU ms; *agreement*: at 640x480 against the "
                  "CPU." % (res, tris.group(1) if tris else "?", os.path.getsize(
                      work + "/big.stl") // 1024, big[len('mesh("big.stl")'):], penumbra,
                      size, frames),
                  ["build", "load s", "box s"] + ["%s frame" % b for b in ctx.backends] +
                  ["%s vs cpu" % b for b in ctx.gpu_backends()])
    for x in ctx.builds:
        load = [min(core.run([x.path, "check", "%s/%s.sdf" % (work, n)])[0] for _ in range(3))
                for n in ("scene", "box")]
        frames_ms = []
        for b in ctx.backends:
            e = bench(x, [scene], b, size if b != "cpu" else "480x270", None,
                      frames if b != "cpu" else 1, (), ctx.fails)
            frames_ms.append(ms(e[0]) if e else None)
        p = lambda b: "%s/mi-%s-%s.png" % (IMG, x, b)  # noqa: E731
        for b in ["cpu"] + ctx.gpu_backends():
            render(x, scene, b, p(b), "640x480")
        t.add(x.name, fmt(load[0], 3), fmt(load[1], 3), *frames_ms,
              *[core.agreement(core.compare(x, p(b), p("cpu"))) for b in ctx.gpu_backends()])


def pareto(ctx):
    sweeps = ctx.opt("sweeps", "epsilon=1e-2..1e-6 max_steps=32..1024 relaxation=1..1.8")
    size = ctx.size_list(["640x480"])[0][0]
    frames = ctx.n_frames(5)
    t = ctx.table("`sdfc pareto examples/seedN.sdf --size %s --frames %d --sweep %s`: where "
                  "the defaults stand; the charts in $OUT (pareto-gpu-seedN.svg through CUDA, "
                  "pareto-wgpu-seedN.svg through wgpu)." % (
                      size, frames, " --sweep ".join(sweeps.split())),
                  ["scene", "backend", "PSNR dB", "steps/px", "ms", "time front",
                   "steps front"])
    for i in ctx.opt("scenes", ["1", "2", "3", "4", "5", "6"]):
        for b in ctx.backends:
            cmd = [ctx.new.path, "pareto", "examples/seed%s.sdf" % i, "--backend", b, "--size",
                   size, "--frames", frames, "-o", "%s/pareto-%s-seed%s.svg" % (
                       ctx.out, "gpu" if b == "cuda" else b, i),
                   "--json"]
            for s in sweeps.split():
                cmd += ["--sweep", s]
            if i == "6":
                cmd += ["--limit", "memory=12000"]
            _, out, err, code = core.run(cmd)
            open("%s/pareto-%s-seed%s.json" % (ctx.out, b, i), "w").write(out)
            try:
                p = [x for x in json.loads(out)["points"] if x["default"]][0]
            except (ValueError, IndexError, KeyError):
                ctx.fails.note("pareto seed%s %s" % (i, b), err)
                continue
            t.add("seed" + i, b, p["psnr"], fmt(p["steps_mean"], 1), fmt(1e3 * p["median_s"], 3),
                  str(p["front_time"]), str(p["front_steps"]))


def _edit(path, how):
    """Saves an edit as editors do: a new file renamed over the old."""
    t = open(path).read()
    if how == "numeric":
        u = re.sub(r"intensity: *([0-9.]+)", lambda m: "intensity: %g" % (
            float(m.group(1)) * 0.9), t, count=1)
    elif how == "structural":
        u = t.replace("scene {", "scene {\n  sphere(0.01).translate(0, 1000, 0);", 1)
    else:
        u = re.sub(r"sphere\(([0-9.]+)\)(?!\.translate\(0, 1000)", lambda m: "sphere(%g)" % (
            float(m.group(1)) * 1.1), t, count=1)
        if u == t:
            return _edit(path, "numeric")
    open(path + ".new", "w").write(u)
    os.replace(path + ".new", path)


def _wait_for(path, proc, limit=60):
    end = time.time() + limit
    while not os.path.exists(path):
        if proc.poll() is not None or time.time() > end:
            return False
        time.sleep(0.005)
    return True


def view(ctx):
    backend = (ctx.gpu_backends() or ["wgpu"])[0]
    size = ctx.size_list(["1920x1080"])[0][0]
    kernel = ctx.opt("kernel", "auto")
    scenes = ctx.scene_list(core.examples())
    t = ctx.table(
        "`sdfc view SCENE --headless --backend %s --kernel %s --size %s --timings`: three edits "
        "saved one after the other, each once the one before converged (a light's intensity, "
        "one more shape, a sphere's radius): edit to pixel, ms (the load's timings line in the "
        "JSON); the kernel of the structural edit's first frame." % (backend, kernel, size),
        ["scene", "build", "numeric", "structural", "radius", "structural's kernel"],
        ["---", "---", "---:", "---:", "---:", "---"])
    for f in scenes:
        for x in ctx.builds:
            d = tempfile.mkdtemp()
            subprocess.run(["cp", "-r", os.path.dirname(f) + "/.", d])
            s = os.path.join(d, os.path.basename(f))
            log = open(d + "/log", "w")
            p = subprocess.Popen([x.path, "view", s, "--headless", "--backend", backend,
                                  "--kernel", kernel, "--size", size, "--timings",
                                  "--screenshot-dir", d + "/shots", "--exit-after-reloads", "3"],
                                 stdout=log, stderr=subprocess.STDOUT)
            ok = _wait_for(d + "/shots/reload-0.png", p)
            for i, how in enumerate(("numeric", "structural", "radius")):
                if ok:
                    _edit(s, how)
                    ok = _wait_for(d + "/shots/reload-%d.png" % (i + 1), p)
            if not ok:
                p.kill()
                ctx.fails.append("view %s %s: an edit did not arrive" % (x, scene_name(f)))
            p.wait()
            text = open(d + "/log").read()
            lines = [ln for ln in text.splitlines() if "timings" in ln or "kernel ready" in ln]
            ctx.data.setdefault(scene_name(f), {})[x.name] = lines
            cells = []
            for k in (1, 2, 3):
                m = re.search(r"load %d timings.*?edit to pixel ([0-9.]+) ms" % k, text)
                cells.append(fmt(float(m.group(1)), 1) if m else "-")
            m = re.search(r"load 2 timings.*?first frame [0-9.]+ ms \([0-9]+x[0-9]+, ([a-z]+)",
                          text)
            t.add(scene_name(f), x.name, *cells, m.group(1) if m else "-")
            subprocess.run(["rm", "-rf", d])
    orbit = ctx.opt("orbit", ["seed1", "seed2", "seed3", "seed4", "seed5", "seed6", "temple"])
    t = ctx.table("`sdfc view examples/SCENE.sdf --headless --size %s --orbit-frames %d`: the "
                  "orbit's line." % (size, ctx.opt("orbit_frames", 120)),
                  ["scene", "build", "orbit"], ["---", "---", "---"])
    for n in orbit:
        for x in ctx.builds:
            d = tempfile.mkdtemp()
            _, out, err, code = core.run([x.path, "view", "examples/%s.sdf" % n, "--headless",
                                          "--backend", backend, "--size", size, "--orbit-frames",
                                          ctx.opt("orbit_frames", 120), "--screenshot-dir", d,
                                          "--exit-after-reloads", "0"], timeout=120)
            lines = [ln.strip().replace("view: orbit: ", "") for ln in (out + err).splitlines()
                     if "orbit" in ln]
            t.add(n, x.name, "; ".join(lines) or "failed")
            subprocess.run(["rm", "-rf", d])


SUITES = {
    "analytic": (analytic, "seeds 1 and 2 traced against marched at aa 1, 4, 8, and the traced "
                 "examples' agreement; --with aa=1,4,8, max_march_samples=N, check=0"),
    "text": (text, "examples/plaque.sdf, a 40-character and a 1-character extruded string: "
                   "frame ms, kernel sizes"),
    "mesh-import": (mesh_import, "a 100 000-triangle mesh(path) scene: load, 1080p frame, "
                    "agreement; --with resolution=104, penumbra=3deg (0: hard, traced), shell=0"),
    "view": (view, "sdfc view --headless: edit to pixel of numeric, structural and radius "
             "edits, orbit frames/s; --with kernel=auto, orbit=seed1,..."),
    "pareto": (pareto, "docs/accuracy.md's speed-accuracy charts on the GPU backends; --with "
               "scenes=3, sweeps=..."),
}
