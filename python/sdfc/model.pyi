# The modelling API's types, generated from the checker's table of built-ins and records by
# python/sdfc/stubs.py (`python -m sdfc.stubs python/sdfc/model.pyi`), which keeps this head and
# the shape's own methods as they are written here; a test keeps it current.
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

class Path(_Expr): ...

class Profile(_Expr):
    def extrude(self, height: float, round: float = ...) -> Shape: ...
    def revolve(self, offset: float = ...) -> Shape: ...
    def sweep(self, path: Path) -> Shape: ...
    def loft(self, top: Profile, height: float) -> Shape: ...
    def screw(self, pitch: float, height: float, hand: str = ...) -> Shape: ...
    def offset(self, amount: float) -> Profile: ...
    def union(self, b: Profile, *more: Profile) -> Profile: ...
    def intersect(self, b: Profile, *more: Profile) -> Profile: ...
    def subtract(self, b: Profile) -> Profile: ...
    @overload
    def translate(self, offset: Vec2) -> Profile: ...
    @overload
    def translate(self, x: float, y: float = ...) -> Profile: ...
    def rotate(self, angle: Angle) -> Profile: ...
    def scale(self, factor: float) -> Profile: ...
    def mirror(self, x: bool = ..., y: bool = ...) -> Profile: ...
    def reflect(self, normal: Vec2) -> Profile: ...
    def repeat_polar(self, count: int, mirror: bool = ...) -> Profile: ...

class Shape(_Expr):
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
    # The methods of the table of built-ins:
    def union(self, b: Shape, *more: Shape) -> Shape: ...
    def intersect(self, b: Shape, *more: Shape) -> Shape: ...
    def subtract(self, b: Shape) -> Shape: ...
    def engrave(self, b: Shape, depth: float) -> Shape: ...
    def groove(self, b: Shape, width: float, depth: float) -> Shape: ...
    def tongue(self, b: Shape, width: float, height: float) -> Shape: ...
    def pipe(self, b: Shape, radius: float) -> Shape: ...
    @overload
    def translate(self, offset: Vec3) -> Shape: ...
    @overload
    def translate(self, x: float, y: float = ..., z: float = ...) -> Shape: ...
    def rotate_x(self, angle: Angle) -> Shape: ...
    def rotate_y(self, angle: Angle) -> Shape: ...
    def rotate_z(self, angle: Angle) -> Shape: ...
    def rotate(self, axis: Vec3, angle: Angle) -> Shape: ...
    @overload
    def scale(self, factor: float) -> Shape: ...
    @overload
    def scale(self, factors: Vec3) -> Shape: ...
    @overload
    def repeat(self, period: Vec3) -> Shape: ...
    @overload
    def repeat(self, period: Vec3, count: Vec3) -> Shape: ...
    def mirror(self, x: bool = ..., y: bool = ..., z: bool = ...) -> Shape: ...
    def reflect(self, normal: Vec3) -> Shape: ...
    def twist(self, rate: float) -> Shape: ...
    def bend(self, rate: float) -> Shape: ...
    def repeat_polar(self, count: int, axis: Vec3 = ..., mirror: bool = ...) -> Shape: ...
    def wrap(self, radius: float) -> Shape: ...
    def shear(self, xy: float = ..., xz: float = ..., yx: float = ..., yz: float = ..., zx: float = ..., zy: float = ...) -> Shape: ...
    def taper(self, rate: float) -> Shape: ...
    def morph(self, b: Shape, t: float) -> Shape: ...
    def round(self, radius: float) -> Shape: ...
    def hull(self) -> Shape: ...
    def minkowski(self, ball: Shape) -> Shape: ...
    def shell(self, thickness: float) -> Shape: ...
    def elongate(self, half: Vec3) -> Shape: ...

def sphere(radius: float = ...) -> Shape:
    """```sdf
    sphere(radius: float = 1) -> shape
    ```
    Valid: `radius` > 0

    A sphere centred on the origin.
    """
    ...
@overload
def box(half: Vec3) -> Shape: ...
@overload
def box(half: float = ...) -> Shape:
    """```sdf
    box(half: vec3) -> shape
    ```
    Valid: `half` > 0

    A box of half-extents `half` (a vec3, or one number for a cube).

    ```sdf
    box(half: float = 0.5) -> shape
    ```
    Valid: `half` > 0
    """
    ...
def round_box(half: Vec3, radius: float = ...) -> Shape:
    """```sdf
    round_box(half: vec3, radius: float = 0.05) -> shape
    ```
    Valid: `half` > 0; `radius` ≥ 0

    A box with edges rounded by `radius`, which lies inside the half-extents (it must not exceed any of them).
    """
    ...
def plane(normal: Vec3 = ..., height: float = ...) -> Shape:
    """```sdf
    plane(normal: vec3 = (0, 1, 0), height: float = 0) -> shape
    ```
    Valid: `normal` not (0, 0, 0)

    The half-space below the plane `dot(p, normal) = height`; `normal` is normalised.
    """
    ...
def torus(major: float = ..., minor: float = ...) -> Shape:
    """```sdf
    torus(major: float = 1, minor: float = 0.25) -> shape
    ```
    Valid: `major` > 0; `minor` > 0

    A torus in the xz plane: ring radius `major`, tube radius `minor`.
    """
    ...
