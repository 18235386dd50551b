"""Suites of kernels: the interpreted kernel against the specialised one, compile times cold
and warm, the pictures of the backends against each other (`agree`, `ptx`), the distance
conformance suite on the device, and sequences (`anim`)."""

import os
import re

from . import core
from .core import IMG, bench, fmt, ms, ratio, render, scene_name

def _caches(folder, cold):
    """An environment whose compile caches (sdfc's, CUDA's JIT, the NVIDIA shader disk cache)
    are in `folder`, emptied when `cold`."""
    if cold:
        core.fresh(folder)
    env = dict(os.environ)
    for k, sub in (("SDFC_CACHE_DIR", "sdfc"), ("CUDA_CACHE_PATH", "cuda"),
                   ("__GL_SHADER_DISK_CACHE_PATH", "gl")):
        env[k] = os.path.join(folder, sub)
        os.makedirs(env[k], exist_ok=True)
    env["__GL_SHADER_DISK_CACHE"], env["__GL_SHADER_DISK_CACHE_SKIP_CLEANUP"] = "1", "1"
    return env


def instructions(build, f):
    _, out, _, _ = core.run([build.path, "compile", f, "--emit", "program"])
    m = re.search(r"distance program: ([0-9]+) instructions", out)
    return int(m.group(1)) if m else None


def interp(ctx):
    scenes = ctx.scene_list(core.examples() + [
        "examples/scaling/compound_100.sdf", "examples/scaling/lattice_1000.sdf",
        "examples/scaling/random_1000.sdf"])
    size = ctx.size_list(["1920x1080"])[0][0]
    frames, limit = ctx.n_frames(5), ctx.opt("limit", 300)
    t = ctx.table(
        "Marched (`--set method=march`). *ready*: a whole `sdfc render --kernel K --size "
        "64x64`, s, cold (every compile cache empty) / warm; *frame*: `sdfc bench --kernel K "
        "--size %s --frames %d`, median GPU ms. TIME: over %d s; WRONG: another kernel ran." % (
            size, frames, limit),
        ["scene", "backend", "build", "instructions", "spec. ready", "interp. ready",
         "spec. frame", "interp. frame", "interp. / spec."], ["---"] * 3 + ["---:"] * 6)
    march = ["--set", "method=march"]
    for f in scenes:
        n = scene_name(f)
        for b in ctx.gpu_backends() or ctx.backends:
            for x in ctx.builds:
                ready = {}
                for k in ("specialised", "interpreted"):
                    got = []
                    for state in ("cold", "warm"):
                        env = _caches("/tmp/sdfc-interp-cache/%s-%s-%s-%s" % (x, n, b, k),
                                      state == "cold")
                        wall, log, code = render(x, f, b, "%s/interp.png" % IMG, "64x64", None,
                                                 march + ["--kernel", k, "--stats"], env,
                                                 timeout=limit)
                        got.append("TIME" if code == 124 else "FAIL" if code else
                                   "WRONG" if not re.search(r"^kernel +%s" % k, log, re.M)
                                   and b != "cpu" else fmt(wall))
                    ready[k] = " / ".join(got)
                frame = {}
                for k in ("specialised", "interpreted"):
                    e = bench(x, [f], b, size, None, frames, march + ["--kernel", k], ctx.fails,
                              timeout=limit, env=_caches("/tmp/sdfc-interp-cache/bench", False))
                    e = e[0] if e else None
                    frame[k] = None if not e or (b != "cpu" and e.get("kernel") != k) else ms(e)
                t.add(n, b, x.name, str(instructions(x, f)), ready["specialised"],
                      ready["interpreted"], frame["specialised"], frame["interpreted"],
                      ratio(frame["interpreted"], frame["specialised"]))


def compile_times(ctx):
    scenes = ctx.scene_list(core.examples())
    runs = ctx.n_runs(2)
    t = ctx.table(
        "`sdfc render FILE --backend B --size 64x48 --stats`: cold (sdfc's cache emptied, "
        "CUDA_CACHE_DISABLE=1 and __GL_SHADER_DISK_CACHE=0), %d runs, then warm (sdfc's cache "
        "filled), ms of the phases *kernel* (the kernel's text), *PTX* and *driver compile*." %
        runs, ["scene", "backend", "build", "kernel cold", "PTX cold", "driver compile cold",
               "driver compile warm", "warm: how"], ["---"] * 3 + ["---:"] * 4 + ["---"])
    for f in scenes:
        for b in ctx.gpu_backends() or ctx.backends:
            for x in ctx.builds:
                cold = []
                for _ in range(runs):
                    env = _caches("/tmp/sdfc-compile-cache", True)
                    env["CUDA_CACHE_DISABLE"], env["__GL_SHADER_DISK_CACHE"] = "1", "0"
                    _, log, code = render(x, f, b, IMG + "/jit.png", "64x48", None, ["--stats"],
                                          env)
                    cold.append(core.stats(log))
                env = _caches("/tmp/sdfc-compile-cache", False)
                _, log, code = render(x, f, b, IMG + "/jit.png", "64x48", None, ["--stats"], env)
                warm = core.stats(log)
                col = lambda k: ", ".join(fmt(s.get(k), 1) for s in cold)  # noqa: E731
                t.add(scene_name(f), b, x.name, col("kernel"), col("PTX"), col("driver compile"),
                      fmt(warm.get("driver compile"), 1), warm.get("driver compile how", ""))


