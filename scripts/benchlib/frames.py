"""Suites of frames and whole renders: the examples' GPU frames, the scaling scenes, the
render path of one GPU (where a frame's time goes on the host, a sequence's frames/s, the
first picture), and several devices."""

import os

from . import core, first
from .core import IMG, bench, fmt, ms, ratio, render, scene_name

SCALING_MARCHED = ["compound_100", "compound_1000", "lattice_1000", "random_1000",
                   "random_10000", "jittered_1024"]
ORBIT = "examples/animation/orbit.sdf"
BIG = ["--limit", "memory=65536"]


def _scenes_with_settings(ctx):
    """The examples suite's scenes: (label, file, extra arguments)."""
    if ctx.scenes:
        return [(scene_name(f), f, []) for f in ctx.scenes]
    rows = [(scene_name(f), f, []) for f in core.examples()]
    if ctx.opt("scaling", True):
        rows += [(n + " marched", "examples/scaling/%s.sdf" % n, ["--set", "method=march"])
                 for n in SCALING_MARCHED]
        rows.append(("jittered_1024 traced", "examples/scaling/jittered_1024.sdf", []))
    return rows


def examples(ctx):
    frames = ctx.n_frames(21)
    backends = ctx.backends
    for size, aa in ctx.size_list(["1920x1080"]):
        head = ["scene"]
        for b in backends:
            head += ["%s %s" % (b, x.name) for x in ctx.builds]
            if ctx.side_by_side:
                head.append("%s new / old" % b)
        if len(backends) == 2 and not ctx.side_by_side:
            head.append("%s / %s" % (backends[1], backends[0]))
        head += ["%s wall − GPU" % b for b in backends if b != "cpu"]
        head += ["steps/px"]
        t = ctx.table(
            "`sdfc bench FILE --backend B --size %s%s --frames %d`: median GPU ms (the CPU: "
            "median frame ms); *wall − GPU*: median wall less median GPU time, new build; "
            "steps/px: the new build's first backend." % (
                size, " --aa %d" % aa if aa else "", frames), head)
        for label, f, extra in _scenes_with_settings(ctx):
            cells, walls, steps = [label], [], None
            news = {}
            for b in backends:
                got = {}
                for x in ctx.builds:
                    e = bench(x, [f], b, size, aa, frames, extra, ctx.fails)
                    got[x.name] = e[0] if e else None
                    ctx.data.setdefault(label, {}).setdefault("%s %s %s" % (b, size, aa or 1),
                                                              {})[x.name] = got[x.name]
                cells += [ms(got[x.name]) for x in ctx.builds]
                if ctx.side_by_side:
                    cells.append(ratio(ms(got["new"]), ms(got["old"])))
                news[b] = got["new"]
                if steps is None and got["new"]:
                    steps = got["new"]["stats"]["steps_mean"]
            if len(backends) == 2 and not ctx.side_by_side:
                cells.append(ratio(ms(news[backends[1]]), ms(news[backends[0]])))
            for b in backends:
                if b != "cpu":
                    w, g = ms(news[b], "median_wall_s"), ms(news[b])
                    walls.append(None if w is None or g is None else w - g)
            t.add(*cells, *[fmt(w, 3) for w in walls], fmt(steps, 1))


def scaling(ctx):
    kinds = ctx.opt("kinds", ["random", "lattice", "compound"])
    counts = ctx.opt("n", ["10", "100", "1000", "10000"])
    march_max = ctx.opt("march_max", 1000)
    frames = ctx.n_frames(5)
    for size, aa in ctx.size_list(["1920x1080"]):
        head = ["scene"]
        for b in ctx.backends:
            for x in ctx.builds:
                suffix = " " + x.name if ctx.side_by_side else ""
                head += ["%s marched%s" % (b, suffix), "%s traced%s" % (b, suffix)]
        t = ctx.table(
            "`sdfc bench examples/scaling/KIND_N.sdf --backend B --size %s --frames %d --set "
            "method=march|trace`: median GPU ms (the CPU: frame ms); marched up to %d objects, "
            "compound scenes never traced (a torus)." % (size, frames, march_max), head)
        for kind in kinds:
            for n in counts:
                f = "examples/scaling/%s_%s.sdf" % (kind, n)
                if not os.path.exists(f):
                    continue
                cells = ["%s_%s" % (kind, n)]
                for b in ctx.backends:
                    for x in ctx.builds:
                        for method in ("march", "trace"):
                            if (method == "march" and int(n) > march_max) or (
                                    method == "trace" and kind == "compound"):
                                cells.append("-")
                                continue
                            e = bench(x, [f], b, size, aa, frames, ["--set", "method=" + method],
                                      ctx.fails, timeout=ctx.opt("timeout", 300))
                            cells.append(ms(e[0]) if e else "failed")
                t.add(*cells)


