"""The type stubs of the modelling API, `model.pyi`, written from the checker's table of
built-ins and records (the same table `model.py` builds the functions from): one function
(with an overload per form) for each built-in that makes a shape or a profile, a method of
`Shape` or `Profile` where its first parameter takes one, and a keyword class for each
material, light, camera and render record; model.pyi's head and the shape's own methods are
written by hand there, and kept. A test keeps python/sdfc/model.pyi equal to `generate()`;
`python -m sdfc.stubs python/sdfc/model.pyi` writes it again.
"""

from __future__ import annotations

import sys
import textwrap
from pathlib import Path
from typing import List, Optional, Tuple

from . import model


def _type(ty: str) -> str:
    if ty.startswith("["):
        return f"Sequence[{_type(ty[1:-1])}]"
    return model._TYPES[ty][0]


# model.pyi's parts written by hand, kept as they are there: its head (to the first class of
# the table, `Path`) and the shape's own API (model.py, class Shape) before the methods of the
# table, which start at `_OWN_END`.
_HEAD_END = "class Path(_Expr): ..."
_SHAPE = "class Shape(_Expr):"
_OWN_END = "    # The methods of the table of built-ins:"


def _written_by_hand(text: str) -> Tuple[str, str]:
    """The head and the shape's own methods of `text`, a model.pyi."""
    head, found, rest = text.partition(_HEAD_END + "\n")
    own = rest.partition("\n" + _SHAPE + "\n")[2].partition("\n" + _OWN_END + "\n")[0]
    if not found or not own:
        raise ValueError("model.pyi has lost its parts written by hand (its head, the shape's own methods): git checkout python/sdfc/model.pyi")
    return head, own


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


def generate(pyi: Optional[Path] = None) -> str:
    """The text of model.pyi, its parts written by hand read from `pyi` (this package's)."""
    head, own = _written_by_hand((pyi or Path(__file__).with_name("model.pyi")).read_text())
    out = [head.removesuffix("\n")]
    shaped = {n: [s for s in model.BUILTINS[n].sigs if s.ret in model._MADE] for n in model.SHAPE_BUILTINS}
    out.append("class Path(_Expr): ...")
    out.append("")
    for cls, ty in (("Profile", "profile"), ("Shape", "shape")):
        out.append(f"class {cls}(_Expr):")
        if cls == "Shape":
            out += [own, _OWN_END]
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
    # `python -m sdfc.stubs FILE` writes FILE (python/sdfc/model.pyi) again, keeping its parts
    # written by hand; without FILE, the text is printed, those parts taken from this package's.
    if len(sys.argv) > 1:
        target = Path(sys.argv[1])
        target.write_text(generate(target))
    else:
        print(generate(), end="")
