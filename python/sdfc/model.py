"""Shapes as Python objects (docs/python.md, "Model in Python"): every built-in of the
language that makes a shape or a profile is a function of `sdfc` (and, where its first
parameter is one, a method), generated at import from the checker's table of built-ins
(`_sdfc.builtins()`), with the language's names, parameters and defaults; `|`, `&` and `-`
are the booleans and `@` paints with a material. A shape stands for `.sdf` text, which it
writes (`source`), checks and compiles (`scene`), and through which it meshes, saves,
renders, evaluates and states its facts.

    import sdfc
    f = sdfc.sphere(1) & sdfc.box(0.75)
    c = sdfc.cylinder(0.5, 3)
    f -= c | c.rotate_x(sdfc.deg(90)) | c.rotate_z(sdfc.deg(90))
    f.save("out.stl", resolution=128)
"""

from __future__ import annotations

import keyword
import math
import numbers
import os
import re
import sys
from typing import Any, Dict, List, Optional, Sequence, Tuple

import numpy as np

from . import _sdfc, writing
from ._sdfc import CompileError

_HERE = os.path.dirname(os.path.abspath(__file__))


def _caller() -> Tuple[str, int]:
    """The file and line of the nearest caller outside this package."""
    f = sys._getframe(1)
    while f is not None and _inside(f.f_code.co_filename):
        f = f.f_back
    if f is None:
        return ("<unknown>", 0)
    return (f.f_code.co_filename, f.f_lineno)


_INSIDE: Dict[str, bool] = {}


def _inside(filename: str) -> bool:
    """Whether the file is one of this package's (asked once per file)."""
    inside = _INSIDE.get(filename)
    if inside is None:
        inside = _INSIDE[filename] = os.path.dirname(os.path.abspath(filename)) == _HERE
    return inside


# --- values -------------------------------------------------------------------------------


class Angle:
    """An angle: `deg(30)` or `rad(0.5)`, as the language writes `30deg` and `0.5rad`. A plain
    number where an angle goes is refused, as in the language: it could be either (fogleman/sdf
    reads radians, OpenSCAD degrees)."""

    __slots__ = ("value", "unit")

    def __init__(self, value: float, unit: str = "deg") -> None:
        if unit not in ("deg", "rad"):
            raise ValueError(f'unit must be "deg" or "rad", not {unit!r}')
        self.value = float(value)
        self.unit = unit

    @property
    def radians(self) -> float:
        return math.radians(self.value) if self.unit == "deg" else self.value

    def __repr__(self) -> str:
        return f"sdfc.{self.unit}({writing.num(self.value)})"

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Angle) and self.radians == other.radians

    def __hash__(self) -> int:
        return hash(self.radians)


def deg(x: float) -> Angle:
    """An angle of `x` degrees (the language's `xdeg`)."""
    return Angle(x, "deg")


def rad(x: float) -> Angle:
    """An angle of `x` radians (the language's `xrad`)."""
    return Angle(x, "rad")


# The language's types of value: the annotation of each in model.pyi (stubs.py), and the
# words an error names it with.
_TYPES = {
    "float": ("float", "a number"),
    "int": ("int", "an int"),
    "bool": ("bool", "a bool"),
    "vec2": ("Vec2", "2 numbers"),
    "vec3": ("Vec3", "3 numbers"),
    "angle": ("Angle", "an angle, sdfc.deg(x) or sdfc.rad(x)"),
    "string": ("str", "a str"),
    "shape": ("Shape", "a shape"),
    "profile": ("Profile", "a profile"),
    "path": ("Path", "a path (sdfc.polyline, sdfc.helix, sdfc.bezier or sdfc.arc3)"),
}


def _words(ty: str) -> str:
    return _TYPES[ty][1] if ty in _TYPES else ty


def _type_words(ty: str) -> str:
    if ty.startswith("["):
        return f"a list of {_words(ty[1:-1]).replace('a ', '', 1)}s"
    return _words(ty)


class _Bad(Exception):
    """A value that does not fit a parameter's type (the message says why)."""


def _real(x: Any) -> float:
    if isinstance(x, (bool, np.bool_)) or not isinstance(x, numbers.Real):
        raise _Bad()
    v = float(x)
    if not math.isfinite(v):
        raise _Bad("must be finite")
    return v