@overload
def cylinder(radius: float = ..., height: float = ...) -> Shape: ...
@overload
def cylinder(a: Vec3, b: Vec3, radius: float = ...) -> Shape:
    """```sdf
    cylinder(radius: float = 0.5, height: float = 1) -> shape
    ```
    Valid: `radius` > 0; `height` > 0

    A capped cylinder along y, `height` tall in all, centred on the origin.

    ```sdf
    cylinder(a: vec3, b: vec3, radius: float = 0.5) -> shape
    ```
    Valid: `a` ≠ `b`; `radius` > 0

    A capped cylinder whose axis runs from the point `a` to the point `b`. Exact.
    """
    ...
def capsule(radius: float = ..., height: float = ...) -> Shape:
    """```sdf
    capsule(radius: float = 0.25, height: float = 1) -> shape
    ```
    Valid: `radius` > 0; `height` ≥ 0

    A capsule along y: a segment `height` long, swept by `radius`.
    """
    ...
@overload
def cone(radius: float = ..., height: float = ...) -> Shape: ...
@overload
def cone(a: Vec3, b: Vec3, radius_a: float = ..., radius_b: float = ...) -> Shape:
    """```sdf
    cone(radius: float = 0.5, height: float = 1) -> shape
    ```
    Valid: `radius` > 0; `height` > 0

    A capped cone along y: base of `radius` at `-height/2`, tip at `height/2`.

    ```sdf
    cone(a: vec3, b: vec3, radius_a: float = 0.5, radius_b: float = 0) -> shape
    ```
    Valid: `a` ≠ `b`; `radius_a`, `radius_b` ≥ 0, not both 0

    A cone (a frustum where both radii are above 0) whose axis runs from `a`, where its radius is `radius_a`, to `b`, where it is `radius_b`. Exact.
    """
    ...
def ellipsoid(radii: Vec3) -> Shape:
    """```sdf
    ellipsoid(radii: vec3) -> shape
    ```
    Valid: `radii` > 0

    An axis-aligned ellipsoid of radii `radii` (a bound, not an exact distance).
    """
    ...
def mesh(path: str, scale: float = ...) -> Shape:
    """```sdf
    mesh(path: string, scale: float = 1) -> shape
    ```
    Valid: `path` ends in `.stl`, `.obj`, `.ply` or `.glb`; `scale` > 0

    A triangle mesh read from a file, relative to the file that calls it as imports are: STL (binary or ASCII), OBJ, PLY (ASCII or binary) or binary glTF, its coordinates times `scale`. The exact signed distance to the nearest triangle; the inside is told by the angle-weighted pseudo-normals, so the mesh should be closed (W0015 says where it is not). docs/mesh.md, "Import".
    """
    ...
@overload
def rect(half: Vec2) -> Profile: ...
@overload
def rect(half: float = ...) -> Profile:
    """```sdf
    rect(half: vec2) -> profile
    ```
    Valid: `half` > 0

    A rectangle of half-extents `half` (or a square), centred. Exact.

    ```sdf
    rect(half: float = 0.5) -> profile
    ```
    Valid: `half` > 0
    """
    ...
def polygon(points: Sequence[Vec2]) -> Profile:
    """```sdf
    polygon(points: [vec2]) -> profile
    ```
    Valid: three or more points, not on one line, edges not crossing

    The simple polygon through `points`, either winding (§9c). Exact.
    """
    ...
def text(string: str, size: float = ..., font: str = ...) -> Profile:
    """```sdf
    text(string: string, size: float = 1, font: string = "") -> profile
    ```
    Valid: `size` > 0; a string with a visible glyph, every character in the font; `font` a TrueType file

    The glyphs of `string`, the em `size` high, in DejaVu Sans or the font file `font` names (relative to the scene), kerned, centred, reading left to right towards −x (§9c). Exact.
    """
    ...
def regular_polygon(sides: int, radius: float = ...) -> Profile:
    """```sdf
    regular_polygon(sides: int, radius: float = 0.5) -> profile
    ```
    Valid: `sides` 3 … 10000; `radius` > 0

    A regular polygon with its corners `radius` from the centre, one on +y. Exact.
    """
    ...
def star(points: int, outer: float = ..., inner: float = ...) -> Profile:
    """```sdf
    star(points: int, outer: float = 0.5, inner: float = 0.25) -> profile
    ```
    Valid: `points` 2 … 10000; radii > 0

    A star of `points` tips `outer` from the centre (one on +y) and dents `inner` from it. Exact.
    """
    ...
def ring(radius: float = ..., thickness: float = ...) -> Profile:
    """```sdf
    ring(radius: float = 0.5, thickness: float = 0.1) -> profile
    ```
    Valid: both > 0

    The band `thickness` wide about the circle of `radius`. Exact.
    """
    ...
def segment2(a: Vec2, b: Vec2, radius: float = ...) -> Profile:
    """```sdf
    segment2(a: vec2, b: vec2, radius: float = 0.1) -> profile
    ```
    Valid: `radius` > 0

    The points within `radius` of the segment from `a` to `b` (a 2D capsule). Exact.
    """
    ...
def extrude(profile: Profile, height: float, round: float = ...) -> Shape:
    """```sdf
    extrude(profile: profile, height: float, round: float = 0) -> shape
    ```
    Valid: `height` > 0; `round` ≥ 0 and at most `height` / 2

    The profile swept along z over `height`, centred, its top and bottom edges rounded by `round` (§9c). Exact as the profile is, for `round` 0.
    """
    ...
