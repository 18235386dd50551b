"""Tests of the modelling API (python/sdfc/model.py, docs/python.md "Model in Python"), run
against the installed wheel: every built-in of the checker's table reachable from Python and
compiled, every operator, the round trip shape → source → Scene, errors at the Python line,
the limits, meshes and files, pictures, the viewer, the type stubs current, and the
README's "Model in Python" example run as written."""

import ast
import inspect
import os
import stat
import subprocess
import sys
import tempfile
import unittest
from pathlib import Path

import numpy as np

import sdfc
from sdfc import model, stubs

ROOT = Path(__file__).resolve().parents[2]
POINTS = np.random.default_rng(53).uniform(-2.5, 2.5, size=(400, 3))


def here() -> int:
    """The line of the caller."""
    return inspect.currentframe().f_back.f_lineno


def sample(p):
    """A value of the parameter's type inside its valid values, for calling every form."""
    return {
        "float": 0.5,
        "int": 3,
        "bool": True,
        "vec2": (0.5, 0.5),
        "vec3": (0.5, 0.5, 0.5),
        "angle": sdfc.deg(90),
        "string": "A",
        "shape": sdfc.sphere(0.5),
        "profile": sdfc.circle(0.5),
        "[shape]": [sdfc.sphere(0.5), sdfc.box(0.3)],
        "[profile]": [sdfc.circle(0.5), sdfc.rect(0.3)],
        "[vec2]": [(0, 0), (1, 0), (0, 1)],
        "[vec3]": [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)],
        "path": sdfc.polyline([(0, 0, 0), (0, 1, 0), (1, 2, 0)]),
    }[p.type]


# Arguments where the sample would break a rule among the arguments (the checker's, which
# these tests leave to it): the built-in → arguments by name.
SPECIAL = {
    "round_box": {"radius": 0.1},
    "extrude": {"height": 1.0, "round": 0.1},
    "cylinder": {"b": (0, 1, 0)},
    "cone": {"b": (0, 1, 0)},
    "round_cone": {"b": (0, 1, 0)},
    "bezier": {"control": (1, 0.2)},
    "repeat": {"count": (2, 1, 1)},
    # A hull of shapes takes balls or parallel cylinders (the sample list has a box).
    "hull": {"shapes": [sdfc.sphere(0.5), sdfc.sphere(0.3).translate(1, 0, 0)]},
}


class EveryBuiltin(unittest.TestCase):
    def test_every_builtin_is_python_or_a_value(self):
        table = [b["name"] for b in sdfc._sdfc.builtins()]
        self.assertEqual(sorted(model.SHAPE_BUILTINS + model.VALUE_BUILTINS), sorted(table))
        for name in table:
            b = model.BUILTINS[name]
            if any(s.ret in ("shape", "profile") for s in b.sigs):
                f = getattr(sdfc, name, None)
                self.assertTrue(callable(f), f"the built-in `{name}` is missing from sdfc")
                self.assertEqual(f.__doc__, b.doc)
            else:
                # Numbers and vectors: Python's arithmetic, and `field` formulas call them.
                self.assertTrue(all(s.ret not in ("shape", "profile") for s in b.sigs))

    def test_every_form_compiles(self):
        # Each form of each built-in that makes a shape or a profile, called from Python with
        # values inside its valid values, checks clean in a scene (a profile extruded).
        meshfile = Path(tempfile.mkdtemp()) / "part.stl"
        sdfc.sphere(1).save(meshfile, resolution=8)
        called = 0
        for name in model.SHAPE_BUILTINS:
            for sig in model.BUILTINS[name].sigs:
                if sig.ret not in ("shape", "profile"):
                    continue
                special = SPECIAL.get(name, {})
                args = {p.name: special.get(p.name, sample(p)) for p in sig.params if p.required or p.name in special}
                if name == "mesh":
                    args["path"] = str(meshfile)
                if name == "screw":
                    args["profile"] = sdfc.circle(0.2).translate(0.5, 0)
                with self.subTest(sig.signature):
                    shape = getattr(sdfc, name)(**args)
                    self.assertIsInstance(shape, sdfc.Shape if sig.ret == "shape" else sdfc.Profile)
                    if sig.ret == "profile":
                        shape = shape.extrude(0.5)
                    facts = shape.facts()
                    self.assertIn(facts.exactness, ("exact", "bound", "approximate"))
                    self.assertIn(f"{name}(", shape.source())
                    called += 1
        self.assertGreater(called, 90)

    def test_methods_are_the_forms_that_take_the_shape_first(self):
        self.assertTrue(callable(sdfc.Shape.translate) and callable(sdfc.Shape.round))
        self.assertTrue(callable(sdfc.Profile.extrude) and callable(sdfc.Profile.revolve))
        self.assertFalse(hasattr(sdfc.Shape, "extrude"))
        # The shape's own `mesh` and `distance`, not the built-ins of those names.
        self.assertIn("resolution", inspect.signature(sdfc.Shape.mesh).parameters)
        s = sdfc.sphere(1).translate(1, 0, 0).round(0.1)
        self.assertIn("sphere(1).translate(1, 0, 0).round(0.1)", s.source())