def agree(ctx):
    scenes = ctx.scene_list(core.examples())
    backends = ctx.backends if "cpu" in ctx.backends else ["cpu"] + ctx.backends
    gpus = [b for b in backends if b != "cpu"]
    pairs = [(b, "cpu") for b in gpus] + [(gpus[i], gpus[j]) for i in range(len(gpus))
                                          for j in range(i + 1, len(gpus))]
    for size, aa in ctx.size_list(["1920x1080"]):
        t = ctx.table("`sdfc render FILE --backend B --size %s%s` of each backend compared "
                      "(`sdfc compare`): PSNR, pixels differing by more than 0.1 in a channel." %
                      (size, " --aa %d" % aa if aa else ""),
                      ["scene", "build"] + ["%s vs %s" % p for p in pairs], ["---"] *
                      (2 + len(pairs)))
        for f in scenes:
            for x in ctx.builds:
                paths = {}
                for b in backends:
                    paths[b] = "%s/agree-%s-%s-%s.png" % (IMG, x, scene_name(f), b)
                    _, log, code = render(x, f, b, paths[b], size, aa, ["--limit",
                                                                         "memory=16384"],
                                          timeout=ctx.opt("timeout", 600))
                    if code:
                        ctx.fails.note("%s %s %s" % (x, scene_name(f), b), log)
                cells = [core.agreement(core.compare(x, paths[a], paths[c])) for a, c in pairs]
                t.add(scene_name(f), x.name, *cells)


def ptx(ctx):
    scenes = ctx.scene_list(core.examples() + [
        "examples/scaling/%s.sdf" % n for n in ("compound_100", "lattice_100", "random_100",
                                                "compound_1000", "random_1000")])
    backends = ctx.gpu_backends() if len(ctx.gpu_backends()) == 2 else ctx.backends[:2]
    size = ctx.size_list(["960x540"])[0][0]
    min_psnr, max_diff = ctx.opt("min_psnr", 40.0), ctx.opt("max_differing", 0.005)
    a, b = backends
    t = ctx.table("`sdfc render FILE --size %s` through %s and %s, compared; DISAGREE below "
                  "%.0f dB or above %.1f %% of pixels differing (the PTX is translated from the "
                  "validated WGSL: only the drivers' code generation differs)." % (
                      size, a, b, min_psnr, 100 * max_diff),
                  ["scene", "build", "PSNR dB", "differing %", "%s s" % a, "%s s" % b, ""],
                  ["---", "---"] + ["---:"] * 4 + ["---"])
    for f in scenes:
        for x in ctx.builds:
            paths, secs = [], []
            for be in backends:
                p = "%s/ptx-%s-%s-%s.png" % (IMG, x, scene_name(f), be)
                wall, log, code = render(x, f, be, p, size)
                if code:
                    ctx.fails.note("%s %s %s" % (x, scene_name(f), be), log)
                paths.append(p)
                secs.append(wall)
            c = core.compare(x, *paths)
            bad = not c or (c["psnr"] is not None and c["psnr"] < min_psnr) or (
                c["differing"] > max_diff)
            if bad:
                ctx.fails.append("%s %s: %s and %s disagree" % (x, scene_name(f), a, b))
            t.add(scene_name(f), x.name, "inf" if c and c["psnr"] is None else
                  fmt(c and c["psnr"], 1), fmt(c and 100 * c["differing"], 4), *secs,
                  "DISAGREE" if bad else "")
    repeat = ctx.opt("repeat", 10)
    if repeat and "wgpu" in ctx.backends:
        t = ctx.table("`sdfc render examples/lattice.sdf --backend wgpu`, %d processes: the "
                      "exits that were not clean." % repeat, ["build", "exit codes", "not clean"])
        for x in ctx.builds:
            codes = [render(x, "examples/lattice.sdf", "wgpu", IMG + "/lattice.png")[2]
                     for _ in range(repeat)]
            bad = sum(1 for c in codes if c)
            if bad:
                ctx.fails.append("%s: lattice through wgpu exited uncleanly %d times" % (x, bad))
            t.add(x.name, " ".join(map(str, codes)), str(bad))


def conformance(ctx):
    test = os.path.abspath(ctx.opt("binary", ".dev/distance_conformance"))
    if not os.path.exists(test):
        raise core.Skip(
            "no test binary at %s: `cargo test --release -p sdfc-runtime --test "
            "distance_conformance --no-run`, copied from target/release/deps/" % test)
    os.chmod(test, 0o755)
    env = dict(os.environ, SDFC_REQUIRE_CUDA="1" if "cuda" in ctx.backends else "0")
    wall, out, err, code = _in_runtime(test, env)
    open(os.path.join(ctx.out, "distance-conformance.txt"), "w").write(out + err)
    t = ctx.table("The distance conformance suite (runtime/tests, %s) on this machine's devices "
                  "(SDFC_REQUIRE_CUDA=1 with cuda): its report's lines of worst ulps." %
                  os.path.basename(test), ["line"], ["---"])
    for line in (out + err).splitlines():
        if "ulp" in line or line.startswith("test result"):
            t.add(line.strip().replace("|", "/"))
    if code:
        ctx.fails.append("the conformance suite failed (exit %d)" % code)