def revolve(profile: Profile, offset: float = ...) -> Shape:
    """```sdf
    revolve(profile: profile, offset: float = 0) -> shape
    ```
    The profile turned about the y axis, its x the distance from the axis less `offset` (§9c).
    """
    ...
@overload
def bezier(a: Vec2, control: Vec2, b: Vec2, radius: float = ...) -> Profile: ...
@overload
def bezier(points: Sequence[Vec3]) -> Path:
    """```sdf
    bezier(a: vec2, control: vec2, b: vec2, radius: float = 0.05) -> profile
    ```
    Valid: `radius` > 0; `control` not the midpoint of `a` and `b`

    The points within `radius` of the quadratic Bézier curve from `a` to `b` pulled towards `control`, as `segment2` is of a segment (§9c). Exact.

    ```sdf
    bezier(points: [vec3]) -> path
    ```
    Valid: 3k + 1 points (k ≥ 1); no control point on its curve's end

    Cubic Bézier curves, each through 4 of the points, the next starting at the last one's end; closed where the last point is the first.
    """
    ...
def sweep(profile: Profile, path: Path) -> Shape:
    """```sdf
    sweep(profile: profile, path: path) -> shape
    ```
    Valid: the profile of finite extent

    The profile moved along the path, its plane normal to the path on a rotation-minimising frame, closed paths joined without a seam, open ends cut flat (§9c, "Sweeps"). Exact for a `circle`; otherwise a bound, with L as §9c says, or not proven where the profile reaches past the path's reach (W0018).
    """
    ...
def polyline(points: Sequence[Vec3]) -> Path:
    """```sdf
    polyline(points: [vec3]) -> path
    ```
    Valid: two or more points, no two in a row equal, no corner turning straight back

    The path through the points; closed where the last is the first.
    """
    ...
def helix(radius: float, pitch: float, turns: float) -> Path:
    """```sdf
    helix(radius: float, pitch: float, turns: float) -> path
    ```
    Valid: all > 0

    The right-handed helix about y from (`radius`, −h/2, 0) to y = h/2, h = `pitch`·`turns`.
    """
    ...
def arc3(start: Vec3, through: Vec3, end: Vec3) -> Path:
    """```sdf
    arc3(start: vec3, through: vec3, end: vec3) -> path
    ```
    Valid: three points not on one line

    The arc of the circle through the three points, from `start` to `end` by way of `through`.
    """
    ...
def loft(bottom: Profile, top: Profile, height: float) -> Shape:
    """```sdf
    loft(bottom: profile, top: profile, height: float) -> shape
    ```
    Valid: `height` > 0; both profiles of finite extent

    The solid from `bottom` at z = −`height`/2 to `top` at z = +`height`/2, its section at each height the profiles' fields mixed by the height's fraction (§9c). The extrusion of the profile when both are one. Not exact: L as §9c says.
    """
    ...
def screw(profile: Profile, pitch: float, height: float, hand: str = ...) -> Shape:
    """```sdf
    screw(profile: profile, pitch: float, height: float, hand: string = "right") -> shape
    ```
    Valid: `pitch`, `height` > 0; the profile at x > 0 and within y = ±`pitch`/2; `hand` `"right"` or `"left"`

    A thread: the profile, in the half-plane of `revolve` (x the distance from the y axis), swept along a right-handed helix (or, with `hand: "left"`, its mirror image) rising `pitch` per turn and cut to \\|y\\| ≤ `height`/2 (§9c). Not exact: L as §9c says.
    """
    ...
def offset(profile: Profile, amount: float) -> Profile:
    """```sdf
    offset(profile: profile, amount: float) -> profile
    ```
    The profile grown outwards by `amount` (its corners rounded), or inset by −`amount` where it is negative (its corners kept sharp, its holes grown). A bound: an inset of an exact profile is exact inside.
    """
    ...
@overload
def union(a: Shape, b: Shape, *more: Shape) -> Shape: ...
@overload
def union(shapes: Sequence[Shape]) -> Shape: ...
@overload
def union(a: Profile, b: Profile, *more: Profile) -> Profile: ...
@overload
def union(profiles: Sequence[Profile]) -> Profile:
    """```sdf
    union(a: shape, b...: shape) -> shape
    ```
    The union of two or more shapes.

    ```sdf
    union(shapes: [shape]) -> shape
    ```
    Valid: not empty

    The union of a list of shapes: the same as giving them one by one (§6a).

    ```sdf
    union(a: profile, b...: profile) -> profile
    ```
    The union of two or more profiles.

    ```sdf
    union(profiles: [profile]) -> profile
    ```
    Valid: not empty

    The union of a list of profiles.
    """
    ...
@overload
def intersect(a: Shape, b: Shape, *more: Shape) -> Shape: ...
@overload
def intersect(shapes: Sequence[Shape]) -> Shape: ...
@overload
def intersect(a: Profile, b: Profile, *more: Profile) -> Profile: ...
@overload
def intersect(profiles: Sequence[Profile]) -> Profile:
    """```sdf
    intersect(a: shape, b...: shape) -> shape
    ```
    The intersection of two or more shapes.

    ```sdf
    intersect(shapes: [shape]) -> shape
    ```
    Valid: not empty

    The intersection of a list of shapes.

    ```sdf
    intersect(a: profile, b...: profile) -> profile
    ```
    The intersection of two or more profiles.

    ```sdf
    intersect(profiles: [profile]) -> profile
    ```
    Valid: not empty

    The intersection of a list of profiles.
    """
    ...
