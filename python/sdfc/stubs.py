"""The type stubs of the modelling API, `model.pyi`, written from the checker's table of
built-ins and records (the same table `model.py` builds the functions from): one function
(with an overload per form) for each built-in that makes a shape or a profile, a method of
`Shape` or `Profile` where its first parameter takes one, and a keyword class for each
material, light, camera and render record. A test keeps python/sdfc/model.pyi equal to
`generate()`; `python -m sdfc.stubs > python/sdfc/model.pyi` writes it again.
"""

from __future__ import annotations

import textwrap
from typing import List

from . import model

_TYPES = {
    "float": "float",
    "int": "int",
    "bool": "bool",
    "vec2": "Vec2",
    "vec3": "Vec3",
    "angle": "Angle",
    "string": "str",
    "shape": "Shape",
    "profile": "Profile",
    "path": "Path",
}


def _type(ty: str) -> str:
    if ty.startswith("["):
        return f"Sequence[{_type(ty[1:-1])}]"
    return _TYPES[ty]


# The shape's own API (model.py, class Shape), beside the methods of the table.
_SHAPE_OWN = '''
    def __matmul__(self, material: Record) -> Shape: ...
    def source(self, camera: Optional[Camera] = ..., lights: Optional[Sequence[Record]] = ..., render: Optional[Render] = ...) -> str: ...
    def scene(
        self,
        camera: Optional[Camera] = ...,
        lights: Optional[Sequence[Record]] = ...,
        render: Optional[Render] = ...,
        set: Optional[Dict[str, Any]] = ...,
        limits: Optional[Dict[str, int]] = ...,
    ) -> Scene: ...
    def mesh(
        self,
        resolution: Optional[int] = ...,
        bounds: Optional[Sequence[Sequence[float]]] = ...,
        voxel: Optional[float] = ...,
        sharp: bool = ...,
        limits: Optional[Dict[str, int]] = ...,
    ) -> Tuple[np.ndarray, np.ndarray, np.ndarray]: ...
    def save(
        self,
        path: Any,
        resolution: Optional[int] = ...,
        bounds: Optional[Sequence[Sequence[float]]] = ...,
        voxel: Optional[float] = ...,
        sharp: bool = ...,
        limits: Optional[Dict[str, int]] = ...,
        up: Optional[str] = ...,
    ) -> Tuple[int, int]: ...
    def distance(self, points: Any, backend: str = ...) -> np.ndarray: ...
    def facts(self) -> Facts: ...
    def render(
        self,
        size: Optional[Tuple[int, int]] = ...,
        backend: str = ...,
        aa: Optional[int] = ...,
        camera: Optional[Camera] = ...,
        lights: Optional[Sequence[Record]] = ...,
        render: Optional[Render] = ...,
        dtype: Any = ...,
    ) -> np.ndarray: ...
    def png(self, size: Optional[Tuple[int, int]] = ..., backend: str = ..., **scene: Any) -> bytes: ...
    def _repr_png_(self) -> bytes: ...
    def show(self, **scene: Any) -> subprocess.Popen[bytes]: ...
'''

_HEAD = '''# The modelling API's types, generated from the checker's table of built-ins and records by
# python/sdfc/stubs.py (`python -m sdfc.stubs > python/sdfc/model.pyi`); a test keeps it current.
import subprocess
from typing import Any, Dict, List, Optional, Sequence, Tuple, TypeVar, Union, overload

import numpy as np

from . import Facts, Scene

Vec2 = Union[Tuple[float, float], Sequence[float], np.ndarray]
Vec3 = Union[Tuple[float, float, float], Sequence[float], np.ndarray]
_E = TypeVar("_E", bound="_Expr")

class Angle:
    value: float
    unit: str
    def __init__(self, value: float, unit: str = ...) -> None: ...
    @property
    def radians(self) -> float: ...

def deg(x: float) -> Angle: ...
def rad(x: float) -> Angle: ...

class _Expr:
    def __or__(self: _E, other: _E) -> _E: ...
    def __and__(self: _E, other: _E) -> _E: ...
    def __sub__(self: _E, other: _E) -> _E: ...
    def source(self) -> str: ...

class Record: ...

def field(formula: str, lipschitz: Optional[float] = ..., **values: Any) -> Shape: ...
def profile(formula: str, lipschitz: Optional[float] = ..., **values: Any) -> Profile: ...
def show(shape: Shape, **scene: Any) -> subprocess.Popen[bytes]: ...
'''