def _phases(log):
    s = core.stats(log)
    return [s.get(k) for k in ("upload", "frame", "readback", "conversion", "sRGB", "PNG",
                               "run")]


def render_path(ctx):
    scenes = ctx.scene_list(["examples/seed3.sdf"])
    sizes = ctx.size_list(["1920x1080", "7680x4320:2"])
    gpus = ctx.gpu_backends() or ctx.backends
    dev = lambda b: ["--devices", "0"] if b != "cpu" else []  # noqa: E731
    # Warm: kernels compiled and cached (the CUDA JIT's cache, the driver's pipeline cache).
    for b in gpus:
        for x in ctx.builds:
            for size, aa in sizes:
                render(x, scenes[0], b, IMG + "/warm.png", size, aa, BIG + dev(b))
    t = ctx.table(
        "`sdfc bench SCENE --devices 0 --frames N` (N = %d, or %d above 1080p): median ms; "
        "*GPU* the launches' device time, *host* the render's call until its pixels are in "
        "host memory (`median_frame_s`)." % (ctx.n_frames(20), ctx.n_frames(5)),
        ["scene", "backend", "size", "build", "GPU", "host", "host / GPU"],
        ["---", "---", "---", "---", "---:", "---:", "---:"])
    for f in scenes:
        for b in gpus:
            for size, aa in sizes:
                n = ctx.n_frames(20 if size == "1920x1080" or aa is None else 5)
                for x in ctx.builds:
                    e = bench(x, [f], b, size, aa, n, BIG + dev(b), ctx.fails)
                    e = e[0] if e else None
                    label = size + (" aa %d" % aa if aa else "")
                    t.add(scene_name(f), b, label, x.name, ms(e), ms(e, "median_frame_s"),
                          ratio(ms(e, "median_frame_s"), ms(e)))
    t = ctx.table(
        "`sdfc render SCENE --devices 0 --stats` (a process's first frame), ms of its phases; "
        "*run*: from the process's start to the image written.",
        ["scene", "backend", "size", "build", "upload", "frame", "readback", "conversion",
         "sRGB", "PNG", "run"], ["---"] * 4 + ["---:"] * 7)
    for f in scenes:
        for b in gpus:
            for size, aa in sizes:
                for x in ctx.builds:
                    _, log, code = render(x, f, b, IMG + "/path.png", size, aa,
                                          BIG + dev(b) + ["--stats"])
                    if code:
                        ctx.fails.note("render --stats %s %s %s" % (x, b, size), log)
                    t.add(scene_name(f), b, size + (" aa %d" % aa if aa else ""), x.name,
                          *[fmt(v, 1) for v in _phases(log)])
    count = ctx.opt("count", 120)
    seq_size = ctx.opt("sequence_size", "1920x1080")
    runs = ctx.n_runs(2)
    t = ctx.table(
        "`sdfc render %s --devices 0 --size %s --frames 0..%d --force -o DIR/f_###.png`: "
        "frames/s of the whole process, %d runs; *same*: the frames byte for byte the new "
        "build's." % (ORBIT, seq_size, count, runs),
        ["backend", "build", "frames/s", "same"], ["---", "---", "---:", "---"])
    for b in gpus:
        got = {x.name: [] for x in ctx.builds}
        for r in range(runs):
            for x in ctx.builds:
                d = core.fresh("%s/seq-%s-%s" % (IMG, x.name, b))
                _, log, code = render(x, ORBIT, b, d + "/f_###.png", seq_size, None,
                                      dev(b) + ["--frames", "0..%d" % count, "--force"])
                got[x.name].append(core.fps(log))
        for x in ctx.builds:
            same = core.same_files("%s/seq-new-%s" % (IMG, b), "%s/seq-%s-%s" % (IMG, x.name, b))
            t.add(b, x.name, ", ".join(fmt(v, 1) for v in got[x.name]),
                  "yes" if same else "NO")
    if ctx.side_by_side:
        t = ctx.table("PNGs of the two builds byte for byte (`sdfc render` at each size).",
                      ["backend", "identical", "differ"], ["---", "---:", "---"])
        stills = ctx.opt("same", ["seed1", "seed2", "seed3", "seed4", "seed5", "seed6"])
        for b in gpus:
            same, differ = 0, []
            for s in stills:
                for size, aa in sizes[:1]:
                    paths = []
                    for x in ctx.builds:
                        p = "%s/same-%s-%s-%s.png" % (IMG, x.name, b, s)
                        render(x, "examples/%s.sdf" % s, b, p, size, aa, BIG + dev(b))
                        paths.append(p)
                    if core.same_files(*paths):
                        same += 1
                    else:
                        differ.append(s)
            t.add(b, "%d of %d" % (same, len(stills)), " ".join(differ) or "-")
    first.first_picture(ctx, gpus, scenes[0])