@overload
def subtract(a: Shape, b: Shape) -> Shape: ...
@overload
def subtract(a: Profile, b: Profile) -> Profile:
    """```sdf
    subtract(a: shape, b: shape) -> shape
    ```
    `a` with `b` cut away.

    ```sdf
    subtract(a: profile, b: profile) -> profile
    ```
    """
    ...
@overload
def smooth_union(k: float, a: Shape, b: Shape, variant: str = ..., steps: int = ...) -> Shape: ...
@overload
def smooth_union(k: float, a: Profile, b: Profile, variant: str = ..., steps: int = ...) -> Profile: ...
@overload
def smooth_union(k: float, profiles: Sequence[Profile], variant: str = ..., steps: int = ...) -> Profile: ...
@overload
def smooth_union(k: float, shapes: Sequence[Shape], variant: str = ..., steps: int = ...) -> Shape:
    """```sdf
    smooth_union(k: float, a: shape, b: shape, variant: string = "poly", steps: int = 4) -> shape
    ```
    Valid: `k` ≥ 0; `variant` "poly", "exp", "chamfer", "round", "stairs" or "columns"; `steps` 1 … 64

    Union blended over a radius `k` (0: the plain union, which an animated radius may pass through); `variant` "poly" (quadratic, default) or "exp" (exponential) smooth minima, or the edges of Mercury's hg_sdf library: "chamfer" (a 45° bevel `k` wide), "round" (a quarter circle of radius `k`), "stairs" (`steps` steps within `k`), "columns" (`steps` round columns within `k`). `steps` is read by "stairs" and "columns" only.

    ```sdf
    smooth_union(k: float, a: profile, b: profile, variant: string = "poly", steps: int = 4) -> profile
    ```
    Valid: as for shapes

    The blends of shapes, of profiles.

    ```sdf
    smooth_union(k: float, profiles: [profile], variant: string = "poly", steps: int = 4) -> profile
    ```
    Valid: as for shapes

    ```sdf
    smooth_union(k: float, shapes: [shape], variant: string = "poly", steps: int = 4) -> shape
    ```
    Valid: `k` ≥ 0; not empty

    The left fold of the binary form over the list; independent of the list's order only with `variant: "exp"` (§6a).
    """
    ...
@overload
def smooth_intersect(k: float, a: Shape, b: Shape, variant: str = ..., steps: int = ...) -> Shape: ...
@overload
def smooth_intersect(k: float, a: Profile, b: Profile, variant: str = ..., steps: int = ...) -> Profile: ...
@overload
def smooth_intersect(k: float, profiles: Sequence[Profile], variant: str = ..., steps: int = ...) -> Profile: ...
@overload
def smooth_intersect(k: float, shapes: Sequence[Shape], variant: str = ..., steps: int = ...) -> Shape:
    """```sdf
    smooth_intersect(k: float, a: shape, b: shape, variant: string = "poly", steps: int = 4) -> shape
    ```
    Valid: `k` ≥ 0; `variant` and `steps` as for `smooth_union`

    Intersection blended over `k`; `variant` as for `smooth_union`.

    ```sdf
    smooth_intersect(k: float, a: profile, b: profile, variant: string = "poly", steps: int = 4) -> profile
    ```
    Valid: as for shapes

    ```sdf
    smooth_intersect(k: float, profiles: [profile], variant: string = "poly", steps: int = 4) -> profile
    ```
    Valid: as for shapes

    ```sdf
    smooth_intersect(k: float, shapes: [shape], variant: string = "poly", steps: int = 4) -> shape
    ```
    Valid: `k` ≥ 0; not empty

    The left fold of the binary form over the list, as for `smooth_union`.
    """
    ...
@overload
def smooth_subtract(k: float, a: Shape, b: Shape, variant: str = ..., steps: int = ...) -> Shape: ...
@overload
def smooth_subtract(k: float, a: Profile, b: Profile, variant: str = ..., steps: int = ...) -> Profile:
    """```sdf
    smooth_subtract(k: float, a: shape, b: shape, variant: string = "poly", steps: int = 4) -> shape
    ```
    Valid: `k` ≥ 0; `variant` and `steps` as for `smooth_union`

    Subtraction blended over `k`; `variant` as for `smooth_union`.

    ```sdf
    smooth_subtract(k: float, a: profile, b: profile, variant: string = "poly", steps: int = 4) -> profile
    ```
    Valid: as for shapes
    """
    ...
def engrave(a: Shape, b: Shape, depth: float) -> Shape:
    """```sdf
    engrave(a: shape, b: shape, depth: float) -> shape
    ```
    Valid: `depth` > 0

    `a` with a V-shaped cut `depth` deep where `b`'s surface crosses it (hg_sdf's `fOpEngrave`).
    """
    ...
def groove(a: Shape, b: Shape, width: float, depth: float) -> Shape:
    """```sdf
    groove(a: shape, b: shape, width: float, depth: float) -> shape
    ```
    Valid: `width` > 0; `depth` > 0

    `a` with a square groove `width` wide and `depth` deep along `b`'s surface (hg_sdf's `fOpGroove`).
    """
    ...
def tongue(a: Shape, b: Shape, width: float, height: float) -> Shape:
    """```sdf
    tongue(a: shape, b: shape, width: float, height: float) -> shape
    ```
    Valid: `width` > 0; `height` > 0

    `a` with a square ridge `width` wide standing `height` out of it along `b`'s surface (hg_sdf's `fOpTongue`).
    """
    ...
