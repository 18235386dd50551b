"""The runner's shared parts: the machine's setup and record, the builds, running `sdfc`
(`bench --json`, `render --stats`, `compare --json`, whole processes) and parsing what it
prints, medians, and the Markdown tables every suite prints."""

import glob
import json
import os
import re
import shutil
import statistics
import subprocess
import time

IMG = "/tmp/sdfc-bench"


class Skip(Exception):
    """A suite that cannot run here (no GPU, no nvcc, no Python package): its reason."""


def setup_machine():
    """The GPU machine's setup: the Vulkan loader and GL vendor-neutral libraries carried as
    Debian packages in .gl/ unpacked, Vulkan pointed at the NVIDIA driver where it has one,
    the CUDA JIT cache at SDFC_CACHE_DIR (default /tmp/sdfc-jit). Harmless elsewhere."""
    debs = sorted(glob.glob(".gl/*.deb"))
    if debs and os.geteuid() == 0:
        for deb in debs:
            subprocess.run(["dpkg", "-x", deb, "/"], check=False)
        subprocess.run(["ldconfig"], check=False)
    icd = "/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json"
    if os.path.exists(icd):
        os.environ["VK_DRIVER_FILES"] = icd
        os.environ["__EGL_VENDOR_LIBRARY_FILENAMES"] = (
            "/usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json")
    os.environ.setdefault("SDFC_CACHE_DIR", "/tmp/sdfc-jit")
    os.environ.setdefault("XDG_RUNTIME_DIR", "/tmp/xdg")
    os.makedirs(os.environ["XDG_RUNTIME_DIR"], exist_ok=True)
    os.makedirs(IMG, exist_ok=True)


def gpu_count():
    """The NVIDIA GPUs of this host (0 without nvidia-smi)."""
    try:
        out = subprocess.run(["nvidia-smi", "-L"], capture_output=True, text=True).stdout
    except OSError:
        return 0
    return sum(1 for line in out.splitlines() if line.startswith("GPU"))


def machine(commit=None):
    """The machine, date and commit, recorded once per run."""
    gpus = []
    try:
        out = subprocess.run(["nvidia-smi", "--query-gpu=name,driver_version,clocks.max.sm",
                              "--format=csv,noheader"], capture_output=True, text=True).stdout
        gpus = [g.strip() for g in out.splitlines() if g.strip()]
    except OSError:
        pass
    cpu = "?"
    for line in open("/proc/cpuinfo"):
        if line.startswith("model name"):
            cpu = line.split(":", 1)[1].strip()
            break
    if commit is None:
        try:
            commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True,
                                    text=True).stdout.strip() or None
        except OSError:
            commit = None
    if commit is None and os.path.exists(".dev/commit.txt"):
        commit = open(".dev/commit.txt").read().split()[0]
    gpu = "%d× %s" % (len(gpus), gpus[0]) if gpus else "no NVIDIA GPU"
    return {
        "gpu": gpu, "gpus": gpus, "cpu": "%s, %d cores" % (cpu, os.cpu_count() or 0),
        "date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()), "commit": commit or "?",
        "load": open("/proc/loadavg").read().split()[:3],
    }


class Build:
    """One sdfc binary under its name: `new` (the build measured) or `old` (the one before)."""

    def __init__(self, name, path):
        self.name, self.path = name, path
        if os.path.exists(path):
            os.chmod(path, os.stat(path).st_mode | 0o111)

    def __repr__(self):
        return self.name


def run(cmd, env=None, timeout=None):
    """Runs `cmd`; returns (wall s measured outside, stdout, stderr, exit code). A timeout
    gives exit code 124."""
    t = time.perf_counter()
    try:
        p = subprocess.run([str(c) for c in cmd], env=env, capture_output=True, text=True,
                           timeout=timeout)
        return time.perf_counter() - t, p.stdout, p.stderr, p.returncode
    except subprocess.TimeoutExpired:
        return time.perf_counter() - t, "", "timed out", 124


def last_line(text):
    lines = text.strip().splitlines()
    return lines[-1] if lines else ""


class Failures(list):
    """What failed in a suite, printed under its tables."""

    def note(self, what, err):
        self.append("%s: %s" % (what, last_line(err)))


def size_spec(spec):
    """`WxH` or `WxH:AA` → (`WxH`, aa or None)."""
    size, _, aa = spec.partition(":")
    return size, int(aa) if aa else None


def bench(build, files, backend, size=None, aa=None, frames=5, extra=(), fails=None,
          timeout=None, env=None):
    """`sdfc bench --json`: the list of its entries (one a scene), or [] (noted in `fails`)."""
    cmd = [build.path, "bench", *files, "--backend", backend, "--frames", frames, "--json"]
    if size:
        cmd += ["--size", size]
    if aa:
        cmd += ["--aa", aa]
    cmd += list(extra)
    wall, out, err, code = run(cmd, env=env, timeout=timeout)
    try:
        return json.loads(out)
    except ValueError:
        if fails is not None:
            fails.note("%s bench %s %s" % (build, " ".join(map(str, files)), backend),
                       err or "exit %d" % code)
        return []


def ms(entry, key="median_s"):
    """A `bench --json` entry's seconds as ms (None when absent)."""
    v = entry.get(key) if entry else None
    return None if v is None else 1e3 * v