class Operators(unittest.TestCase):
    a = sdfc.sphere(1)
    b = sdfc.box((0.8, 0.5, 1.2)).translate(0.6, 0, 0)

    def d(self, shape):
        return shape.distance(POINTS)

    def test_union_intersect_subtract(self):
        da, db = self.d(self.a), self.d(self.b)
        np.testing.assert_allclose(self.d(self.a | self.b), np.minimum(da, db), atol=1e-12)
        np.testing.assert_allclose(self.d(self.a & self.b), np.maximum(da, db), atol=1e-12)
        np.testing.assert_allclose(self.d(self.a - self.b), np.maximum(da, -db), atol=1e-12)
        self.assertIn("union(sphere(1), box(", (self.a | self.b).source())
        self.assertIn("intersect(", (self.a & self.b).source())
        self.assertIn("subtract(", (self.a - self.b).source())

    def test_in_place_and_chains(self):
        c = sdfc.cylinder(0.3, 4)
        f = self.a
        f -= c
        f -= c.rotate_x(sdfc.deg(90))
        f -= c.rotate_z(sdfc.deg(90))
        expected = np.maximum(np.maximum(np.maximum(self.d(self.a), -self.d(c)), -self.d(c.rotate_x(sdfc.deg(90)))), -self.d(c.rotate_z(sdfc.deg(90))))
        np.testing.assert_allclose(self.d(f), expected, atol=1e-12)
        # A chain of `-` is one subtraction of a union; of `|`, one union.
        self.assertEqual(f.source().count("subtract("), 1)
        u = self.a | self.b | c
        self.assertIn("union(sphere(1), box((0.8, 0.5, 1.2)).translate(0.6, 0, 0), cylinder(0.3, 4))", u.source())

    def test_profiles(self):
        p = sdfc.rect((1, 0.5)) | sdfc.circle(0.6).translate(1, 0)
        q = sdfc.rect((1, 0.5)) & sdfc.circle(0.6)
        r = sdfc.rect((1, 0.5)) - sdfc.circle(0.6)
        for profile, word in ((p, "union("), (q, "intersect("), (r, "subtract(")):
            self.assertIsInstance(profile, sdfc.Profile)
            self.assertIn(word, profile.extrude(0.2).source())
        self.assertLess(p.extrude(0.2).distance([1.5, 0, 0])[0], 0)

    def test_paint(self):
        red = sdfc.Phong(color=(0.9, 0.1, 0.1))
        s = (self.a @ red) | (self.b @ sdfc.Checker(size=0.25)) | (self.b.translate(0, 2, 0) @ red)
        text = s.source()
        self.assertIn("material m1 = phong { color: (0.9, 0.1, 0.1) };", text)
        self.assertIn("material m2 = checker { size: 0.25 };", text)
        self.assertEqual(text.count("material "), 2)  # one declaration per material object
        _, materials = s.scene().distance([[0, 0, 0], [0.6, 2, 0]])
        self.assertEqual(list(materials), [1, 1])
        with self.assertRaises(TypeError):
            self.a @ sdfc.Camera()

    def test_smooth_and_keywords(self):
        s = sdfc.smooth_union(0.2, self.a, self.b, variant="exp")
        self.assertIn('smooth_union(0.2, sphere(1), box((0.8, 0.5, 1.2)).translate(0.6, 0, 0), "exp")', s.source())
        # A parameter given by name after one left at its default is written by name.
        t = sdfc.smooth_union(0.2, self.a, self.b, steps=6)
        self.assertIn("steps: 6", t.source())
        self.assertLess(self.d(s).max(), self.d(self.a | self.b).max() + 1e-9)