def pipe(a: Shape, b: Shape, radius: float) -> Shape:
    """```sdf
    pipe(a: shape, b: shape, radius: float) -> shape
    ```
    Valid: `radius` > 0

    A tube of `radius` along the curve where the surfaces of `a` and `b` meet; neither shape remains (hg_sdf's `fOpPipe`). It has `a`'s material.
    """
    ...
@overload
def translate(shape: Shape, offset: Vec3) -> Shape: ...
@overload
def translate(shape: Shape, x: float, y: float = ..., z: float = ...) -> Shape: ...
@overload
def translate(profile: Profile, offset: Vec2) -> Profile: ...
@overload
def translate(profile: Profile, x: float, y: float = ...) -> Profile:
    """```sdf
    translate(shape: shape, offset: vec3) -> shape
    ```
    Moves a shape by a vector, or by `x`, `y`, `z`.

    ```sdf
    translate(shape: shape, x: float, y: float = 0, z: float = 0) -> shape
    ```
    ```sdf
    translate(profile: profile, offset: vec2) -> profile
    ```
    Moves a profile by a vector, or by `x`, `y`.

    ```sdf
    translate(profile: profile, x: float, y: float = 0) -> profile
    ```
    """
    ...
def rotate_x(shape: Shape, angle: Angle) -> Shape:
    """```sdf
    rotate_x(shape: shape, angle: angle) -> shape
    ```
    Rotates a shape about the x axis.
    """
    ...
def rotate_y(shape: Shape, angle: Angle) -> Shape:
    """```sdf
    rotate_y(shape: shape, angle: angle) -> shape
    ```
    Rotates a shape about the y axis.
    """
    ...
def rotate_z(shape: Shape, angle: Angle) -> Shape:
    """```sdf
    rotate_z(shape: shape, angle: angle) -> shape
    ```
    Rotates a shape about the z axis.
    """
    ...
@overload
def rotate(shape: Shape, axis: Vec3, angle: Angle) -> Shape: ...
@overload
def rotate(profile: Profile, angle: Angle) -> Profile:
    """```sdf
    rotate(shape: shape, axis: vec3, angle: angle) -> shape
    ```
    Valid: `axis` not (0, 0, 0)

    Rotates a shape about `axis` (normalised) by `angle`.

    ```sdf
    rotate(profile: profile, angle: angle) -> profile
    ```
    Rotates a profile about the origin, counter-clockwise.
    """
    ...
@overload
def scale(shape: Shape, factor: float) -> Shape: ...
@overload
def scale(profile: Profile, factor: float) -> Profile: ...
@overload
def scale(shape: Shape, factors: Vec3) -> Shape:
    """```sdf
    scale(shape: shape, factor: float) -> shape
    ```
    Valid: `factor` > 0

    Scales a shape uniformly (exact), or per axis (the field becomes a bound).

    ```sdf
    scale(profile: profile, factor: float) -> profile
    ```
    Valid: `factor` > 0

    Scales a profile uniformly (exact).

    ```sdf
    scale(shape: shape, factors: vec3) -> shape
    ```
    Valid: `factors` > 0
    """
    ...
@overload
def repeat(shape: Shape, period: Vec3) -> Shape: ...
@overload
def repeat(shape: Shape, period: Vec3, count: Vec3) -> Shape:
    """```sdf
    repeat(shape: shape, period: vec3) -> shape
    ```
    Valid: `period` ≥ 0

    Repeats a shape with a period per axis (0: no repetition on that axis), forever or `count` copies per axis (whole numbers).

    ```sdf
    repeat(shape: shape, period: vec3, count: vec3) -> shape
    ```
    Valid: `period` ≥ 0; `count` 1 … 1000000
    """
    ...
@overload
def mirror(shape: Shape, x: bool = ..., y: bool = ..., z: bool = ...) -> Shape: ...
@overload
def mirror(profile: Profile, x: bool = ..., y: bool = ...) -> Profile:
    """```sdf
    mirror(shape: shape, x: bool = true, y: bool = false, z: bool = false) -> shape
    ```
    A symmetric fold across the planes x = 0, y = 0, z = 0 that are set: the point is folded onto the positive side, so the shape's part there is kept and copied onto the other side, and its part at negative coordinates is dropped (a shape on both sides of a plane gets a second, overlapping half). For the shape's mirror image use `reflect`.

    ```sdf
    mirror(profile: profile, x: bool = true, y: bool = false) -> profile
    ```
    A symmetric fold across x = 0 and/or y = 0: the side of positive coordinates is kept and copied onto the other side (what lies at negative coordinates is dropped). For one reflected copy use `reflect`.
    """
    ...
@overload
def reflect(shape: Shape, normal: Vec3) -> Shape: ...
@overload
def reflect(profile: Profile, normal: Vec2) -> Profile:
    """```sdf
    reflect(shape: shape, normal: vec3) -> shape
    ```
    Valid: `normal` not (0, 0, 0)

    The shape's mirror image across the plane through the origin with that normal (`shape.reflect((1, 0, 0))` flips x): one copy, nothing folded; a right-handed thread becomes left-handed. Exact as the shape is.

    ```sdf
    reflect(profile: profile, normal: vec2) -> profile
    ```
    Valid: `normal` not (0, 0)

    The mirror image of a profile across the line through the origin with that normal: one copy, nothing folded. Exact as the profile is.
    """
    ...