def _conform(value: Any, ty: str) -> Any:
    """`value` as the parameter of type `ty` takes it (numbers as floats or ints, vectors as
    tuples, angles as `Angle`), or raises `_Bad`."""
    if ty == "float":
        return _real(value)
    if ty == "int":
        if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Integral):
            raise _Bad()
        i = int(value)
        if not -(2**63) <= i < 2**63:
            raise _Bad("must fit in 64 bits")
        return i
    if ty == "bool":
        if not isinstance(value, (bool, np.bool_)):
            raise _Bad()
        return bool(value)
    if ty in ("vec2", "vec3"):
        n = 2 if ty == "vec2" else 3
        if isinstance(value, (str, bytes, _Expr)) or not hasattr(value, "__len__"):
            raise _Bad()
        if len(value) != n:
            raise _Bad()
        return tuple(_real(c) for c in value)
    if ty == "angle":
        if isinstance(value, Angle):
            if not math.isfinite(value.value):
                raise _Bad("must be finite")
            return value
        n = writing.num(_real(value))
        raise _Bad(f"must be an angle with its unit, sdfc.deg({n}) or sdfc.rad({n}), not the plain number {n}")
    if ty == "string":
        if not isinstance(value, str):
            raise _Bad()
        bad = [c for c in value if ord(c) < 32 and c not in "\n\t"]
        if bad:
            raise _Bad(f"holds the control character {bad[0]!r}, which the language cannot write")
        return value
    if ty == "shape":
        if not isinstance(value, Shape):
            raise _Bad()
        return value
    if ty == "profile":
        if not isinstance(value, Profile):
            raise _Bad()
        return value
    if ty == "path":
        if not isinstance(value, Path):
            raise _Bad()
        return value
    if ty.startswith("["):
        if not isinstance(value, (list, tuple)):
            raise _Bad()
        return [_conform(v, ty[1:-1]) for v in value]
    raise _Bad()


def _range_value(v: Any) -> Any:
    if isinstance(v, Angle):
        return ("rad", v.radians)
    if isinstance(v, tuple):
        return list(v)
    return v


def _what(value: Any) -> str:
    if isinstance(value, _Expr):
        return f"a {type(value).__name__.lower()}"
    if isinstance(value, (list, tuple, np.ndarray)):
        return f"a {type(value).__name__} of {len(value)}"
    return type(value).__name__


# --- the table ---------------------------------------------------------------------------


class _Param:
    __slots__ = ("name", "type", "required", "default", "default_text", "checked", "index")

    def __init__(self, d: Dict[str, Any], index: int) -> None:
        for k in ("name", "type", "required", "default", "default_text", "checked"):
            setattr(self, k, d[k])
        self.index = index


class _Sig:
    __slots__ = ("index", "params", "rest", "ret", "signature", "method")

    def __init__(self, d: Dict[str, Any], index: int) -> None:
        self.index = index
        self.params = [_Param(p, i) for i, p in enumerate(d["params"])]
        self.rest = d["rest"]
        self.ret = d["ret"]
        self.signature = d["signature"]
        self.method = d["method"]


class _Builtin:
    __slots__ = ("name", "doc", "sigs")

    def __init__(self, d: Dict[str, Any]) -> None:
        self.name = d["name"]
        self.doc = d["doc"] or ""
        self.sigs = [_Sig(s, i) for i, s in enumerate(d["sigs"])]


BUILTINS: Dict[str, _Builtin] = {d["name"]: _Builtin(d) for d in _sdfc.builtins()}

# The kinds of value a built-in makes that Python builds as expressions.
_MADE = ("shape", "profile", "path")

# The built-ins that make shapes, profiles or paths, reachable from Python; the others compute
# numbers and vectors (Python's own arithmetic does that, and a `field` formula calls them).
SHAPE_BUILTINS: List[str] = [n for n, b in BUILTINS.items() if any(s.ret in _MADE for s in b.sigs)]
VALUE_BUILTINS: List[str] = [n for n in BUILTINS if n not in SHAPE_BUILTINS]