def _in_runtime(test, env):
    """Runs the test binary from runtime/, as cargo runs it (it reads runtime/tests/in)."""
    cwd = os.getcwd()
    os.chdir("runtime")
    try:
        return core.run([test, "--nocapture", "--test-threads", "1"], env=env)
    finally:
        os.chdir(cwd)


ANIMATED = ["examples/animation/orbit.sdf", "examples/animation/bounce.sdf"]


def anim(ctx):
    parts = ctx.opt("parts", ["fps", "agree", "cost"])
    size = ctx.size_list(["1920x1080"])[0][0]
    if "fps" in parts:
        seq = ctx.opt("sequence", "0..60")
        t = ctx.table(
            "`sdfc bench --frames-per-second --constants C --size %s --sequence %s SCENE`: every "
            "frame checked, lowered, prepared again only when its program changed, rendered "
            "(the first untimed); frames/s and ms a frame of each step." % (size, seq),
            ["scene", "backend", "constants", "build", "frames/s", "kernels", "check ms",
             "prepare ms", "render ms"], ["---"] * 4 + ["---:"] * 5)
        for b in ctx.backends:
            for c in ("parameters", "literal"):
                for x in ctx.builds:
                    for e in bench(x, ANIMATED, b, size, None, 1, ["--frames-per-second",
                                                                  "--constants", c,
                                                                  "--sequence", seq], ctx.fails):
                        n = e["timed"] or 1
                        t.add(scene_name(e["scene"]), b, c, x.name, e["frames_per_s"],
                              str(e["kernels"]), 1e3 * e["check_s"] / n,
                              1e3 * e["prepare_s"] / n, 1e3 * e["render_s"] / n)
    if "agree" in parts:
        asize = ctx.opt("agree_size", "640x480")
        gpus = ctx.gpu_backends()
        t = ctx.table("`sdfc render SCENE --size %s --frames 0..8`: the worst PSNR over the "
                      "frames against the CPU's." % asize, ["scene", "build"] + gpus,
                      ["---"] * (2 + len(gpus)))
        for f in ANIMATED:
            for x in ctx.builds:
                dirs = {}
                for b in ["cpu"] + gpus:
                    dirs[b] = core.fresh("%s/anim-%s-%s-%s" % (IMG, x, scene_name(f), b))
                    render(x, f, b, dirs[b] + "/f_##.png", asize, None, ["--frames", "0..8",
                                                                        "--force"])
                cells = []
                for b in gpus:
                    ps = [core.compare(x, "%s/f_%02d.png" % (dirs[b], k),
                                       "%s/f_%02d.png" % (dirs["cpu"], k)) for k in range(8)]
                    vals = [float("inf") if p and p["psnr"] is None else p["psnr"] if p else 0
                            for p in ps]
                    cells.append("%.1f dB" % min(vals))
                t.add(scene_name(f), x.name, *cells)
    if "cost" in parts:
        frames = ctx.n_frames(5)
        stills = ctx.scene_list(["examples/seed%d.sdf" % i for i in range(1, 7)] + [
            "examples/temple.sdf", "examples/lattice.sdf", "examples/blends.sdf"])
        head = ["scene", "build"]
        for b in ctx.backends:
            head += ["%s literal" % b, "%s parameters" % b]
        t = ctx.table("`sdfc bench SCENE --size %s --frames %d --set method=march --constants "
                      "literal|parameters`: median GPU ms, the distance program's constants "
                      "written as literals or read from the kernel's buffer." % (size, frames),
                      head)
        for f in stills:
            for x in ctx.builds:
                cells = []
                for b in ctx.backends:
                    for c in ("literal", "parameters"):
                        e = bench(x, [f], b, size, None, frames, ["--set", "method=march",
                                                                  "--constants", c], ctx.fails)
                        cells.append(ms(e[0]) if e else None)
                t.add(scene_name(f), x.name, *[fmt(v, 3) for v in cells])


SUITES = {
    "interp": (interp, "interpreted against specialised kernel, marched: cold/warm ready "
               "time and 1080p frame; --with limit=300"),
    "compile": (compile_times, "kernel, PTX and driver compile ms cold and warm, every example"),
    "agree": (agree, "each example rendered by the CPU and each GPU backend, compared "
              "(PSNR, differing pixels); --size, --scenes"),
    "ptx": (ptx, "PTX (CUDA) against WGSL (wgpu) images of every example and scaling scenes, "
            "failing on disagreement; lattice through wgpu repeated; --with repeat=10"),
    "conformance": (conformance, "the distance conformance test binary (.dev/"
                    "distance_conformance) on the device; --with binary=PATH"),
    "anim": (anim, "sequences: frames/s with constants as parameters or literals, frames "
             "against the CPU, the cost of constants from the buffer; --with parts=, sequence="),
}