def twist(shape: Shape, rate: float) -> Shape:
    """```sdf
    twist(shape: shape, rate: float) -> shape
    ```
    Twists a shape about y by `rate` radians per unit of height.
    """
    ...
def bend(shape: Shape, rate: float) -> Shape:
    """```sdf
    bend(shape: shape, rate: float) -> shape
    ```
    Bends a shape in the xy plane by `rate` radians per unit of x.
    """
    ...
@overload
def repeat_polar(shape: Shape, count: int, axis: Vec3 = ..., mirror: bool = ...) -> Shape: ...
@overload
def repeat_polar(profile: Profile, count: int, mirror: bool = ...) -> Profile:
    """```sdf
    repeat_polar(shape: shape, count: int, axis: vec3 = (0, 1, 0), mirror: bool = false) -> shape
    ```
    Valid: `count` 1 … 1000000; `axis` not (0, 0, 0); `count` even with `mirror`

    `count` copies of a shape around `axis` (through the origin), 360°/`count` apart: the shape as given is the copy at angle 0 (so translate it along +x first, for the y axis), the others turned as `rotate(shape, axis, k·360deg/count)`. With `mirror: true` every other copy is reflected across its own plane through the axis, so that neighbours face each other. The copies in the point's sector and as many neighbouring sectors as the shape reaches into are evaluated, so a shape wider than its sector stays exact near its surface (docs/analysis.md).

    ```sdf
    repeat_polar(profile: profile, count: int, mirror: bool = false) -> profile
    ```
    Valid: `count` 1 … 1000000; `count` even with `mirror`

    `count` copies of a profile about the origin, 360°/`count` apart, the profile as given the copy at angle 0; as `repeat_polar` of shapes about z.
    """
    ...
def wrap(shape: Shape, radius: float) -> Shape:
    """```sdf
    wrap(shape: shape, radius: float) -> shape
    ```
    Valid: `radius` > 0

    Wraps a shape's x axis around the circle of `radius` about the y axis (in the xz plane): the point (x, y, z) of the shape goes to angle x/`radius` on the circle, `z` towards the centre, so a bar of length 2π·`radius` along x (centred on the origin) closes into a ring centred on the origin. A bound, divided by its stretch `radius`/(`radius` − z_max) over the shape; a shape longer than the circle or reaching the axis (z ≥ `radius`) folds (W0014).
    """
    ...
def shear(shape: Shape, xy: float = ..., xz: float = ..., yx: float = ..., yz: float = ..., zx: float = ..., zy: float = ...) -> Shape:
    """```sdf
    shear(shape: shape, xy: float = 0, xz: float = 0, yx: float = 0, yz: float = 0, zx: float = 0, zy: float = 0) -> shape
    ```
    Valid: not singular

    Shears a shape: its point (x, y, z) moves to (x + xy·y + xz·z, yx·x + y + yz·z, zx·x + zy·y + z). A bound, the field multiplied by the map's smallest stretch (W0007 when the largest is ten times it).
    """
    ...
def taper(shape: Shape, rate: float) -> Shape:
    """```sdf
    taper(shape: shape, rate: float) -> shape
    ```
    Scales a shape's cross-sections (x, z) by 1 + `rate`·y at height y. Its stretch is divided out locally like a twist's (W0003 above 1.5-fold); where 1 + `rate`·y falls to 0 over the shape it folds (W0014).
    """
    ...
def morph(a: Shape, b: Shape, t: float) -> Shape:
    """```sdf
    morph(a: shape, b: shape, t: float) -> shape
    ```
    Valid: `t` 0 … 1

    The shape between `a` (t = 0) and `b` (t = 1): the field (1 − t)·a + t·b, a bound with the larger L of the two.
    """
    ...
def round(shape: Shape, radius: float) -> Shape:
    """```sdf
    round(shape: shape, radius: float) -> shape
    ```
    Valid: `radius` ≥ 0

    Offsets a shape's surface outwards by `radius`.
    """
    ...
@overload
def hull(shapes: Shape, *more: Shape) -> Shape: ...
@overload
def hull(shapes: Sequence[Shape]) -> Shape: ...
@overload
def hull(points: Sequence[Vec3], radius: float = ...) -> Shape:
    """```sdf
    hull(shapes...: shape) -> shape
    ```
    Valid: balls, or parallel cylinders of one span (§9d); at most `hull_shapes` (64)

    The convex hull of the shapes. Exact.

    ```sdf
    hull(shapes: [shape]) -> shape
    ```
    Valid: not empty; as above

    The convex hull of a list of shapes: the same as giving them one by one.

    ```sdf
    hull(points: [vec3], radius: float = 0) -> shape
    ```
    Valid: 4 points or more not in one plane, or `radius` > 0

    The convex hull of the points; with a `radius`, the hull of balls of that radius about them. Exact.
    """
    ...
def minkowski(shape: Shape, ball: Shape) -> Shape:
    """```sdf
    minkowski(shape: shape, ball: shape) -> shape
    ```
    Valid: `ball` is `sphere(r)`

    OpenSCAD's Minkowski sum with a ball about the origin: the same node as `shape.round(r)`.
    """
    ...