def _bind(b: _Builtin, sig: _Sig, args: Sequence[Any], kwargs: Dict[str, Any]) -> Tuple[int, Any]:
    """Binds the call to one overload: (how many arguments fit, the bound arguments as
    [(param, value)] in the parameters' order, a repeated one's values in theirs) or (how
    many fit before the first that does not, the error to raise)."""
    params = sig.params
    bound: List[Tuple[_Param, Any]] = []
    fit = 0
    if len(args) > len(params) and not sig.rest:
        # The form that takes the most arguments is the one to name.
        return (len(params) - len(args), TypeError(f"takes at most {len(params)} arguments ({len(args)} given)"))
    for i, a in enumerate(args):
        p = params[min(i, len(params) - 1)]
        bound.append((p, a))
    names = {p.name for p in params}
    given = {p.name for p, _ in bound}
    for k, v in kwargs.items():
        if k not in names:
            return (0, TypeError(f"got an unexpected keyword argument `{k}`"))
        if k in given:
            return (0, TypeError(f"got `{k}` twice"))
        bound.append((next(p for p in params if p.name == k), v))
        given.add(k)
    out = []
    # Sorting is stable: a repeated (last) parameter's values keep their order.
    for p, v in sorted(bound, key=lambda pv: pv[0].index):
        try:
            out.append((p, _conform(v, p.type)))
            fit += 1
        except _Bad as e:
            why = str(e) or f"must be {_type_words(p.type)}, not {_what(v)}"
            return (fit, TypeError(f"`{p.name}` {why}"))
    for p in params:
        if p.required and p.name not in given:
            return (fit, TypeError(f"missing the argument `{p.name}`"))
    return (fit, out)


def _call(name: str, args: Sequence[Any], kwargs: Dict[str, Any], method: bool = False) -> "_Expr":
    b = BUILTINS[name]
    best: Optional[Tuple[int, Exception, _Sig]] = None
    for sig in b.sigs:
        if sig.ret not in _MADE:
            continue
        fit, bound = _bind(b, sig, args, kwargs)
        if isinstance(bound, Exception):
            if best is None or fit > best[0]:
                best = (fit, bound, sig)
            continue
        for p, v in bound:
            if p.checked and not isinstance(v, (_Expr, list, bool)):
                why = _sdfc.range_error(f"builtin:{name}", sig.index, p.index, _range_value(v))
                if why:
                    raise ValueError(f"sdfc.{name}(): `{p.name}` {why}, not {_show(v)}")
        node_type = {"shape": Shape, "profile": Profile, "path": Path}[sig.ret]
        return node_type(name, bound, method=method)
    assert best is not None
    fit, error, sig = best
    shapes = [s.signature for s in b.sigs if s.ret in _MADE]
    hint = "" if len(shapes) == 1 else " (its forms: " + "; ".join(shapes) + ")"
    raise type(error)(f"sdfc.{name}(): {error}{hint}")


def _show(v: Any) -> str:
    if isinstance(v, tuple):
        return "(" + ", ".join(writing.num(c) for c in v) + ")"
    if isinstance(v, float):
        return writing.num(v)
    return repr(v)


# --- shapes ------------------------------------------------------------------------------


class _Expr:
    """A shape or profile: a call of a built-in on arguments, a formula, or a painted shape;
    it records the Python line that built it."""

    __slots__ = ("_name", "_args", "_loc", "_method", "_flat", "__weakref__")

    def __init__(self, name: str, args: List[Tuple[Any, Any]], method: bool = False, flat: bool = False) -> None:
        self._name = name
        self._args = args
        self._loc = _caller()
        self._method = method
        self._flat = flat

    def _children(self) -> List[Any]:
        out = []
        for _, v in self._args:
            if isinstance(v, _Expr):
                out.append(v)
            elif isinstance(v, list):
                out.extend(x for x in v if isinstance(x, _Expr))
        return out

    def _binary(self, other: Any, name: str) -> "_Expr":
        if not isinstance(other, type(self)):
            return NotImplemented
        ty = "shape" if isinstance(self, Shape) else "profile"
        b = BUILTINS[name]
        sig = next(s for s in b.sigs if s.params[0].type == ty)
        return type(self)(name, [(sig.params[0], self), (sig.params[1], other)], flat=True)

    def __or__(self, other: Any) -> Any:
        """`a | b`: `union(a, b)`."""
        return self._binary(other, "union")

    def __and__(self, other: Any) -> Any:
        """`a & b`: `intersect(a, b)`."""
        return self._binary(other, "intersect")

    def __sub__(self, other: Any) -> Any:
        """`a - b`: `subtract(a, b)`."""
        return self._binary(other, "subtract")

    def source(self) -> str:
        """The expression's `.sdf` text (a profile's as `let result = …;`; a shape's is a file)."""
        return writing.fmt(writing.Text(self, profile=isinstance(self, Profile)).text)

    def __repr__(self) -> str:
        text = writing.Text(self, profile=isinstance(self, Profile)).expression()
        return f"<sdfc.{type(self).__name__} {text if len(text) < 200 else text[:197] + '...'}>"