class RoundTrip(unittest.TestCase):
    def test_source_gives_the_same_field(self):
        # shape → source → Scene: the same distances and materials as the shape's own.
        shared = sdfc.torus(0.8, 0.2).rotate(axis=(1, 1, 0), angle=sdfc.rad(0.7))
        gyroid = sdfc.field("abs(sin(p.x * s) * cos(p.y * s) + sin(p.y * s) * cos(p.z * s) + sin(p.z * s) * cos(p.x * s)) / s - 0.05", s=6.0)
        shape = (
            sdfc.smooth_union(0.1, sdfc.sphere(1), shared.translate(0.5, 0.2, 0))
            | shared.translate(-1, 0, 0) @ sdfc.Phong(color=(0.2, 0.3, 0.9))
            | (sdfc.polygon([(0, 0), (1, 0), (0.5, 1)]).extrude(0.3, round=0.05)).translate(0, -1.5, 0)
            | (gyroid & sdfc.box(0.7)).translate(0, 1.6, 0)
            | sdfc.star(5).revolve(offset=0.2).scale(0.5).twist(0.3).translate(1.5, 1, 1)
        )
        text = shape.source()
        self.assertIn("let shape1 = ", text)  # the shape used twice is written once
        self.assertEqual(text, sdfc._sdfc.fmt(text))  # as `sdfc fmt` writes it
        scene = sdfc.Scene(source=text)
        d, m = scene.distance(POINTS)
        np.testing.assert_array_equal(d, shape.distance(POINTS))
        np.testing.assert_array_equal(m, shape.scene().distance(POINTS)[1])
        self.assertGreater(len(set(m)), 1)

    def test_shared_profiles_and_colour_fields(self):
        c = sdfc.circle(0.5).translate(1, 0)
        p = c | c.rotate(sdfc.deg(90))
        self.assertEqual(p.source(), "let profile1 = circle(0.5).translate(1, 0);\nlet result = union(profile1, profile1.rotate(90deg));\n")
        self.assertIn("<sdfc.Profile union(profile1, profile1.rotate(90deg))>", repr(p))
        solid = p.extrude(0.2)
        self.assertLess(solid.distance([0, 1, 0])[0], 0)
        stripes = sdfc.Phong(color=sdfc.field("vec3(0.5 + 0.5 * sin(8 * p.y), 0.3, 0.3)"))
        ball = sdfc.sphere(1) @ stripes
        self.assertIn("material m1 = phong { color: field { vec3(0.5 + 0.5 * sin(8 * p.y), 0.3, 0.3) } };", ball.source())
        image = ball.render(size=(32, 24), backend="cpu")
        # The stripes: red varies over the ball while green stays, whatever the shading.
        middle = image[6:18, 10:22]
        self.assertGreater(np.ptp(middle[..., 0] / np.maximum(middle[..., 1], 1e-6)), 1.0)

    def test_facts(self):
        f = sdfc.sphere(1).translate(1, 2, 3).facts()
        self.assertEqual((f.exactness, f.lipschitz), ("exact", 1.0))
        np.testing.assert_allclose(f.box, ((0, 1, 2), (2, 3, 4)))
        g = sdfc.field("2 * (length(p) - 1)").facts()
        self.assertEqual(g.lipschitz, 2.0)
        self.assertTrue(np.isinf(sdfc.plane().facts().box[0][1]))