def shell(shape: Shape, thickness: float) -> Shape:
    """```sdf
    shell(shape: shape, thickness: float) -> shape
    ```
    Valid: `thickness` > 0

    Hollows a shape into a wall `thickness` thick centred on its surface: the field \\|f\\| − thickness/2, as other SDF tools' `shell(t)` (Quilez's onion of t/2). Until issue 33 it was \\|f\\| − thickness, a wall twice as thick: double the argument of a scene written for that.
    """
    ...
def elongate(shape: Shape, half: Vec3) -> Shape:
    """```sdf
    elongate(shape: shape, half: vec3) -> shape
    ```
    Valid: `half` ≥ 0

    Stretches a shape by inserting a box of half-extents `half` at the origin.
    """
    ...
def mandelbulb(power: float = ..., iterations: int = ...) -> Shape:
    """```sdf
    mandelbulb(power: float = 8, iterations: int = 8) -> shape
    ```
    Valid: `power` 2 … 16; `iterations` 1 … 64

    The Mandelbulb fractal (a distance estimate).
    """
    ...
def capped_cone(height: float = ..., bottom: float = ..., top: float = ...) -> Shape:
    """```sdf
    capped_cone(height: float = 1, bottom: float = 0.5, top: float = 0.25) -> shape
    ```
    Valid: `height` > 0; `bottom`, `top` ≥ 0, not both 0

    A cone along y cut at both ends (a frustum): radius `bottom` at `-height/2`, `top` at `height/2`. Exact.
    """
    ...
@overload
def round_cone(bottom: float = ..., top: float = ..., height: float = ...) -> Shape: ...
@overload
def round_cone(a: Vec3, b: Vec3, radius_a: float = ..., radius_b: float = ...) -> Shape:
    """```sdf
    round_cone(bottom: float = 0.5, top: float = 0.25, height: float = 1) -> shape
    ```
    Valid: `bottom`, `top` ≥ 0, not both 0; `height` > 0 and above \\|`bottom` − `top`\\|

    The hull of a sphere of radius `bottom` at `-height/2` and one of radius `top` at `height/2` on the y axis. Exact.

    ```sdf
    round_cone(a: vec3, b: vec3, radius_a: float = 0.5, radius_b: float = 0.25) -> shape
    ```
    Valid: `radius_a`, `radius_b` ≥ 0, not both 0; \\|`a` − `b`\\| above \\|`radius_a` − `radius_b`\\|

    The hull of the ball of radius `radius_a` about `a` and that of radius `radius_b` about `b`. Exact.
    """
    ...
def segment(a: Vec3, b: Vec3, radius: float = ...) -> Shape:
    """```sdf
    segment(a: vec3, b: vec3, radius: float = 0.25) -> shape
    ```
    Valid: `radius` > 0

    A capsule between the points `a` and `b`: every point within `radius` of the segment. Exact.
    """
    ...
def rounded_cylinder(radius: float = ..., round: float = ..., height: float = ...) -> Shape:
    """```sdf
    rounded_cylinder(radius: float = 0.5, round: float = 0.1, height: float = 1) -> shape
    ```
    Valid: `radius`, `height` > 0; `round` 0 … min(`radius`, `height/2`)

    A cylinder like `cylinder(radius, height)` with its two rims rounded by `round`, within the same extents. Exact.
    """
    ...
def link(length: float = ..., major: float = ..., minor: float = ...) -> Shape:
    """```sdf
    link(length: float = 1, major: float = 0.5, minor: float = 0.1) -> shape
    ```
    Valid: `length` ≥ 0; `major`, `minor` > 0

    A chain link in the xy plane: a torus of radii `major` and `minor` opened along y by straight parts `length` long. Exact.
    """
    ...
def infinite_cylinder(radius: float = ..., axis: Vec3 = ...) -> Shape:
    """```sdf
    infinite_cylinder(radius: float = 0.5, axis: vec3 = (0, 1, 0)) -> shape
    ```
    Valid: `radius` > 0; `axis` not (0, 0, 0)

    A cylinder without ends about the line through the origin along `axis` (normalised). Exact.
    """
    ...
def slab(thickness: float = ..., normal: Vec3 = ...) -> Shape:
    """```sdf
    slab(thickness: float = 1, normal: vec3 = (0, 1, 0)) -> shape
    ```
    Valid: `thickness` > 0; `normal` not (0, 0, 0)

    The space between two parallel planes `thickness` apart, centred on the origin, normal to `normal` (normalised). Exact.
    """
    ...
def hex_prism(radius: float = ..., height: float = ...) -> Shape:
    """```sdf
    hex_prism(radius: float = 0.5, height: float = 1) -> shape
    ```
    Valid: `radius` > 0; `height` > 0

    A hexagonal prism along y; `radius` is the distance from the axis to each flat side (two of them face ±z). Exact.
    """
    ...
def tri_prism(radius: float = ..., height: float = ...) -> Shape:
    """```sdf
    tri_prism(radius: float = 0.5, height: float = 1) -> shape
    ```
    Valid: `radius` > 0; `height` > 0

    A prism along y of an equilateral triangle, a corner towards +z; `radius` is the distance from the axis to each side. Exact.
    """
    ...
def octahedron(radius: float = ...) -> Shape:
    """```sdf
    octahedron(radius: float = 1) -> shape
    ```
    Valid: `radius` > 0

    A regular octahedron with its corners on the axes, `radius` from the centre. Exact.
    """
    ...
def pyramid(base: float = ..., height: float = ...) -> Shape:
    """```sdf
    pyramid(base: float = 1, height: float = 1) -> shape
    ```
    Valid: `base` > 0; `height` > 0

    A pyramid along y: a square base of side `base` at `-height/2`, its apex at `height/2`. Exact.
    """
    ...
