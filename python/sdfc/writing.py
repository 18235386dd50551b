"""The `.sdf` text of a modelled shape (model.py) and the way back from it: the writer,
which records for each shape the range of text it wrote and the Python line that built it;
the scene compiled from the text as `sdfc fmt` writes it; and its diagnostics placed at
those Python lines (`sdfc fmt` changes only the space between tokens, so a position in the
formatted text is one in the written text).
"""

from __future__ import annotations

import bisect
from typing import Any, Dict, List, Optional, Sequence, Tuple

from . import _sdfc, model
from ._sdfc import CompileError


def num(x: float) -> str:
    """A number as the language reads it: the shortest text that gives it back."""
    if isinstance(x, int):
        return str(x)
    if x.is_integer() and abs(x) < 1e15:
        return str(int(x))
    return repr(x)


ESCAPES = {'"': '\\"', "\\": "\\\\", "\n": "\\n", "\t": "\\t"}


def string(s: str) -> str:
    return '"' + "".join(ESCAPES.get(c, c) for c in s) + '"'


class Text:
    """The `.sdf` text of a shape (with its settings) and, for each node, the range of the
    text it wrote and the Python line that built it."""

    def __init__(self, root: model._Expr, settings: Sequence[model.Record] = (), profile: bool = False) -> None:
        self.root = root
        self.parts: List[str] = []
        self.pos = 0
        self.spans: List[Tuple[int, int, Tuple[str, int]]] = []
        self.loc = model._caller()
        nodes, self.uses = walk(root)
        uses = self.uses
        self.names: Dict[int, str] = {}
        materials: Dict[int, str] = {}
        for n in nodes:
            if n._name == "@":
                m = n._args[1][1]
                if id(m) not in materials:
                    materials[id(m)] = f"m{len(materials) + 1}"
                    self._record(m, f"material {materials[id(m)]} = ", ";\n", materials)
        self.materials = materials
        for s in settings:
            self._record(s, "light " if s._group == "light" else "", "\n", materials)
        # A node used more than once (and not a leaf) is written once, as a `let`: in the
        # scene block, or for a profile alone before it, as constants.
        counts = {"shape": 0, "profile": 0, "path": 0}
        shared = [n for n in nodes if uses[id(n)] > 1 and n._children()]
        indent = "" if profile else "    "
        if not profile:
            self.write("scene {\n")
        for n in shared:
            kind = "profile" if isinstance(n, model.Profile) else "path" if isinstance(n, model.Path) else "shape"
            counts[kind] += 1
            name = f"{kind}{counts[kind]}"
            self.write(f"{indent}let {name} = ")
            self.emit(n)
            self.write(";\n")
            self.names[id(n)] = name
        self.write("let result = " if profile else indent)
        self.body = (self.pos, 0)
        self.emit(root)
        self.body = (self.body[0], self.pos)
        self.write(";\n" if profile else ";\n}\n")
        self.text = "".join(self.parts)

    def expression(self) -> str:
        """The text of the root's expression (shared parts by their names)."""
        return self.text[self.body[0] : self.body[1]]

    def write(self, s: str) -> None:
        self.parts.append(s)
        self.pos += len(s)

    def _record(self, r: model.Record, before: str, after: str, materials: Dict[int, str]) -> None:
        start = self.pos
        head = r._kind if r._group in ("material", "light") else r._group
        self.write(f"{before}{head} {{")
        items = list(r._values.items())
        for i, (k, v) in enumerate(items):
            self.write(f" {k}: ")
            if isinstance(v, model._Expr):
                self.emit(v)
            else:
                self.write(value(v))
            self.write("," if i + 1 < len(items) else " ")
        self.write("}" + after)
        self.spans.append((start, self.pos, r._loc))

    def emit(self, root: model._Expr) -> None:
        """Writes the expression of `root`, without recursion (a chain of a million calls is
        text for the checker's limits to refuse, not a Python stack overflow)."""
        stack: List[Any] = [root]
        while stack:
            item = stack.pop()
            if isinstance(item, str):
                self.write(item)
                continue
            if isinstance(item, End):
                self.spans.append((item.start, self.pos, item.node._loc))
                continue
            name = self.names.get(id(item))
            if name is not None:
                self.write(name)
                continue
            stack.append(End(item, self.pos))
            stack.extend(reversed(self._parts(item)))

    def _parts(self, n: model._Expr) -> List[Any]:
        """The pieces of a node's text, in order: text, and child nodes."""
        if n._name == "@":
            return [n._args[0][1], f" @ {self.materials[id(n._args[1][1])]}"]
        if n._name in ("field", "profile"):
            formula, lipschitz = n._args[0][1], n._args[1][1]
            head = n._name if lipschitz is None else f"{n._name}(lipschitz: {num(lipschitz)})"
            out: List[Any] = [head + " { "]
            for name, v in n._args[2:]:
                out += [f"let {name} = ", piece(v), "; "]
            return out + [formula, " }"]
        args = n._args
        if n._flat and n._name in ("union", "intersect"):
            args = self._flattened(n)
        elif n._flat and n._name == "subtract":
            # a - b - c is subtract(a, union(b, c)): max(a, -min(b, c)) = max(max(a, -b), -c).
            cut, first = [args[1][1]], args[0][1]
            while first._flat and first._name == "subtract" and id(first) not in self.names and self.uses.get(id(first), 1) == 1:
                cut.append(first._args[1][1])
                first = first._args[0][1]
            if len(cut) > 1:
                cut.reverse()
                return ["subtract(", first, ", union(", *joined(cut), "))"]
        out = []
        named = False
        items: List[Any] = []
        previous = -1
        for p, v in args:
            if p is not None and p.index != previous + 1 and p.index > previous:
                named = True
            if p is not None:
                previous = max(previous, p.index)
            items.append(f"{p.name}: " if named and p is not None else "")
            items.append(v if isinstance(v, list) else piece(v))
        if n._method and args and isinstance(args[0][1], model._Expr):
            out = [args[0][1], f".{n._name}("]
            rest = items[2:]
        else:
            out = [f"{n._name}("]
            rest = items
        for i in range(0, len(rest), 2):
            if i:
                out.append(", ")
            if rest[i]:
                out.append(rest[i])
            v = rest[i + 1]
            if isinstance(v, list):
                out += ["[", *joined(v), "]"]
            else:
                out.append(v)
        return out + [")"]

    def _flattened(self, n: model._Expr) -> List[Tuple[Any, Any]]:
        """`(a | b) | c` as `union(a, b, c)` where `a | b` is written nowhere else."""
        tail = []
        while True:
            first, second = n._args[0], n._args[1]
            tail.append(second)
            inner = first[1]
            if inner._flat and inner._name == n._name and id(inner) not in self.names and self.uses.get(id(inner), 1) == 1:
                n = inner
                continue
            tail.append(first)
            break
        tail.reverse()
        return tail


