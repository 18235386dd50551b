"""sdfc from Python: check a scene, render it into a NumPy array, mesh it, and evaluate its
distance field at points, through the same compiler, renderers and mesher as the `sdfc`
command (docs/python.md).

    import sdfc
    scene = sdfc.Scene(path="examples/seed3.sdf")
    image = scene.render(size=(320, 240))           # (240, 320, 3) float32, linear RGB
    distances, materials = scene.distance([[0, 1, 0], [0, 0, 0]])
    part = sdfc.Scene(path="examples/mesh/bracket.sdf")  # bounded: seed3's floor plane is not
    vertices, faces, colours = part.mesh(resolution=64)

Shapes are Python objects too (python/sdfc/model.py, docs/python.md "Model in Python"):

    f = sdfc.sphere(1) & sdfc.box(0.75)
    f -= sdfc.cylinder(0.5, 3)
    f.save("part.stl", resolution=128)
"""

from __future__ import annotations

import dataclasses
import os
from typing import Any, Dict, Iterable, Iterator, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np

from . import _sdfc
from ._sdfc import CompileError

# Python's `round`: the package's own `round` (the language's, below) is a shape's.
_round = round

__all__ = ["CompileError", "Diagnostic", "Facts", "Scene", "check"]


@dataclasses.dataclass(frozen=True)
class Diagnostic:
    """One thing the compiler said about a scene, at its primary span (lines and columns
    1-based, columns in characters)."""

    severity: str
    code: str
    message: str
    file: str
    line: int
    column: int
    end_line: int
    end_column: int
    span_text: str
    label: str
    notes: Tuple[str, ...]
    help: Optional[str]

    @staticmethod
    def _of(d: Mapping[str, Any]) -> "Diagnostic":
        return Diagnostic(**{**d, "notes": tuple(d["notes"])})

    def __str__(self) -> str:
        return f"{self.file}:{self.line}:{self.column}: {self.severity}[{self.code}]: {self.message}"


@dataclasses.dataclass(frozen=True)
class Facts:
    """What the analysis derived about a clean scene's distance field, as `sdfc check` says:
    exact, a bound or approximate; its Lipschitz bound L (None where none is proven); the
    intersection method ("trace" or "march") and why; the box that holds the solid, (lo,
    hi), infinite along an axis where it is unbounded (None for a scene with no objects)."""

    exactness: Optional[str]
    lipschitz: Optional[float]
    proven: Optional[bool]
    step_lipschitz: Optional[float]
    method: str
    method_reason: str
    summary: str
    animated: bool
    box: Optional[Tuple[Tuple[float, float, float], Tuple[float, float, float]]] = None


def _diagnostics(error: CompileError) -> List[Diagnostic]:
    return [Diagnostic._of(d) for d in getattr(error, "diagnostics", [])]


def _wrap(error: CompileError) -> CompileError:
    error.diagnostics = _diagnostics(error)
    return error


def check(
    source: Optional[str] = None, path: Optional[str] = None, limits: Optional[Mapping[str, int]] = None
) -> Tuple[List[Diagnostic], Optional[Facts]]:
    """Checks a scene given as text (`source`; `path`, if given, names it for its imports) or
    read from `path`: every diagnostic, and the facts of its field when it has no errors
    (None when it has). Raises ValueError for a file that cannot be read."""
    diags, facts = _sdfc.check(source, path, _limits(limits))
    return [Diagnostic._of(d) for d in diags], (Facts(**facts) if facts is not None else None)


def _limits(limits: Optional[Mapping[str, int]]) -> List[str]:
    return [f"{k}={v}" for k, v in (limits or {}).items()]


def _setting(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (tuple, list, np.ndarray)):
        return ",".join(str(v) for v in value)
    return str(value)