class Profile(_Expr):
    """A profile: a signed distance field of the plane (`circle`, `rect`, `polygon`, …),
    made a shape by `extrude`, `revolve`, `loft` or `screw`."""

    __slots__ = ()


class Path(_Expr):
    """A path a profile is swept along (`sweep(profile, path)`): `polyline`, `helix`,
    `bezier` or `arc3`. Paths are not combined."""

    __slots__ = ()

    def _binary(self, other: Any, name: str) -> Any:
        return NotImplemented


class Shape(_Expr):
    """A shape: a signed distance field of space."""

    __slots__ = ()

    def __matmul__(self, material: Any) -> "Shape":
        """`shape @ material`: the shape painted with a material (`sdfc.Phong(...)`)."""
        if not isinstance(material, Record) or material._group != "material":
            raise TypeError(f"a shape is painted with a material (sdfc.Phong(...), sdfc.Checker(...)), not {_what(material)}")
        return Shape("@", [(None, self), (None, material)])

    def source(
        self,
        camera: Optional["Record"] = None,
        lights: Optional[Sequence["Record"]] = None,
        render: Optional["Record"] = None,
    ) -> str:
        """The `.sdf` file this shape stands for, as `sdfc fmt` writes it: its materials, a
        camera (`camera`, or one that frames the shape's box), lights (`lights`, or a key
        and a fill light; `[]` for none), the render settings `render`, and the scene."""
        return writing.fmt(self._text(camera, lights, render).text)

    def _text(self, camera: Any, lights: Any, render: Any) -> "writing.Text":
        settings = _settings(camera, lights, render)
        if camera is None:
            framed = _framing(self)
            if framed is not None:
                settings.insert(0, framed)
        if lights is None:
            settings.extend(_default_lights())
        return writing.Text(self, settings=settings)

    def scene(
        self,
        camera: Optional["Record"] = None,
        lights: Optional[Sequence["Record"]] = None,
        render: Optional["Record"] = None,
        set: Optional[Dict[str, Any]] = None,
        limits: Optional[Dict[str, int]] = None,
    ) -> "Any":
        """A checked `sdfc.Scene` of `source(camera, lights, render)`; `set` and `limits`
        as `sdfc.Scene`'s. Errors raise `sdfc.CompileError` at the Python line that built
        the offending shape."""
        return writing.compiled(self._text(camera, lights, render), set, limits)

    def _bare(self, limits: Optional[Dict[str, int]] = None) -> Any:
        """The shape's scene without camera or lights (what meshes, distances and facts
        read), compiled once (with other `limits` than the default, each time)."""
        if limits is not None:
            return writing.compiled(writing.Text(self), None, limits)
        kept = _BARE.get(id(self))
        if kept is not None and kept[0] is self:
            return kept[1]
        scene = writing.compiled(writing.Text(self), None, None)
        _BARE[id(self)] = (self, scene)
        if len(_BARE) > 64:
            _BARE.pop(next(iter(_BARE)))
        return scene

    def mesh(
        self,
        resolution: Optional[int] = None,
        bounds: Optional[Sequence[Sequence[float]]] = None,
        voxel: Optional[float] = None,
        sharp: bool = True,
        limits: Optional[Dict[str, int]] = None,
    ) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(vertices, faces, colours) as `sdfc.Scene.mesh` gives them: watertight, sharp
        edged; `resolution` cells along the longest side (128) or `voxel` a cell's edge;
        `limits` as `sdfc.Scene`'s (`{"memory": 8192}` for a finer mesh)."""
        return self._bare(limits).mesh(resolution=resolution, bounds=bounds, voxel=voxel, sharp=sharp)

    def save(
        self,
        path: Any,
        resolution: Optional[int] = None,
        bounds: Optional[Sequence[Sequence[float]]] = None,
        voxel: Optional[float] = None,
        sharp: bool = True,
        limits: Optional[Dict[str, int]] = None,
        up: Optional[str] = None,
    ) -> Tuple[int, int]:
        """Meshes the shape and writes it to `path` as `sdfc mesh -o PATH` does, in the
        format of its extension (.stl, .obj, .ply, .glb, .3mf): (triangles, vertices); `up`
        the file's up axis, "y" (the scene's) or "z" (a slicer's; the default for .3mf); the
        other parameters as `mesh`'s."""
        return self._bare(limits).save(os.fspath(path), resolution=resolution, bounds=bounds, voxel=voxel, sharp=sharp, up=up)

    def distance(self, points: Any, backend: str = "cpu") -> np.ndarray:
        """The signed distance at each of `points` ((n, 3), or one point): float64 on the
        CPU, float32 on a GPU (`backend="wgpu"` or `"cuda"`)."""
        d, _ = self._bare().distance(points, backend=backend)
        return d

    def facts(self) -> Any:
        """What the analysis proves of the shape's field: `exactness` ("exact", "bound",
        "approximate"), `lipschitz` (L), `box` ((lo, hi), infinite where unbounded), and
        the rest of `sdfc.Facts`."""
        return writing.facts(writing.Text(self))

    def render(
        self,
        size: Optional[Tuple[int, int]] = None,
        backend: str = "auto",
        aa: Optional[int] = None,
        camera: Optional["Record"] = None,
        lights: Optional[Sequence["Record"]] = None,
        render: Optional["Record"] = None,
        dtype: Any = np.float32,
    ) -> np.ndarray:
        """The picture of `scene(camera, lights, render)`, as `sdfc.Scene.render` gives it."""
        return self.scene(camera, lights, render).render(size=size, backend=backend, aa=aa, dtype=dtype)

    def png(self, size: Optional[Tuple[int, int]] = (480, 360), backend: str = "auto", **scene: Any) -> bytes:
        """The picture as the bytes of a PNG file."""
        return self.scene(**scene).png(size=size, backend=backend)

    def _repr_png_(self) -> bytes:
        # Jupyter shows a shape as its picture.
        return self.png()

    def show(self, **scene: Any) -> Any:
        """Opens the live viewer on the shape (`sdfc.show`)."""
        return show(self, **scene)