def devices(ctx, parts=None):
    parts = parts or ctx.opt("parts", ["still", "sequence", "same", "first", "cpu"])
    gpus = ctx.gpu_backends()
    if not gpus:
        raise core.Skip("the devices suite needs a GPU backend")
    n = core.gpu_count()
    # Lists are separated by spaces (`--with "lists=0 0,1"`): a list is comma-separated.
    lists = (ctx.options.get("lists") or "").split() or (
        ["0"] + (["0,1"] if n >= 2 else ["0,0"]) + (["0,1,2,3"] if n >= 4 else []))
    scenes = ctx.scene_list(["examples/seed3.sdf", "examples/seed6.sdf", "examples/temple.sdf"])
    if "still" in parts:
        size, aa = ctx.size_list(["7680x4320:2"])[0]
        frames = ctx.n_frames(5)
        t = ctx.table(
            "`sdfc bench SCENE --devices LIST --size %s%s --frames %d %s`: median whole frame "
            "(host) ms, %d runs (their medians' median); speed-up over the first list." % (
                size, " --aa %d" % aa if aa else "", frames, " ".join(BIG), ctx.n_runs(1)),
            ["backend", "scene", "build"] + ["[%s]" % d for d in lists] +
            ["speed-up [%s]" % d for d in lists[1:]], ["---"] * 3 + ["---:"] * (2 * len(lists) - 1))
        for b in gpus:
            for f in scenes:
                for x in ctx.builds:
                    vals = []
                    for d in lists:
                        runs = []
                        for r in range(ctx.n_runs(1)):
                            e = bench(x, [f], b, size, aa, frames, BIG + ["--devices", d],
                                      ctx.fails)
                            runs.append(ms(e[0], "median_frame_s") if e else None)
                            if e:
                                ctx.data.setdefault("still", []).append(
                                    {"build": x.name, "backend": b, "scene": f, "devices": d,
                                     "entry": e[0]})
                        vals.append(core.median(runs))
                    t.add(b, scene_name(f), x.name, *[fmt(v, 1) for v in vals],
                          *[ratio(vals[0], v) + "×" for v in vals[1:]])
    if "sequence" in parts:
        size = ctx.opt("sequence_size", "1920x1080")
        for count in ctx.opt("counts", ["120", "480"]):
            t = ctx.table(
                "`sdfc render %s --devices LIST --size %s --frames 0..%s --force --stats -o "
                "DIR/f_###.png`: frames/s of the whole process; *same*: every list's frames "
                "byte for byte the first build's on the first list." % (ORBIT, size, count),
                ["backend", "build"] + ["[%s]" % d for d in lists] + ["same"],
                ["---", "---"] + ["---:"] * len(lists) + ["---"])
            for b in gpus:
                for x in ctx.builds:
                    vals, same = [], True
                    for d in lists:
                        dd = core.fresh("%s/dseq-%s-%s-%s" % (IMG, x.name, b, d))
                        _, log, code = render(x, ORBIT, b, dd + "/f_###.png", size, None,
                                              ["--devices", d, "--frames", "0..%s" % count,
                                               "--force", "--stats"])
                        if code:
                            ctx.fails.note("sequence %s %s [%s]" % (x, b, d), log)
                        vals.append(core.fps(log))
                        same &= core.same_files("%s/dseq-new-%s-%s" % (IMG, b, lists[0]), dd)
                    t.add(b, x.name, *[fmt(v, 1) for v in vals], "yes" if same else "NO")
    if "same" in parts:
        size, aa = ctx.opt("same_size", "1920x1080"), 2
        t = ctx.table("`sdfc render SCENE --devices LIST --size %s --aa 2`: each list's PNG "
                      "against the new build's on the first list (`sdfc compare`)." % size,
                      ["backend", "scene", "build"] + ["[%s]" % d for d in lists],
                      ["---"] * (3 + len(lists)))
        for b in gpus:
            for f in scenes:
                for x in ctx.builds:
                    cells = []
                    for d in lists:
                        p = "%s/dsame-%s-%s-%s-%s.png" % (IMG, x.name, b, scene_name(f), d)
                        render(x, f, b, p, size, aa, ["--devices", d])
                        base = "%s/dsame-new-%s-%s-%s.png" % (IMG, b, scene_name(f), lists[0])
                        if core.same_files(base, p):
                            cells.append("same")
                        else:
                            cells.append(core.agreement(core.compare(ctx.new, base, p)))
                    t.add(b, scene_name(f), x.name, *cells)
    if "first" in parts:
        first.first_picture(ctx, gpus, "examples/seed3.sdf", lists)
    if "cpu" in parts:
        size = ctx.opt("cpu_size", "1920x1080")
        frames = ctx.n_frames(3)
        t = ctx.table("`sdfc bench SCENE --devices 0|cpu,0 --size %s --frames %d`: the CPU "
                      "beside GPU 0, median whole frame ms." % (size, frames),
                      ["backend", "scene", "build", "[0]", "[cpu,0]", "speed-up"],
                      ["---"] * 3 + ["---:"] * 3)
        for b in gpus:
            for f in ["examples/seed3.sdf", "examples/seed6.sdf"]:
                for x in ctx.builds:
                    v = []
                    for d in ("0", "cpu,0"):
                        e = bench(x, [f], b, size, None, frames, ["--devices", d], ctx.fails)
                        v.append(ms(e[0], "median_frame_s") if e else None)
                    t.add(b, scene_name(f), x.name, fmt(v[0], 1), fmt(v[1], 1),
                          ratio(v[0], v[1]) + "×")


def stills(ctx):
    devices(ctx, ["still", "same"])


SUITES = {
    "examples": (examples, "every example (and the scaling scenes marched) at 1080p: "
                 "`sdfc bench` median GPU ms per backend; --with scaling=0 leaves those out"),
    "scaling": (scaling, "examples/scaling KIND_N marched and traced; --with kinds=, n=, "
                "march_max=1000, timeout=300"),
    "render-path": (render_path, "seed3 at 1080p and 8K aa 2 on one GPU: bench GPU/host ms, "
                    "render --stats phases, orbit.sdf frames/s, same PNGs, warm first picture; "
                    "--with count=120, sequence_size=, same=seed1,..."),
    "first-second": (first.first_second, "whole `sdfc render --stats` processes cold/warm/"
                     "sdfc cache, each phase, bare CUDA/Vulkan contexts, plain warm processes; "
                     "--with modes=cold,warm,sdfc[,vulkan], plain=N, scaling=FILE ..."),
    "devices": (devices, "several GPUs: 8K stills, sequences, same pictures, first picture "
                "per --devices list, the CPU beside a GPU; --with parts=, \"lists=0 0,1\""),
    "stills": (stills, "the devices suite's 8K stills and same pictures alone"),
}