class Errors(unittest.TestCase):
    def test_types_and_values_name_the_parameter(self):
        cases = [
            (lambda: sdfc.sphere(-1), ValueError, "`radius` must be greater than 0"),
            (lambda: sdfc.sphere("1"), TypeError, "`radius` must be a number, not str"),
            (lambda: sdfc.sphere(float("nan")), TypeError, "`radius` must be finite"),
            (lambda: sdfc.box((1, 2)), TypeError, "`half` must be 3 numbers, not a tuple of 2"),
            (lambda: sdfc.sphere(1).translate(1, 2, 3, 4), TypeError, "takes at most 4 arguments (5 given)"),
            (lambda: sdfc.sphere(1).translate(q=1), TypeError, "unexpected keyword argument `q`"),
            (lambda: sdfc.extrude(sdfc.circle(1)), TypeError, "missing the argument `height`"),
            (lambda: sdfc.extrude(sdfc.sphere(1), 1), TypeError, "`profile` must be a profile, not a shape"),
            (lambda: sdfc.regular_polygon(2.5), TypeError, "`sides` must be an int"),
            (lambda: sdfc.box(1).rotate_y(1.57), TypeError, "`angle` must be an angle with its unit, sdfc.deg(1.57) or sdfc.rad(1.57), not the plain number 1.57"),
            (lambda: sdfc.regular_polygon(2), ValueError, "`sides` must be between 3 and 10000"),
            (lambda: sdfc.smooth_union(0.1, sdfc.sphere(), sdfc.box(), variant="x"), ValueError, '`variant` must be one of "poly"'),
            (lambda: sdfc.text("a\x01"), TypeError, "control character"),
            (lambda: sdfc.Phong(colour=(1, 0, 0)), TypeError, "unknown field `colour`"),
            (lambda: sdfc.Phong(ambient=2), ValueError, "`ambient` must be between 0 and 1, not 2"),
            (lambda: sdfc.PointLight(), TypeError, "missing the field `position`"),
            (lambda: sdfc.Camera(fov=sdfc.deg(200)), ValueError, "`fov` must be between 0.1deg and 179deg"),
            (lambda: sdfc.field("length(p) - 1", p=1), ValueError, "`p` cannot name a value"),
            (lambda: sdfc.sphere() | 1, TypeError, "unsupported operand"),
            (lambda: sdfc.sphere() | sdfc.circle(1), TypeError, "unsupported operand"),
        ]
        for f, kind, words in cases:
            with self.subTest(words):
                with self.assertRaises(kind) as e:
                    f()
                self.assertIn(words, str(e.exception))

    def test_compile_error_points_at_the_python_line(self):
        ball = sdfc.sphere(1)
        bad = sdfc.round_box((0.1, 1, 1), 0.5)
        line = here() - 1
        shape = ball | bad.translate(2, 0, 0)
        for call in (shape.scene, shape.facts, shape.mesh, lambda: shape.distance([0, 0, 0])):
            with self.assertRaises(sdfc.CompileError) as e:
                call()
            self.assertEqual(e.exception.python, (__file__, line))
            self.assertTrue(str(e.exception).startswith(f"{__file__}:{line}: error[E0400]: the rounding radius 0.5"), str(e.exception))
            self.assertEqual(e.exception.diagnostics[0].code, "E0400")

    def test_formula_errors_point_at_the_field(self):
        f = sdfc.field("length(p) - radius")
        line = here() - 1
        with self.assertRaises(sdfc.CompileError) as e:
            (sdfc.sphere() | f.translate(1, 0, 0)).scene()
        self.assertEqual(e.exception.python, (__file__, line))
        self.assertIn("unknown name `radius`", str(e.exception))

    def test_the_language_limits_refuse_a_huge_shape(self):
        # 5000 calls nested inside each other: the checker refuses them as it would the file
        # (E0507, `nesting`), with no Python recursion on the way; as a method chain, which
        # the language does not nest, they are fine.
        nested, chained = sdfc.sphere(0.1), sdfc.sphere(0.1)
        for i in range(5000):
            nested = sdfc.translate(nested, 0.001, 0, 0)
            chained = chained.translate(0.001, 0, 0)
        with self.assertRaises(sdfc.CompileError) as e:
            nested.facts()
        self.assertIn("E0507", str(e.exception))
        self.assertIn("nest more than 1000 levels", str(e.exception))
        np.testing.assert_allclose(chained.facts().box, ((4.9, -0.1, -0.1), (5.1, 0.1, 0.1)))
        # 20 000 unions are one call of 20 000 shapes; within the default limits, refused
        # by a lower `nodes` limit as the file would be.
        u = sdfc.sphere(0.1)
        for i in range(1, 20000):
            u = u | sdfc.sphere(0.1).translate(i * 0.2, 0, 0)
        self.assertEqual(u.source().count("union("), 1)
        self.assertAlmostEqual(float(u.distance([1999.8, 0, 0])[0]), -0.1)
        with self.assertRaises(sdfc.CompileError) as e:
            u.scene(limits={"nodes": 10000})
        self.assertIn("E0507", str(e.exception))
        self.assertIn('limits={"nodes"', str(e.exception.diagnostics[0].notes))