_BARE: Dict[int, Tuple[Any, Any]] = {}


# --- formulas ----------------------------------------------------------------------------

_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*\Z")


def _formula(kind: str, formula: str, lipschitz: Optional[float], bindings: Dict[str, Any]) -> Any:
    if not isinstance(formula, str):
        raise TypeError(f"sdfc.{kind}(): `formula` must be a str, not {_what(formula)}")
    if lipschitz is not None:
        try:
            lipschitz = _real(lipschitz)
        except _Bad:
            raise TypeError(f"sdfc.{kind}(): `lipschitz` must be a number, not {_what(lipschitz)}") from None
        if lipschitz <= 0:
            raise ValueError(f"sdfc.{kind}(): `lipschitz` must be greater than 0, not {writing.num(lipschitz)}")
    lets = []
    for name, v in bindings.items():
        if not _NAME.match(name) or name == "p":
            raise ValueError(f"sdfc.{kind}(): `{name}` cannot name a value in a formula")
        for ty in ("shape", "profile", "float", "vec3", "vec2", "angle"):
            try:
                lets.append((name, _conform(v, ty)))
                break
            except _Bad:
                continue
        else:
            raise TypeError(f"sdfc.{kind}(): `{name}` must be a number, a vector, an angle, a shape or a profile, not {_what(v)}")
    node = (Shape if kind == "field" else Profile)(kind, [(None, formula), (None, lipschitz)] + lets)
    return node


def field(formula: str, lipschitz: Optional[float] = None, **values: Any) -> Shape:
    """`field { formula }`: the shape whose distance at the point `p` (a vec3) is the
    formula's value (docs/language.md, "Fields"); `values` are named in it (`field("distance(s,
    p) - 0.1", s=sdfc.box(1))`), `lipschitz` declares its bound. A formula of a vec3 is a
    colour field, for a material's colour."""
    return _formula("field", formula, lipschitz, values)