class End:
    """Where a node's text ends, on the writer's stack: its span is then recorded."""

    __slots__ = ("node", "start")

    def __init__(self, node: model._Expr, start: int) -> None:
        self.node = node
        self.start = start


def joined(items: Sequence[Any]) -> List[Any]:
    out: List[Any] = []
    for i, v in enumerate(items):
        if i:
            out.append(", ")
        out.append(piece(v))
    return out


def piece(v: Any) -> Any:
    """A value as a piece of a node's text: a node stays one (its text is written in its
    turn, its span recorded), any other value becomes its text."""
    return v if isinstance(v, model._Expr) else value(v)


def walk(root: model._Expr) -> Tuple[List[model._Expr], Dict[int, int]]:
    """Every node under `root`, children before parents, and how many parents use each."""
    uses: Dict[int, int] = {id(root): 1}
    order: List[model._Expr] = []
    seen = {id(root)}
    stack: List[Tuple[model._Expr, bool]] = [(root, False)]
    while stack:
        node, done = stack.pop()
        if done:
            order.append(node)
            continue
        stack.append((node, True))
        for c in reversed(node._children()):
            uses[id(c)] = uses.get(id(c), 0) + 1
            if id(c) not in seen:
                seen.add(id(c))
                stack.append((c, False))
    return order, uses