class Scene:
    """A checked scene (raises CompileError when it has errors), from its text (`source`) or
    file (`path`), with render settings overridden as `sdfc render --set` does
    (`set={"max_steps": 512, "background": (0, 0, 0)}`), and resource limits raised or
    lowered as `sdfc --limit` does (`limits={"memory": 8192}`; `sdfc --help` lists them),
    and its parameters given values as `sdfc --param` does (`params={"width": 60}`).

    Every method is safe to call from several threads at once; renders and meshes release
    the GIL, and Ctrl-C during them raises KeyboardInterrupt."""

    def __init__(
        self,
        source: Optional[str] = None,
        path: Optional[str] = None,
        set: Optional[Mapping[str, Any]] = None,
        limits: Optional[Mapping[str, int]] = None,
        params: Optional[Mapping[str, Any]] = None,
        _locate: Any = None,
    ) -> None:
        sets = [f"{k}={_setting(v)}" for k, v in (set or {}).items()]
        values = [(k, _setting(v)) for k, v in (params or {}).items()]
        # A scene of a modelled shape places its errors at the Python lines (model.py).
        self._locate = _locate
        self._scene = self._call(
            _sdfc._Scene, source, None if path is None else str(path), sets, _limits(limits), values
        )
        self.path = path

    @property
    def params(self) -> List[Dict[str, Any]]:
        """The scene's parameters (`param`): name, type, value, default, doc, and min, max,
        step or choices where stated."""
        return [dict(p) for p in self._scene.params()]

    def info(self) -> Dict[str, Any]:
        """The scene's own settings: width, height, aa, fps, duration, and whether it reads t."""
        return dict(self._scene.info())

    def render(
        self,
        size: Optional[Tuple[int, int]] = None,
        backend: str = "auto",
        aa: Optional[int] = None,
        t: float = 0.0,
        dtype: Any = np.float32,
    ) -> np.ndarray:
        """Renders the scene at the time `t` into an (h, w, 3) array: float32 linear RGB
        (unclamped), or with `dtype=np.uint8` the clamped sRGB bytes `sdfc render` writes to
        a PNG. `size=(w, h)` and `aa` override the scene's render block; `backend` is "auto"
        (CUDA, else a wgpu GPU, else the CPU), "cpu", "wgpu" or "cuda"."""
        encoding = {np.dtype(np.float32): "linear", np.dtype(np.uint8): "srgb"}.get(np.dtype(dtype))
        if encoding is None:
            raise ValueError("dtype must be float32 (linear) or uint8 (sRGB)")
        w, h, data = self._call(self._scene.render, _size(size), backend, aa, float(t), encoding)
        return np.frombuffer(data, dtype=np.dtype(dtype)).reshape(h, w, 3).copy()

    def png(self, size: Optional[Tuple[int, int]] = None, backend: str = "auto", aa: Optional[int] = None, t: float = 0.0) -> bytes:
        """The render as the bytes of a PNG file (what `sdfc render -o FILE.png` writes)."""
        return self._call(self._scene.render, _size(size), backend, aa, float(t), "png")[2]

    def _repr_png_(self) -> bytes:
        # Jupyter shows the scene as its picture: at most 640 pixels wide, on the best backend.
        info = self._scene.info()
        w, h = info["width"], info["height"]
        if w > 640:
            w, h = 640, max(1, _round(h * 640 / w))
        return self.png(size=(w, h))

    def depth(
        self,
        size: Optional[Tuple[int, int]] = None,
        aa: Optional[int] = None,
        t: float = 0.0,
        backend: str = "cpu",
    ) -> Tuple[np.ndarray, np.ndarray]:
        """Where each pixel's camera rays first hit a surface, as `sdfc render --aux` writes
        it: the mean distance from the eye along the ray of the rays that hit ((h, w) float32,
        NaN where none did) and the fraction of the pixel's rays that hit ((h, w) float32).
        Rendered on the CPU, the one renderer that keeps depth buffers (another `backend`
        raises ValueError)."""
        w, h, d, c = self._call(self._scene.depth, _size(size), backend, aa, float(t))
        d = np.frombuffer(d, dtype=np.float32).reshape(h, w).copy()
        c = np.frombuffer(c, dtype=np.float32).reshape(h, w).copy()
        return (d, c)

    def distance(self, points: Any, t: float = 0.0, backend: str = "cpu") -> Tuple[np.ndarray, np.ndarray]:
        """The signed distance and material id at each of `points`, an (n, 3) array (or one
        point of 3): through the CPU interpreter in float64 (`backend="cpu"`), or on a GPU
        in float32 by the scene's compiled `map` (`"wgpu"`, or `"cuda"` through the CUDA
        driver): ((n,) float64 or float32, (n,) uint32)."""
        p = np.ascontiguousarray(points, dtype=np.float64)
        single = p.shape == (3,)
        if single:
            p = p.reshape(1, 3)
        if p.ndim != 2 or p.shape[1] != 3:
            raise ValueError(f"points must have the shape (n, 3), not {p.shape}")
        d, m = self._call(self._scene.distance, p.tobytes(), float(t), backend)
        d = np.frombuffer(d, dtype=np.float64 if backend == "cpu" else np.float32).copy()
        m = np.frombuffer(m, dtype=np.uint32).copy()
        return (d, m)

    def mesh(
        self,
        resolution: Optional[int] = None,
        bounds: Optional[Sequence[Sequence[float]]] = None,
        voxel: Optional[float] = None,
        sharp: bool = True,
        t: float = 0.0,
    ) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The surface as `sdfc mesh` meshes it (watertight, sharp-edged): vertices (n, 3)
        float64, faces (m, 3) uint32 counter-clockwise from outside, and linear vertex
        colours (n, 3) float32. `resolution` is the cells along the longest side (default
        128), or `voxel` a cell's edge; `bounds=((x0, y0, z0), (x1, y1, z1))` the region
        (needed for an unbounded scene)."""
        v, f, c = self._call(self._scene.mesh, resolution, voxel, _bounds(bounds), sharp, float(t))
        v = np.frombuffer(v, dtype=np.float64).reshape(-1, 3).copy()
        f = np.frombuffer(f, dtype=np.uint32).reshape(-1, 3).copy()
        c = np.frombuffer(c, dtype=np.float32).reshape(-1, 3).copy()
        return (v, f, c)

    def save(
        self,
        path: Any,
        resolution: Optional[int] = None,
        bounds: Optional[Sequence[Sequence[float]]] = None,
        voxel: Optional[float] = None,
        sharp: bool = True,
        t: float = 0.0,
        up: Optional[str] = None,
    ) -> Tuple[int, int]:
        """Meshes as `mesh` does and writes the mesh to `path` as `sdfc mesh -o PATH` does,
        in the format its extension names (.stl, .obj, .ply, .glb, .3mf; another raises
        ValueError): (triangles, vertices). `up` is the file's up axis, "y" (the scene's) or
        "z" (a slicer's); by default z for .3mf, y for the others."""
        return self._call(self._scene.save, os.fspath(path), resolution, voxel, _bounds(bounds), sharp, float(t), up)

    def compile(self, emit: str = "wgsl", part: str = "kernel", name: Optional[str] = None, sm: int = 70, t: float = 0.0) -> Union[str, bytes]:
        """What `sdfc compile --emit EMIT --part PART` writes: text, or bytes for the binary
        targets (spirv, params, scene-data)."""
        data = self._call(self._scene.compile, emit, part, name, sm, float(t))
        if emit in ("spirv", "params", "scene-data"):
            return data
        return data.decode("utf-8")

    def frames(
        self,
        frames: Optional[Iterable[int]] = None,
        size: Optional[Tuple[int, int]] = None,
        backend: str = "auto",
        aa: Optional[int] = None,
        dtype: Any = np.float32,
    ) -> Iterator[np.ndarray]:
        """Renders frame k of the animation at the time k / fps for each k of `frames`
        (default: the frames the scene's render block states)."""
        info = self._scene.info()
        fps = info["fps"]
        if frames is None:
            frames = range(_round(fps * info["duration"]))
        for k in frames:
            yield self.render(size=size, backend=backend, aa=aa, t=k / fps, dtype=dtype)

    def _call(self, f: Any, *args: Any) -> Any:
        try:
            return f(*args)
        except CompileError as e:
            error = _wrap(e)
            if self._locate is not None:
                error = self._locate(error)
            raise error from None


def _bounds(bounds: Optional[Sequence[Sequence[float]]]) -> Any:
    if bounds is None:
        return None
    lo, hi = bounds
    return (tuple(float(x) for x in lo), tuple(float(x) for x in hi))


def _size(size: Optional[Tuple[int, int]]) -> Optional[Tuple[int, int]]:
    if size is None:
        return None
    w, h = size
    return (int(w), int(h))


# The modelling API (model.py): a function per built-in that makes a shape or a profile,
# generated from the checker's table, and the keyword classes of the materials, lights,
# camera and render settings; model.pyi, generated from the same table, types them.
from . import model  # noqa: E402
from .model import *  # noqa: E402,F401,F403

__all__ += model.__all__