def profile(formula: str, lipschitz: Optional[float] = None, **values: Any) -> Profile:
    """`profile { formula }`: the profile whose distance at the point `p` (a vec2) of the
    plane is the formula's value; `values` and `lipschitz` as `field`'s."""
    return _formula("profile", formula, lipschitz, values)


# --- records: materials, lights, camera, render --------------------------------------------


class Record:
    """A material, light, camera or render block: its fields as keywords, checked as the
    language checks them."""

    _group = ""
    _kind = ""
    _fields: Dict[str, _Param] = {}
    _painted: Tuple[str, ...] = ()

    def __init__(self, **fields: Any) -> None:
        name = type(self).__name__
        values = {}
        for k, v in fields.items():
            p = self._fields.get(k)
            if p is None:
                raise TypeError(f"sdfc.{name}(): unknown field `{k}` (the fields: {', '.join(self._fields)})")
            if k in self._painted and isinstance(v, Shape) and v._name == "field":
                values[k] = v
                continue
            try:
                v = _conform(v, p.type)
            except _Bad as e:
                why = str(e) or f"must be {_type_words(p.type)}, not {_what(v)}"
                raise TypeError(f"sdfc.{name}(): `{k}` {why}") from None
            if p.checked:
                owner = f"{self._group}:{self._kind}" if self._group in ("material", "light") else self._group
                why = _sdfc.range_error(owner, 0, p.index, _range_value(v))
                if why:
                    raise ValueError(f"sdfc.{name}(): `{k}` {why}, not {_show(v)}")
            values[k] = v
        for p in self._fields.values():
            if p.required and p.name not in values:
                raise TypeError(f"sdfc.{name}(): missing the field `{p.name}`")
        self._values = values
        self._loc = _caller()

    def __getattr__(self, name: str) -> Any:
        fields = type(self)._fields
        if name in fields:
            return self.__dict__["_values"].get(name, fields[name].default)
        raise AttributeError(name)

    def __repr__(self) -> str:
        inner = ", ".join(f"{k}={v!r}" for k, v in self._values.items())
        return f"sdfc.{type(self).__name__}({inner})"


def _class_name(group: str, kind: str) -> str:
    words = "".join(w.capitalize() for w in kind.split("_"))
    return words + "Light" if group == "light" else words


RECORDS: Dict[str, type] = {}
for _r in _sdfc.records():
    _cls_name = _class_name(_r["group"], _r["name"])
    _fields = {p["name"]: _Param(p, i) for i, p in enumerate(_r["fields"])}
    _doc = f"`{_r['group'] + ' ' if _r['group'] == 'light' else ''}{_r['name']} {{ … }}` (docs/language.md): the fields " + ", ".join(
        f"{p.name}: {p.type}" + (f" = {p.default_text}" if p.default_text is not None else "") for p in _fields.values()
    )
    RECORDS[_cls_name] = type(
        _cls_name,
        (Record,),
        {
            "__doc__": _doc,
            "__module__": "sdfc",
            "_group": _r["group"],
            "_kind": _r["name"],
            "_fields": _fields,
            "_painted": tuple(_r["painted"]),
        },
    )


def _settings(camera: Any, lights: Any, render: Any) -> List[Record]:
    out: List[Record] = []
    for what, value, group in (("camera", camera, "camera"), ("render", render, "render")):
        if value is not None:
            if not isinstance(value, Record) or value._group != group:
                raise TypeError(f"`{what}` must be sdfc.{group.capitalize()}(...), not {_what(value)}")
            out.append(value)
    if lights is not None:
        if isinstance(lights, Record):
            lights = [lights]
        for light in lights:
            if not isinstance(light, Record) or light._group != "light":
                raise TypeError(f"`lights` must be lights (sdfc.PointLight(...), sdfc.DirectionalLight(...)), not {_what(light)}")
            out.append(light)
    return out


def _default_lights() -> List[Record]:
    # A key light from above, front and left, and a dim fill from the right.
    return [
        RECORDS["DirectionalLight"](direction=(0.5, -1.0, 0.7), intensity=0.85),
        RECORDS["DirectionalLight"](direction=(-0.8, -0.3, 0.6), intensity=0.3),
    ]