def value(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, (int, float)):
        return num(v)
    if isinstance(v, tuple):
        return "(" + ", ".join(num(c) for c in v) + ")"
    if isinstance(v, model.Angle):
        n = num(v.value)
        if "e" in n:
            return f"degrees({n})" if v.unit == "deg" else f"({n} * 1rad)"
        return n + v.unit
    if isinstance(v, str):
        return string(v)
    if isinstance(v, list):
        return "[" + ", ".join(value(x) for x in v) + "]"
    raise TypeError(f"cannot write {v!r}")


def fmt(text: str) -> str:
    return _sdfc.fmt(text) or text


def located(text: Text, formatted: str, diags: List[Any], fallback: str) -> CompileError:
    """A `CompileError` of the diagnostics `diags` of the formatted text, its first error
    placed at the Python line that built the shape its span falls in (`.python`, and the
    message's head; `.locations` has one per diagnostic), the diagnostics kept."""
    located = []
    mapping = Alignment(formatted, text.text)
    for d in diags:
        where = None
        if d.line > 0 and d.file == TEXT_NAME:
            at = mapping.offset(d.line, d.column)
            inner = [s for s in text.spans if s[0] <= at < max(s[1], s[0] + 1)]
            if inner:
                where = min(inner, key=lambda s: s[1] - s[0])[2]
        located.append(where or text.loc)
    first = next((i for i, d in enumerate(diags) if d.severity == "error"), 0)
    if diags:
        d, (file, line) = diags[first], located[first]
        span = f" (at `{d.span_text}`)" if d.span_text and len(d.span_text) <= 80 else ""
        message = f"{file}:{line}: {d.severity}[{d.code}]: {d.message}{span}"
    else:
        (file, line) = text.loc
        message = f"{file}:{line}: {fallback}"
    out = CompileError(message)
    out.diagnostics = list(diags)
    out.python = (file, line)
    out.locations = located
    out.source = formatted
    return out


TEXT_NAME = "<string>.sdf"


class Alignment:
    """Positions of the formatted text in the written one: `sdfc fmt` changes only the
    space between tokens, so the n-th character that is not a space is the same in both."""

    def __init__(self, formatted: str, written: str) -> None:
        self.formatted = formatted
        self.same = formatted == written
        f = [i for i, c in enumerate(formatted) if not c.isspace()]
        w = [i for i, c in enumerate(written) if not c.isspace()]
        self.f, self.w = f, w
        self.ok = len(f) == len(w)
        self.starts = [0]
        for i, c in enumerate(formatted):
            if c == "\n":
                self.starts.append(i + 1)

    def offset(self, line: int, column: int) -> int:
        at = self.starts[min(line, len(self.starts)) - 1] + column - 1
        if self.same or not self.ok:
            return at


        k = bisect.bisect_left(self.f, at)
        return self.w[k] if k < len(self.w) else len(self.w)


def compiled(text: Text, set: Optional[Dict[str, Any]], limits: Optional[Dict[str, int]]) -> Any:
    """The `sdfc.Scene` of the text as `sdfc fmt` writes it; its errors, now and when it
    is rendered or meshed, are placed at the Python lines."""
    from . import Scene

    formatted = fmt(text.text)

    def locate(error: CompileError) -> CompileError:
        return located(text, formatted, getattr(error, "diagnostics", []), str(error))

    return Scene(source=formatted, set=set, limits=limits, _locate=locate)


def facts(text: Text) -> Any:
    from . import check

    formatted = fmt(text.text)
    diags, facts = check(source=formatted)
    if facts is None:
        raise located(text, formatted, diags, "the shape has errors")
    return facts