def _params(sig: "model._Sig", skip: int) -> str:
    out: List[str] = []
    params = sig.params
    defaulted = False
    for i, p in enumerate(params):
        if i < skip:
            continue
        ty = _type(p.type)
        if sig.rest and i + 1 == len(params):
            out.append(f"{p.name}: {ty}")
            out.append(f"*more: {ty}")
            continue
        # A required parameter after one with a default (`arc(radius = 0.5, angle)`, given
        # by name) is written with a default too, as Python asks; the call still needs it.
        defaulted |= not p.required
        out.append(f"{p.name}: {ty}" + (" = ..." if defaulted else ""))
    return ", ".join(out)


def _defs(name: str, sigs: List["model._Sig"], method: bool, doc: str, indent: str) -> List[str]:
    """A def per form (overloads where there are several), the docs on the last."""
    forms: List[str] = []
    for sig in sigs:
        params = _params(sig, 1 if method else 0)
        head = ("self, " + params if params else "self") if method else params
        form = f"({head}) -> {_type(sig.ret)}"
        if form not in forms:
            forms.append(form)
    lines: List[str] = []
    for i, form in enumerate(forms):
        if len(forms) > 1:
            lines.append(f"{indent}@overload")
        if i + 1 < len(forms) or not doc:
            lines.append(f"{indent}def {name}{form}: ...")
        else:
            lines.append(f"{indent}def {name}{form}:")
            lines += _docstring(doc, indent)
    return lines


def _docstring(doc: str, indent: str) -> List[str]:
    text = doc.replace("\\", "\\\\").replace('"""', '\\"""').strip()
    body = textwrap.indent(text, indent + "    ").lstrip()
    return [f'{indent}    """{body}', f'{indent}    """', f"{indent}    ..."]


def generate() -> str:
    """The text of model.pyi."""
    out = [_HEAD]
    shaped = {n: [s for s in model.BUILTINS[n].sigs if s.ret in model._MADE] for n in model.SHAPE_BUILTINS}
    out.append("class Path(_Expr): ...")
    out.append("")
    for cls, ty in (("Profile", "profile"), ("Shape", "shape")):
        out.append(f"class {cls}(_Expr):")
        if cls == "Shape":
            out.append(_SHAPE_OWN.strip("\n"))
        for name, sigs in shaped.items():
            # The methods model.py made from the table (not the shape's own of that name).
            if not getattr(getattr(getattr(model, cls), name, None), "_table", False):
                continue
            mine = [s for s in sigs if s.method == ty]
            out += _defs(name, mine, True, "", "    ")
        out.append("")
    for name, sigs in shaped.items():
        out += _defs(name, sigs, False, model.BUILTINS[name].doc, "")
    out.append("")
    for cls_name, cls in model.RECORDS.items():
        fields = ", ".join(
            f"{p.name}: {_type(p.type) if p.name not in cls._painted else f'Union[{_type(p.type)}, Shape]'}" + ("" if p.required else " = ...")
            for p in cls._fields.values()
        )
        out.append(f"class {cls_name}(Record):")
        out.append(f"    def __init__(self, *, {fields}) -> None: ...")
        out.append("")
    names = ", ".join(f'"{n}"' for n in model.__all__)
    out.append(f"__all__ = [{names}]")
    return "\n".join(out) + "\n"


if __name__ == "__main__":
    print(generate(), end="")