def _framing(shape: Shape) -> Optional[Record]:
    """A camera that looks at the shape's box from the front, above and to its side, with
    the box's bounding sphere in view; None where the box is unbounded or the shape does not
    check (the default camera then, and the errors when it is compiled)."""
    try:
        facts = writing.facts(writing.Text(shape))
    except (CompileError, ValueError, RuntimeError):
        return None
    box = facts.box
    if box is None or not all(math.isfinite(x) for x in box[0] + box[1]):
        return None
    lo, hi = np.array(box[0]), np.array(box[1])
    centre = (lo + hi) / 2
    radius = max(float(np.linalg.norm(hi - lo)) / 2, 1e-3)
    fov = 40.0
    direction = np.array([-0.55, 0.6, -1.0])
    direction /= np.linalg.norm(direction)
    eye = centre + direction * radius / math.sin(math.radians(fov / 2)) * 1.05
    # Rounded to the box's scale: what a person would write.
    digits = max(0, 3 - math.floor(math.log10(radius)))
    return RECORDS["Camera"](position=tuple(round(float(x), digits) for x in eye), look_at=tuple(round(float(x), digits) for x in centre), fov=deg(fov))


def show(shape: Shape, **scene: Any) -> Any:
    """Opens the live viewer (`sdfc view`) on `shape.source(**scene)` and returns its
    process (a `subprocess.Popen`): the `sdfc` binary named by the environment variable
    `SDFC_BIN`, else the one on the PATH. The file it views is kept in a temporary folder
    while the viewer runs."""
    import shutil
    import subprocess
    import tempfile

    if not isinstance(shape, Shape):
        raise TypeError(f"sdfc.show(): `shape` must be a shape, not {_what(shape)}")
    binary = os.environ.get("SDFC_BIN") or shutil.which("sdfc")
    if not binary:
        raise RuntimeError("sdfc.show() runs the `sdfc` command's viewer: put `sdfc` on the PATH (cargo install --path runtime) or name it with SDFC_BIN")
    folder = tempfile.mkdtemp(prefix="sdfc-show-")
    path = os.path.join(folder, "shape.sdf")
    with open(path, "w", encoding="utf-8") as f:
        f.write(shape.source(**scene))
    return subprocess.Popen([binary, "view", path])


def _make(name: str) -> Any:
    b = BUILTINS[name]

    def function(*args: Any, **kwargs: Any) -> Any:
        return _call(name, args, kwargs)

    function.__name__ = function.__qualname__ = name
    function.__module__ = "sdfc"
    function.__doc__ = b.doc
    return function


def _make_method(name: str, cls: type) -> Any:
    b = BUILTINS[name]

    def method(self: Any, *args: Any, **kwargs: Any) -> Any:
        return _call(name, (self,) + args, kwargs, method=True)

    method.__name__ = name
    method.__qualname__ = f"{cls.__name__}.{name}"
    # Marked as the table's (stubs.py tells them from the shape's own methods by it).
    method._table = True  # type: ignore[attr-defined]
    method.__doc__ = b.doc
    return method


FUNCTIONS: Dict[str, Any] = {n: _make(n) for n in SHAPE_BUILTINS}

# Methods: the built-ins whose first parameter takes the shape (or profile) itself, unless
# the name is one of the shape's own (`mesh`, `distance`, …).
for _n in SHAPE_BUILTINS:
    for _cls, _ty in ((Shape, "shape"), (Profile, "profile")):
        if any(s.method == _ty and s.ret in ("shape", "profile") for s in BUILTINS[_n].sigs):
            if _n not in _cls.__dict__ and _n not in _Expr.__dict__:
                setattr(_cls, _n, _make_method(_n, _cls))

# Python keywords cannot be function names; none of the built-ins is one today.
assert not any(keyword.iskeyword(n) for n in FUNCTIONS)


def __getattr__(name: str) -> Any:
    # The generated functions and classes are the module's attributes (`from .model import
    # *` takes them), not its globals: `round` in this file stays Python's.
    found = FUNCTIONS.get(name) or RECORDS.get(name)
    if found is None:
        raise AttributeError(f"module 'sdfc.model' has no attribute {name!r}")
    return found

__all__ = ["Angle", "Path", "Profile", "Record", "Shape", "deg", "field", "profile", "rad", "show"]
__all__ += list(FUNCTIONS) + list(RECORDS)