class Outputs(unittest.TestCase):
    def test_save_writes_a_watertight_mesh(self):
        shape = sdfc.sphere(1) - sdfc.cylinder(0.4, 3)
        folder = Path(tempfile.mkdtemp())
        for ext in ("stl", "obj", "ply", "glb", "3mf"):
            triangles, vertices = shape.save(folder / f"part.{ext}", resolution=32)
            self.assertGreater(triangles, 100)
            self.assertGreater((folder / f"part.{ext}").stat().st_size, 1000)
        self.assertEqual((folder / "part.stl").stat().st_size, 84 + 50 * triangles)
        v, f, _ = shape.mesh(resolution=32)
        edges = np.sort(np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]]), axis=1)
        _, counts = np.unique(edges, axis=0, return_counts=True)
        self.assertTrue((counts == 2).all())  # every edge between two triangles: closed
        with self.assertRaises(ValueError) as e:
            shape.save(folder / "part.step")
        self.assertIn(".stl, .obj, .ply, .glb or .3mf", str(e.exception))

    def test_save_turns_the_mesh_up(self):
        # A post 3 tall along the scene's y: with up="z" (a slicer's) the file's z is its height.
        shape = sdfc.box((0.5, 1.5, 0.25)).translate((0, 1.5, 0))
        folder = Path(tempfile.mkdtemp())

        def corners(name, **kw):
            shape.save(folder / name, resolution=16, **kw)
            data = (folder / name).read_bytes()[84:]
            tri = np.frombuffer(data, dtype=np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")]))
            v = tri["v"].reshape(-1, 3)
            return v.min(axis=0), v.max(axis=0)

        lo, hi = corners("y.stl")
        self.assertAlmostEqual(float(hi[1] - lo[1]), 3.0, delta=0.1)
        lo, hi = corners("z.stl", up="z")
        self.assertAlmostEqual(float(hi[2] - lo[2]), 3.0, delta=0.1)
        self.assertAlmostEqual(float(hi[1] - lo[1]), 0.5, delta=0.1)
        with self.assertRaises(ValueError) as e:
            shape.save(folder / "x.stl", up="x")
        self.assertIn('up must be "y"', str(e.exception))

    def test_pictures(self):
        shape = sdfc.torus(1, 0.3) @ sdfc.Phong(color=(0.9, 0.5, 0.1))
        png = shape._repr_png_()
        self.assertTrue(png.startswith(b"\x89PNG"))
        image = shape.render(size=(64, 48), backend="cpu")
        self.assertEqual(image.shape, (48, 64, 3))
        # Framed and lit: the shape fills the middle of the picture, lit brighter than the
        # ambient term alone.
        self.assertGreater(image[20:28, 28:36].max(), 0.3)
        self.assertTrue(shape.scene()._repr_png_().startswith(b"\x89PNG"))
        cam = sdfc.Camera(position=(0, 0, -30), look_at=(0, 0, 0))
        far = shape.render(size=(64, 48), backend="cpu", camera=cam, lights=[sdfc.PointLight(position=(0, 5, -5))])
        self.assertLess((far > 0.2).mean(), (image > 0.2).mean())
        self.assertIn("camera { position: (0, 0, -30), look_at: (0, 0, 0) }", shape.source(camera=cam))

    def test_show_runs_the_viewer_on_the_source(self):
        folder = Path(tempfile.mkdtemp())
        fake = folder / "sdfc"
        fake.write_text(f"#!/bin/sh\necho \"$@\" > {folder}/args\ncp \"$2\" {folder}/viewed.sdf\n")
        fake.chmod(fake.stat().st_mode | stat.S_IEXEC)
        shape = sdfc.sphere(1) | sdfc.box(0.5).translate(1, 0, 0)
        old = os.environ.get("SDFC_BIN")
        os.environ["SDFC_BIN"] = str(fake)
        try:
            process = sdfc.show(shape)
        finally:
            if old is None:
                del os.environ["SDFC_BIN"]
            else:
                os.environ["SDFC_BIN"] = old
        self.assertEqual(process.wait(timeout=30), 0)
        self.assertTrue((folder / "args").read_text().startswith("view "))
        self.assertEqual((folder / "viewed.sdf").read_text(), shape.source())


class Stubs(unittest.TestCase):
    def test_stubs_are_current(self):
        path = Path(model.__file__).with_name("model.pyi")
        self.assertEqual(path.read_text(), stubs.generate(), "python -m sdfc.stubs python/sdfc/model.pyi")
        source = ROOT / "python" / "sdfc" / "model.pyi"
        if source.exists():
            self.assertEqual(source.read_text(), stubs.generate(), "python -m sdfc.stubs python/sdfc/model.pyi")

    def test_stubs_name_every_public_method(self):
        tree = ast.parse(stubs.generate())
        classes = {n.name: n for n in tree.body if isinstance(n, ast.ClassDef)}
        for cls in (sdfc.Shape, sdfc.Profile):
            stubbed = {f.name for f in classes[cls.__name__].body if isinstance(f, ast.FunctionDef)}
            public = {n for n in dir(cls) if not n.startswith("__") and not n.startswith("_") and callable(getattr(cls, n))}
            inherited = {f.name for f in classes["_Expr"].body if isinstance(f, ast.FunctionDef)}
            self.assertEqual(public - stubbed - inherited, set())


class Fogleman(unittest.TestCase):
    def test_the_ports_of_fogleman_sdf_examples_run(self):
        # bench/fogleman: fogleman/sdf's README examples in sdfc's Python, each meshed coarsely
        # here (the benchmark meshes them at the peer's cell size): closed meshes.
        import runpy

        names = ["example", "gearlike", "knurling", "blobby", "weave"]
        bounds = {"weave": ((-12.2, -12.2, -0.6), (12.2, 12.2, 0.6))}
        for name in names:
            with self.subTest(name):
                f = runpy.run_path(str(ROOT / "bench" / "fogleman" / f"{name}.py"))["f"]
                v, faces, _ = f.mesh(resolution=48, bounds=bounds.get(name))
                self.assertGreater(len(faces), 1000)
                edges = np.sort(np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]), axis=1)
                _, counts = np.unique(edges, axis=0, return_counts=True)
                self.assertTrue((counts == 2).all())


class Docs(unittest.TestCase):
    def test_readme_model_example_runs(self):
        text = (ROOT / "README.md").read_text().split("## Model in Python", 1)[1]
        code = text.split("```python\n", 1)[1].split("```", 1)[0]
        folder = tempfile.mkdtemp()
        run = subprocess.run([sys.executable, "-c", code], cwd=folder, capture_output=True, text=True)
        self.assertEqual(run.returncode, 0, f"README's example failed:\n{code}\n{run.stderr}")
        self.assertIn("distance field: bound (L = 1)", run.stdout)
        self.assertGreater(os.path.getsize(os.path.join(folder, "out.stl")), 10000)


if __name__ == "__main__":
    unittest.main()