def box_frame(half: Vec3 = ..., edge: float = ...) -> Shape:
    """```sdf
    box_frame(half: vec3 = (0.5, 0.5, 0.5), edge: float = 0.05) -> shape
    ```
    Valid: `half` > 0; `edge` > 0, at most every half-extent

    The twelve edges of the box of half-extents `half`, as square bars `2·edge` thick inside it. Exact.
    """
    ...
def circle(radius: float = ...) -> Profile:
    """```sdf
    circle(radius: float = 0.5) -> profile
    ```
    Valid: `radius` > 0

    A disc about the origin. Exact.
    """
    ...
def round_rect(half: Vec2, radius: float = ...) -> Profile:
    """```sdf
    round_rect(half: vec2, radius: float = 0.05) -> profile
    ```
    Valid: `half` > 0; `radius` ≥ 0 and at most each half-extent

    A rectangle with its corners rounded by `radius`, inside the extents. Exact.
    """
    ...
def arc(radius: float = ..., angle: Angle = ..., thickness: float = ...) -> Profile:
    """```sdf
    arc(radius: float = 0.5, angle: angle, thickness: float = 0.1) -> profile
    ```
    Valid: `radius`, `thickness` > 0; `angle` 0 … 360deg

    The arc of the circle of `radius` about the origin spanning `angle`, centred on +y (from 90° − angle/2 to 90° + angle/2), stroked `thickness` wide with round ends (Quilez's `sdArc`). `arc(r, 360deg, t)` is `ring(r, t)`. Exact.
    """
    ...

class Phong(Record):
    def __init__(self, *, ambient: float = ..., diffuse: float = ..., specular: float = ..., shininess: float = ..., reflect: float = ..., transparency: float = ..., ior: float = ..., color: Union[Vec3, Shape] = ..., fresnel: bool = ...) -> None: ...

class Checker(Record):
    def __init__(self, *, ambient: float = ..., diffuse: float = ..., specular: float = ..., shininess: float = ..., reflect: float = ..., transparency: float = ..., ior: float = ..., fresnel: bool = ..., a: Union[Vec3, Shape] = ..., b: Union[Vec3, Shape] = ..., size: float = ...) -> None: ...

class Pbr(Record):
    def __init__(self, *, base_color: Union[Vec3, Shape] = ..., roughness: float = ..., metallic: float = ..., emission: Vec3 = ..., transmission: float = ..., ior: float = ...) -> None: ...

class PointLight(Record):
    def __init__(self, *, position: Vec3, radius: float = ..., color: Vec3 = ..., intensity: float = ..., penumbra: Angle = ..., softness: float = ..., shadows: bool = ...) -> None: ...

class DirectionalLight(Record):
    def __init__(self, *, direction: Vec3, color: Vec3 = ..., intensity: float = ..., penumbra: Angle = ..., softness: float = ..., shadows: bool = ...) -> None: ...

class SunLight(Record):
    def __init__(self, *, direction: Vec3, color: Vec3 = ..., intensity: float = ..., angle: Angle = ..., shadows: bool = ...) -> None: ...

class SkyLight(Record):
    def __init__(self, *, color: Vec3 = ..., zenith: Vec3 = ..., horizon: Vec3 = ..., ground: Vec3 = ..., intensity: float = ..., shadows: bool = ..., background: bool = ...) -> None: ...

class Camera(Record):
    def __init__(self, *, position: Vec3 = ..., look_at: Vec3 = ..., up: Vec3 = ..., fov: Angle = ...) -> None: ...

class Render(Record):
    def __init__(self, *, width: int = ..., height: int = ..., aa: int = ..., max_steps: int = ..., epsilon: float = ..., max_depth: int = ..., max_dist: float = ..., relaxation: float = ..., background: Vec3 = ..., method: str = ..., samples: int = ..., bounces: int = ..., fps: float = ..., duration: float = ..., occlusion: float = ..., fog: float = ..., fog_color: Vec3 = ..., glow: float = ..., glow_color: Vec3 = ..., exposure: float = ..., tonemap: str = ...) -> None: ...

__all__ = ["Angle", "Path", "Profile", "Record", "Shape", "deg", "field", "profile", "rad", "show", "sphere", "box", "round_box", "plane", "torus", "cylinder", "capsule", "cone", "ellipsoid", "mesh", "rect", "polygon", "text", "regular_polygon", "star", "ring", "segment2", "extrude", "revolve", "bezier", "sweep", "polyline", "helix", "arc3", "loft", "screw", "offset", "union", "intersect", "subtract", "smooth_union", "smooth_intersect", "smooth_subtract", "engrave", "groove", "tongue", "pipe", "translate", "rotate_x", "rotate_y", "rotate_z", "rotate", "scale", "repeat", "mirror", "reflect", "twist", "bend", "repeat_polar", "wrap", "shear", "taper", "morph", "round", "hull", "minkowski", "shell", "elongate", "mandelbulb", "capped_cone", "round_cone", "segment", "rounded_cylinder", "link", "infinite_cylinder", "slab", "hex_prism", "tri_prism", "octahedron", "pyramid", "box_frame", "circle", "round_rect", "arc", "Phong", "Checker", "Pbr", "PointLight", "DirectionalLight", "SunLight", "SkyLight", "Camera", "Render"]