def stats(text):
    """The `run` block of `render --stats`: {"run": ms, phase: ms, phase + " how": text}."""
    out, inside = {}, False
    for line in text.splitlines():
        if line.startswith("run "):
            inside = True
            out["run"] = float(line.split()[1])
        elif inside and line.startswith("  "):
            name, rest = line[2:22].strip(), line[22:]
            m = re.match(r"\s*([0-9.]+|-) ms\s*(.*)", rest)
            if not m:
                continue
            out[name] = None if m.group(1) == "-" else float(m.group(1))
            out[name + " how"] = m.group(2)
        elif inside:
            inside = False
    return out


def render(build, file, backend, out, size=None, aa=None, extra=(), env=None, timeout=None):
    """`sdfc render` to `out`: (wall s, stdout + stderr, exit code)."""
    cmd = [build.path, "render", file, "--backend", backend, "-o", out]
    if size:
        cmd += ["--size", size]
    if aa:
        cmd += ["--aa", aa]
    wall, o, e, code = run(cmd + list(extra), env=env, timeout=timeout)
    return wall, o + e, code


def fps(text):
    """The frames/s a sequence's `render --frames` prints last."""
    m = re.findall(r"\(([0-9.]+) frames/s\)", text)
    return float(m[-1]) if m else None


def compare(build, a, b):
    """`sdfc compare --json`: {"psnr", "differing", ...} or None."""
    wall, out, err, code = run([build.path, "compare", a, b, "--json"])
    try:
        return json.loads(out)
    except ValueError:
        return None


def agreement(c):
    """A comparison as `PSNR dB, differing %`."""
    if not c:
        return "failed"
    psnr = "inf" if c.get("psnr") is None else "%.1f" % c["psnr"]
    return "%s dB, %.4f %%" % (psnr, 100 * c["differing"])


def same_files(a, b):
    """Whether two files, or two folders' files, are byte for byte the same."""
    if os.path.isdir(a) and os.path.isdir(b):
        na, nb = sorted(os.listdir(a)), sorted(os.listdir(b))
        return na == nb and all(same_files(os.path.join(a, n), os.path.join(b, n)) for n in na)
    try:
        return open(a, "rb").read() == open(b, "rb").read()
    except OSError:
        return False


def fresh(path):
    """An empty folder at `path`."""
    shutil.rmtree(path, ignore_errors=True)
    os.makedirs(path, exist_ok=True)
    return path


def median(values):
    values = [v for v in values if v is not None]
    return statistics.median(values) if values else None


def fmt(x, digits=2):
    """A number for a table: `-` for none, else `digits` decimals (none from 1 000)."""
    if x is None:
        return "-"
    if isinstance(x, str):
        return x
    if abs(x) >= 1000:
        return "%.0f" % x
    return "%.*f" % (digits, x)


def ratio(a, b):
    """a / b for a table."""
    return "-" if not a or not b else "%.2f" % (a / b)


def scene_name(path):
    return os.path.splitext(os.path.basename(path))[0]


def examples():
    return sorted(glob.glob("examples/*.sdf"))


class Table:
    """One Markdown table with its caption (the command and what each column is)."""

    def __init__(self, caption, head, align=None):
        self.caption, self.head, self.rows = caption, list(head), []
        self.align = align or ["---"] + ["---:"] * (len(head) - 1)

    def add(self, *cells):
        self.rows.append([fmt(c) if not isinstance(c, str) else c for c in cells])
        print("  " + " | ".join(self.rows[-1]), flush=True)

    def markdown(self):
        lines = [self.caption, "", "| " + " | ".join(self.head) + " |",
                 "|" + "|".join(self.align) + "|"]
        lines += ["| " + " | ".join(r) + " |" for r in self.rows]
        return "\n".join(lines)

    def data(self):
        return {"caption": self.caption, "head": self.head, "rows": self.rows}


class Ctx:
    """What a suite is given: the builds (new first, old second when present), the backends,
    sizes, runs and frames asked for (None: the suite's default), its options (`--with`), the
    scenes asked for, the output folder, and where its tables and failures go."""

    def __init__(self, builds, backends, sizes, runs, frames, options, scenes, out):
        self.builds, self.backends, self.sizes = builds, backends, sizes
        self.runs, self.frames, self.options, self.scenes, self.out = (
            runs, frames, options, scenes, out)
        self.tables, self.fails, self.data = [], Failures(), {}

    @property
    def new(self):
        return self.builds[0]

    @property
    def side_by_side(self):
        return len(self.builds) > 1

    def opt(self, key, default):
        """The suite option `key` (`--with key=value`), as the default's type."""
        v = self.options.get(key)
        if v is None:
            return default
        if isinstance(default, bool):
            return v not in ("0", "no", "false", "off")
        if isinstance(default, int):
            return int(v)
        if isinstance(default, float):
            return float(v)
        if isinstance(default, list):
            return [x for x in v.replace(",", " ").split() if x]
        return v

    def size_list(self, default):
        return [size_spec(s) for s in (self.sizes or default)]

    def n_runs(self, default):
        return self.runs or default

    def n_frames(self, default):
        return self.frames or default

    def scene_list(self, default):
        return self.scenes or default

    def gpu_backends(self):
        return [b for b in self.backends if b != "cpu"]

    def table(self, caption, head, align=None):
        t = Table(caption, head, align)
        self.tables.append(t)
        print("-- " + caption.splitlines()[0], flush=True)
        return t
