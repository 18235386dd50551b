#!/usr/bin/env python3
"""The one benchmark runner of sdfc: named suites, each timing the build at `--sdfc` (default
.dev/sdfc) and, where `--old` (default .dev/sdfc-old) exists, the build before it, side by
side (their runs alternating), printing its Markdown tables last and writing its JSON to
$OUT/<suite>.json. Python 3 and its standard library only (numpy for the `python` suite): it
runs on the GPU machine beside a carried binary, and here on the CPU and lavapipe.

    scripts/bench.py --list
    scripts/bench.py --suite examples,render-path [--backends cuda,wgpu] [--size 1920x1080]
                     [--runs N] [--frames N] [--scenes FILE...] [--with KEY=VALUE ...]
    scripts/bench.py --suite examples --backends cpu,wgpu --size 64x48 --frames 2   (here)

A size is `WxH` or `WxH:AA` (supersampling); `--size a,b` runs several. The machine, the
date and the commit are recorded once ($OUT/machine.json) and printed with the tables.
BENCHMARKS.md names, under each table, the command that reproduces it."""

import argparse
import json
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from benchlib import core, frames, kernels, looks, peers  # noqa: E402

SUITES = {}
for module in (frames, kernels, looks, peers):
    SUITES.update(module.SUITES)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter,
                                 epilog=__doc__.split("\n\n", 1)[1])
    ap.add_argument("--list", action="store_true", help="name the suites and what they time")
    ap.add_argument("--suite", help="suites to run, comma-separated")
    ap.add_argument("--sdfc", default=".dev/sdfc", help="the build measured (new)")
    ap.add_argument("--old", default=".dev/sdfc-old", help="the build before it, if present")
    ap.add_argument("--backends", default="cuda,wgpu", help="e.g. cuda,wgpu or cpu,wgpu")
    ap.add_argument("--size", help="image sizes, WxH or WxH:AA, comma-separated")
    ap.add_argument("--runs", type=int, help="runs of each measurement")
    ap.add_argument("--frames", type=int, help="frames timed by each `sdfc bench`")
    ap.add_argument("--scenes", nargs="+", help="scene files instead of the suite's own")
    ap.add_argument("--with", dest="options", action="append", default=[],
                    metavar="KEY=VALUE", help="a suite's own option (--list names them)")
    ap.add_argument("--commit", help="the commit of --sdfc, when no git says it")
    ap.add_argument("--out", default=os.environ.get("OUT", "/tmp/out"), help="JSON folder")
    a = ap.parse_args()
    if a.list or not a.suite:
        for name, (_, doc) in SUITES.items():
            print("%-13s %s" % (name, doc))
        return 0 if a.list else 2
    names = [s for s in a.suite.split(",") if s]
    unknown = [n for n in names if n not in SUITES]
    if unknown:
        ap.error("no suite %s (--list names them)" % ", ".join(unknown))
    if not os.path.exists(a.sdfc):
        ap.error("no sdfc binary at %s (--sdfc PATH)" % a.sdfc)
    core.setup_machine()
    os.makedirs(a.out, exist_ok=True)
    builds = [core.Build("new", a.sdfc)]
    if a.old and os.path.exists(a.old):
        builds.append(core.Build("old", a.old))
    options = dict(o.split("=", 1) for o in a.options)
    record = core.machine(a.commit)
    record["builds"] = {b.name: b.path for b in builds}
    json.dump(record, open(os.path.join(a.out, "machine.json"), "w"), indent=1)
    done, status = [], 0
    for name in names:
        print("== %s" % name, flush=True)
        ctx = core.Ctx(builds, a.backends.split(","), a.size.split(",") if a.size else None,
                       a.runs, a.frames, options, a.scenes, a.out)
        try:
            SUITES[name][0](ctx)
        except core.Skip as why:
            ctx.fails.append("not run: %s" % why)
        if ctx.fails:
            status = 1
        json.dump({"suite": name, "machine": record, "tables": [t.data() for t in ctx.tables],
                   "data": ctx.data, "failures": ctx.fails},
                  open(os.path.join(a.out, name + ".json"), "w"), indent=1)
        done.append((name, ctx))
    print()
    print("%s; %s; %s; commit %s; builds: %s" % (
        record["gpu"], record["cpu"], record["date"], record["commit"],
        ", ".join("%s %s" % (b.name, b.path) for b in builds)))
    for name, ctx in done:
        print()
        print("## %s" % name)
        for t in ctx.tables:
            print()
            print(t.markdown())
        for f in ctx.fails:
            print("FAILED: " + f if not f.startswith("not run") else f)
    return status


if __name__ == "__main__":
    sys.exit(main())
