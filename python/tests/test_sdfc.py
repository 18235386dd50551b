"""Tests of the Python package `sdfc`, run against the installed wheel (`.ci/run` builds it
into a fresh virtual environment): check, CompileError, render against `sdfc render`,
distances, meshes, compile, frames, threads and Ctrl-C, and the first examples of README.md
and docs/python.md run as written. The CLI they compare with is $SDFC_BIN, else
target/release/sdfc of this repository."""

import os
import subprocess
import sys
import tempfile
import threading
import unittest
from pathlib import Path

import numpy as np

import sdfc

ROOT = Path(__file__).resolve().parents[2]
ERR = ROOT / "compiler" / "tests" / "in" / "err"

SPHERE = """
camera { position: (0, 0, -4), look_at: (0, 0, 0), fov: 50deg }
light point { position: (2, 3, -4) }
material red = phong { color: (0.9, 0.2, 0.1) };
material blue = phong { color: (0.1, 0.2, 0.9) };
render { width: 32, height: 24 }
scene {
  sphere(1) @ red;
  box((0.5, 0.5, 0.5)).translate(3, 0, 0) @ blue;
}
"""


def sdfc_bin() -> str:
    path = os.environ.get("SDFC_BIN") or str(ROOT / "target" / "release" / "sdfc")
    if not os.path.exists(path):
        raise AssertionError(f"the sdfc binary is needed to compare with: build it (cargo build --release) or set SDFC_BIN; not found at {path}")
    return path


def cli_json_diagnostics(path: Path):
    out = subprocess.run([sdfc_bin(), "check", "--diagnostics", "json", str(path)], capture_output=True, text=True)
    import json

    lines = (out.stdout + out.stderr).splitlines()
    return [json.loads(line) for line in lines if line.startswith("{")]


class Check(unittest.TestCase):
    def test_clean_scene_has_facts(self):
        diags, facts = sdfc.check(SPHERE)
        self.assertEqual([d for d in diags if d.severity == "error"], [])
        self.assertIsNotNone(facts)
        self.assertEqual(facts.exactness, "bound")  # a union of exact fields
        self.assertEqual(facts.lipschitz, 1.0)
        self.assertEqual(facts.method, "trace")
        self.assertFalse(facts.animated)

    def test_errors_are_located(self):
        source = "scene {\n  sphere(1).translate(0, 0, 0) @ nothing;\n}\n"
        diags, facts = sdfc.check(source)
        self.assertIsNone(facts)
        errors = [d for d in diags if d.severity == "error"]
        self.assertEqual(len(errors), 1)
        e = errors[0]
        self.assertEqual((e.line, e.column), (2, 34))
        self.assertEqual(e.span_text, "nothing")
        self.assertTrue(e.code.startswith("E"))

    def test_fixtures_match_the_cli(self):
        # One fixture of each class: lexical, syntax, names, types, ranges, imports.
        names = [
            "bad_character.sdf",
            "missing_closing_paren.sdf",
            "let_type_mismatch.sdf",
            "ior_below_one.sdf",
            "missing_import.sdf",
            "duplicate_material.sdf",
        ]
        for name in names:
            with self.subTest(name):
                path = ERR / name
                with self.assertRaises(sdfc.CompileError) as caught:
                    sdfc.Scene(path=str(path))
                ours = [(d.code, d.line, d.column) for d in caught.exception.diagnostics if d.severity == "error"]
                theirs = [
                    (d["code"], d["labels"][0]["line"], d["labels"][0]["column"])
                    for d in cli_json_diagnostics(path)
                    if d["severity"] == "error"
                ]
                self.assertTrue(ours)
                self.assertEqual(ours, theirs)

    def test_method_reason_names_the_parameter(self):
        # Sphere traced beyond the `traced` limit: the reason says how to raise it here.
        source = "scene { union([for i in 0..20 { sphere(0.1).translate(i, 0, 0) }]); }"
        _, facts = sdfc.check(source, limits={"traced": 10})
        self.assertEqual(facts.method, "march")
        self.assertIn("`traced` limit of 10", facts.method_reason)
        self.assertIn('limits={"traced": 20}', facts.method_reason)
        self.assertNotIn("--", facts.method_reason)

    def test_check_reads_files(self):
        diags, facts = sdfc.check(path=str(ROOT / "examples" / "seed1.sdf"))
        self.assertIsNotNone(facts)
        with self.assertRaises(ValueError):
            sdfc.check(path=str(ROOT / "no such file.sdf"))


class Render(unittest.TestCase):
    def test_cpu_render_equals_the_cli(self):
        for scene, name in [(ROOT / "examples" / "seed1.sdf", "seed1"), (ROOT / "examples" / "blends.sdf", "blends")]:
            with self.subTest(name), tempfile.TemporaryDirectory() as tmp:
                out = Path(tmp) / "cli.png"
                subprocess.run(
                    [sdfc_bin(), "render", str(scene), "--backend", "cpu", "--size", "64x48", "-o", str(out)],
                    check=True,
                    capture_output=True,
                )
                s = sdfc.Scene(path=str(scene))
                self.assertEqual(s.png(size=(64, 48), backend="cpu"), out.read_bytes())
                image = s.render(size=(64, 48), backend="cpu", dtype=np.uint8)
                self.assertEqual(image.shape, (48, 64, 3))
                self.assertEqual(image.dtype, np.uint8)
                linear = s.render(size=(64, 48), backend="cpu")
                self.assertEqual(linear.dtype, np.float32)
                # The sRGB bytes are the linear values encoded (within rounding).
                srgb = np.where(linear <= 0.0031308, 12.92 * linear, 1.055 * np.power(np.clip(linear, 0.0031308, None), 1 / 2.4) - 0.055)
                self.assertLessEqual(np.abs(np.clip(srgb, 0, 1) * 255 - image).max(), 1.0)

    def test_set_overrides_settings(self):
        s = sdfc.Scene(SPHERE, set={"background": (1, 0, 0)})
        image = s.render(backend="cpu")
        self.assertEqual(image.shape, (24, 32, 3))
        self.assertAlmostEqual(float(image[0, 0, 0]), 1.0, places=5)
        self.assertAlmostEqual(float(image[0, 0, 1]), 0.0, places=5)

    def test_threads_agree(self):
        s = sdfc.Scene(path=str(ROOT / "examples" / "seed1.sdf"))
        results = [None] * 4

        def work(i):
            results[i] = s.render(size=(48, 32), backend="cpu")

        threads = [threading.Thread(target=work, args=(i,)) for i in range(4)]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        for r in results[1:]:
            np.testing.assert_array_equal(r, results[0])

    def test_too_large_a_render_is_refused(self):
        s = sdfc.Scene(SPHERE)
        # 16384² pixels at aa 4: far above the default memory limit of the render.
        with self.assertRaises((RuntimeError, ValueError)) as caught:
            s.render(size=(16384, 16384), aa=4, backend="cpu")
        self.assertIn("limit", str(caught.exception))
        # Named as this package's parameter, not as the command line's flag.
        self.assertIn('limits={"memory": ', str(caught.exception))
        self.assertNotIn("--", str(caught.exception))

    def test_limits_are_set_by_the_limits_parameter(self):
        # A memory limit of 1 MiB refuses a render the default allows.
        s = sdfc.Scene(SPHERE, limits={"memory": 1})
        with self.assertRaises(RuntimeError) as caught:
            s.render(size=(640, 480), backend="cpu")
        self.assertIn('limits={"memory": ', str(caught.exception))
        self.assertEqual(sdfc.Scene(SPHERE, limits={"memory": 64}).render(size=(8, 6), backend="cpu").shape, (6, 8, 3))
        with self.assertRaises(ValueError):
            sdfc.Scene(SPHERE, limits={"speed": 1})
        # A limit of the checker: the error's note names the parameter too.
        with self.assertRaises(sdfc.CompileError) as caught:
            sdfc.Scene("scene { union([for i in 0..50 { sphere(0.1) }]); }", limits={"objects": 10})
        notes = " ".join(n for d in caught.exception.diagnostics for n in list(d.notes) + [d.help or ""])
        self.assertIn('limits={"objects": ', notes)

    def test_bad_arguments(self):
        s = sdfc.Scene(SPHERE)
        with self.assertRaises(ValueError):
            s.render(backend="metal")
        with self.assertRaises(ValueError):
            s.render(dtype=np.int16)
        with self.assertRaises(ValueError):
            sdfc.Scene(SPHERE, set={"no_such_setting": 1})

    def test_repr_png(self):
        png = sdfc.Scene(SPHERE)._repr_png_()
        self.assertEqual(png[:8], b"\x89PNG\r\n\x1a\n")

    def test_ctrl_c_interrupts(self):
        import _thread

        s = sdfc.Scene(path=str(ROOT / "examples" / "seed3.sdf"))
        timer = threading.Timer(0.2, _thread.interrupt_main)
        timer.start()
        try:
            with self.assertRaises(KeyboardInterrupt):
                # Minutes of work on two cores: the interrupt comes long before its end.
                s.render(size=(1600, 1200), aa=4, backend="cpu")
        finally:
            timer.cancel()


class Distance(unittest.TestCase):
    def test_sphere_and_box(self):
        s = sdfc.Scene(SPHERE)
        points = np.array([[0, 0, 0], [2, 0, 0], [0, -1.5, 0], [3, 0, 0], [3, 1.5, 0]], dtype=np.float64)
        d, m = s.distance(points)
        self.assertEqual(d.shape, (5,))
        self.assertEqual(m.shape, (5,))
        np.testing.assert_allclose(d, [-1.0, 0.5, 0.5, -0.5, 1.0], atol=1e-12)
        # Materials are numbered from 1 in the order they are declared (0: the default).
        self.assertEqual(list(m[[0, 2]]), [1, 1])
        self.assertEqual(list(m[[3, 4]]), [2, 2])

    def test_many_points(self):
        s = sdfc.Scene(SPHERE)
        rng = np.random.default_rng(1)
        p = rng.uniform(-1.5, 1.5, size=(100_000, 3))
        d, _ = s.distance(p)
        r = np.linalg.norm(p, axis=1)
        near = np.linalg.norm(p - [3, 0, 0], axis=1) > 2
        np.testing.assert_allclose(d[near], (r - 1)[near], atol=1e-9)

    def test_shape_is_checked(self):
        with self.assertRaises(ValueError):
            sdfc.Scene(SPHERE).distance(np.zeros((4, 2)))
        with self.assertRaises(ValueError):
            sdfc.Scene(SPHERE).distance(np.zeros((4, 3)), backend="opengl")

    def test_equals_the_emitted_rust(self):
        # The CLI's `compile --emit rust`, compiled by rustc with glam's two vector types
        # stood in for, evaluated at the same points: map_f64 is the interpreter bit for bit.
        path = ROOT / "examples" / "seed3.sdf"
        rust = subprocess.run([sdfc_bin(), "compile", str(path), "--emit", "rust"], check=True, capture_output=True, text=True).stdout
        rng = np.random.default_rng(7)
        points = rng.uniform(-3, 3, size=(200, 3))
        main = (
            "#![allow(dead_code)]\n"
            "mod glam {\n"
            "    #[derive(Clone, Copy)] pub struct Vec3 { pub x: f32, pub y: f32, pub z: f32 }\n"
            "    #[derive(Clone, Copy)] pub struct DVec3 { pub x: f64, pub y: f64, pub z: f64 }\n"
            "}\n"
            f"mod scene {{\nuse super::glam;\n{rust}\n}}\n"
            "fn main() {\n"
            "    let text = std::fs::read_to_string(std::env::args().nth(1).unwrap()).unwrap();\n"
            "    for line in text.lines() {\n"
            "        let c: Vec<f64> = line.split(' ').map(|w| f64::from_bits(w.parse().unwrap())).collect();\n"
            "        let (d, m) = scene::map_f64(glam::DVec3 { x: c[0], y: c[1], z: c[2] });\n"
            "        println!(\"{} {}\", d.to_bits(), m);\n"
            "    }\n"
            "}\n"
        )
        with tempfile.TemporaryDirectory() as tmp:
            tmp = Path(tmp)
            (tmp / "eval.rs").write_text(main)
            (tmp / "points.txt").write_text("\n".join(" ".join(str(int(x)) for x in row) for row in points.view(np.uint64)))
            subprocess.run(["rustc", "--edition", "2021", "-C", "opt-level=1", "-o", str(tmp / "eval"), str(tmp / "eval.rs")], check=True, capture_output=True)
            out = subprocess.run([str(tmp / "eval"), str(tmp / "points.txt")], check=True, capture_output=True, text=True).stdout
        rows = [line.split(" ") for line in out.splitlines()]
        expected = np.array([int(r[0]) for r in rows], dtype=np.uint64).view(np.float64)
        ids = np.array([int(r[1]) for r in rows], dtype=np.uint32)
        d, m = sdfc.Scene(path=str(path)).distance(points)
        np.testing.assert_array_equal(d, expected)
        np.testing.assert_array_equal(m, ids)

    def test_on_the_gpu(self):
        # wgpu (lavapipe in CI) runs the scene's compiled map in f32: the f64 distances
        # rounded, within a few ulps of the distance's scale, and the same materials.
        path = ROOT / "examples" / "seed3.sdf"
        rng = np.random.default_rng(3)
        points = rng.uniform(-3, 3, size=(5000, 3))
        s = sdfc.Scene(path=str(path))
        d64, m64 = s.distance(points)
        d32, m32 = s.distance(points, backend="wgpu")
        self.assertEqual(d32.dtype, np.float32)
        scale = 1 + np.abs(points).max(axis=1)
        np.testing.assert_array_less(np.abs(d32 - d64), 1e-5 * scale)
        # Ids may differ only where two materials' distances are equal to f32 precision.
        self.assertGreater(np.mean(m32 == m64), 0.99)


class Depth(unittest.TestCase):
    def test_centre_and_corner(self):
        d, c = sdfc.Scene(SPHERE).depth(size=(32, 24))
        self.assertEqual(d.shape, (24, 32))
        self.assertEqual(c.shape, (24, 32))
        self.assertEqual(d.dtype, np.float32)
        # The eye is 4 from the centre of a unit sphere: the centre ray hits at 3.
        centre = d[11:13, 15:17]
        np.testing.assert_allclose(centre, 3.0, atol=0.02)
        np.testing.assert_array_equal(c[11:13, 15:17], 1.0)
        self.assertTrue(np.isnan(d[0, 0]))
        self.assertEqual(c[0, 0], 0.0)

    def test_equals_the_cli_sidecar(self):
        with tempfile.TemporaryDirectory() as tmp:
            out = Path(tmp) / "s.png"
            src = Path(tmp) / "s.sdf"
            src.write_text(SPHERE)
            subprocess.run([sdfc_bin(), "render", str(src), "--backend", "cpu", "--aux", "-o", str(out)], check=True, capture_output=True)
            raw = (Path(tmp) / "s.aux").read_bytes()
        w, h = np.frombuffer(raw[8:16], dtype="<u4")
        n = int(w) * int(h)
        cli_d = np.frombuffer(raw[20 : 20 + 4 * n], dtype="<f4").reshape(h, w)
        cli_c = np.frombuffer(raw[20 + 4 * n : 20 + 8 * n], dtype="<f4").reshape(h, w)
        d, c = sdfc.Scene(SPHERE).depth()
        np.testing.assert_array_equal(d, cli_d)
        np.testing.assert_array_equal(c, cli_c)

    def test_gpu_backends_have_none(self):
        with self.assertRaises(ValueError) as caught:
            sdfc.Scene(SPHERE).depth(backend="wgpu")
        self.assertIn("cpu", str(caught.exception))


class Mesh(unittest.TestCase):
    def test_sphere_mesh_is_closed(self):
        s = sdfc.Scene("material m = phong { color: (0.2, 0.4, 0.6) };\nscene { sphere(1) @ m; }")
        v, f, c = s.mesh(resolution=24)
        self.assertEqual(v.shape[1], 3)
        self.assertEqual(f.shape[1], 3)
        self.assertEqual(c.shape, v.shape)
        self.assertEqual(f.dtype, np.uint32)
        self.assertLess(int(f.max()), len(v))
        np.testing.assert_allclose(np.linalg.norm(v, axis=1), 1.0, atol=0.02)
        np.testing.assert_allclose(c, np.tile([0.2, 0.4, 0.6], (len(v), 1)), atol=1e-6)
        # Watertight: every edge in exactly two faces, once in each direction; a sphere's
        # Euler characteristic is 2.
        edges = np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]])
        directed = {tuple(e) for e in edges.tolist()}
        self.assertEqual(len(directed), len(edges))
        self.assertTrue(all((b, a) in directed for a, b in directed))
        self.assertEqual(len(v) - len(edges) // 2 + len(f), 2)

    def test_unbounded_needs_bounds(self):
        s = sdfc.Scene("scene { plane((0, 1, 0), 0); sphere(0.5); }")
        with self.assertRaises(ValueError) as caught:
            s.mesh(resolution=8)
        # Named as this package's parameter, not as the command line's flag.
        self.assertIn("bounds=((x0, y0, z0), (x1, y1, z1))", str(caught.exception))
        self.assertNotIn("--", str(caught.exception))
        v, f, _ = s.mesh(resolution=16, bounds=((-1, -1, -1), (1, 1, 1)))
        self.assertGreater(len(f), 0)


    def test_too_fine_a_grid_is_refused(self):
        s = sdfc.Scene(path=str(ROOT / "examples" / "mesh" / "bracket.sdf"))
        with self.assertRaises(RuntimeError) as caught:
            s.mesh(resolution=100000)
        message = str(caught.exception)
        self.assertIn("or more", message)
        self.assertIn("limits={", message)
        self.assertNotIn("--", message)


class Compile(unittest.TestCase):
    def test_targets(self):
        s = sdfc.Scene(SPHERE)
        self.assertIn("fn ", s.compile("wgsl"))
        self.assertIn("fn ", s.compile("rust"))
        self.assertIn("sdf", s.compile("wgsl", part="map"))
        self.assertIsInstance(s.compile("spirv"), bytes)
        with self.assertRaises(ValueError):
            s.compile("cobol")

    def test_equals_the_cli(self):
        path = ROOT / "examples" / "seed1.sdf"
        cli = subprocess.run([sdfc_bin(), "compile", str(path), "--emit", "rust"], check=True, capture_output=True, text=True).stdout
        self.assertEqual(sdfc.Scene(path=str(path)).compile("rust"), cli)


class Frames(unittest.TestCase):
    def test_frames_follow_t(self):
        s = sdfc.Scene(
            "render { width: 16, height: 12, fps: 4, duration: 0.5 }\n"
            "camera { position: (0, 0, -4), look_at: (0, 0, 0) }\n"
            "scene { sphere(0.5).translate(t * 2, 0, 0); }"
        )
        frames = list(s.frames(backend="cpu"))
        self.assertEqual(len(frames), 2)
        self.assertFalse(np.array_equal(frames[0], frames[1]))
        np.testing.assert_array_equal(frames[1], s.render(backend="cpu", t=0.25))


class Kept(unittest.TestCase):
    """A scene keeps the render and the distance kernel it prepared last: asked again, with
    the same settings or others, it answers as a scene made anew would."""

    ANIMATED = (
        "render { width: 24, height: 16 }\n"
        "camera { position: (0, 0, -4), look_at: (0, 0, 0) }\n"
        "light point { position: (2, 3, -4) }\n"
        "scene { sphere(0.5).translate(t * 2, 0, 0); box((0.3, 0.3, 0.3)).translate(-1, 0, 0); }"
    )

    def renders_again_as_a_new_scene_would(self, backend):
        s = sdfc.Scene(self.ANIMATED)
        asks = [dict(t=0.0), dict(t=0.25), dict(t=0.25, size=(40, 30)), dict(t=0.0), dict(t=0.0, aa=2)]
        for ask in asks:
            kept = s.render(backend=backend, **ask)
            fresh = sdfc.Scene(self.ANIMATED).render(backend=backend, **ask)
            np.testing.assert_array_equal(kept, fresh, err_msg=str(ask))
        self.assertFalse(np.array_equal(s.render(backend=backend, t=0.0), s.render(backend=backend, t=0.25)))

    def test_renders_again_as_a_new_scene_would(self):
        for backend in ("cpu", "wgpu"):
            with self.subTest(backend=backend):
                self.renders_again_as_a_new_scene_would(backend)

    def require_cuda(self, probe):
        """Skips, saying why, where `probe` cannot reach a CUDA device (unless
        SDFC_REQUIRE_CUDA=1, which makes that a failure)."""
        try:
            probe()
        except RuntimeError as e:
            if os.environ.get("SDFC_REQUIRE_CUDA") == "1":
                raise
            self.skipTest(f"no CUDA device ({e}); SDFC_REQUIRE_CUDA=1 requires one")

    def test_renders_again_through_cuda_as_a_new_scene_would(self):
        # CUDA's preparation is taken over, not copied: once, a second render raised.
        self.require_cuda(lambda: sdfc.Scene(self.ANIMATED).render(backend="cuda"))
        self.renders_again_as_a_new_scene_would("cuda")

    def distances_again_as_a_new_scene_would(self, backend):
        rng = np.random.default_rng(5)
        s = sdfc.Scene(self.ANIMATED)
        for t in (0.0, 0.5, 0.0):
            points = rng.uniform(-2, 2, size=(300, 3))
            d, m = s.distance(points, t=t, backend=backend)
            d_new, m_new = sdfc.Scene(self.ANIMATED).distance(points, t=t, backend=backend)
            np.testing.assert_array_equal(d, d_new)
            np.testing.assert_array_equal(m, m_new)

    def test_distances_again_as_a_new_scene_would(self):
        self.distances_again_as_a_new_scene_would("wgpu")

    def test_distances_again_through_cuda_as_a_new_scene_would(self):
        self.require_cuda(lambda: sdfc.Scene(self.ANIMATED).distance(np.zeros((1, 3)), backend="cuda"))
        self.distances_again_as_a_new_scene_would("cuda")


class Docs(unittest.TestCase):
    def test_first_examples_run_as_written(self):
        # The first Python block of README.md and of docs/python.md, run from the
        # repository's root as a reader would paste them (a scene with a floor plane
        # cannot be meshed without bounds: the example once tried).
        for doc in [ROOT / "README.md", ROOT / "docs" / "python.md"]:
            blocks = doc.read_text().split("```python\n")
            self.assertGreater(len(blocks), 1, f"{doc} has no Python block")
            code = blocks[1].split("```", 1)[0]
            self.assertIn(".mesh(", code)
            run = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True)
            self.assertEqual(run.returncode, 0, f"{doc}'s example failed:\n{code}\n{run.stderr}")


if __name__ == "__main__":
    unittest.main()


class Parameters(unittest.TestCase):
    SOURCE = (
        'param width = 40.0 in 10..100 step 1 "Box width (mm)";\n'
        'param style = "round" in ["round", "square"];\n'
        "light point { position: (0, 5, -5) }\n"
        "scene { box((width / 100, 0.5, 0.5)); }\n"
    )

    def test_params_are_listed_and_set(self):
        scene = sdfc.Scene(self.SOURCE, params={"width": 60, "style": "square"})
        width, style = scene.params
        self.assertEqual((width["name"], width["value"], width["default"]), ("width", 60.0, 40.0))
        self.assertEqual((width["min"], width["max"], width["step"], width["doc"]), (10.0, 100.0, 1.0, "Box width (mm)"))
        self.assertEqual((style["value"], style["choices"]), ("square", ["round", "square"]))
        # The value reaches the shape: the box is 1.2 wide.
        d, _ = scene.distance(np.array([[0.7, 0.0, 0.0]]))
        self.assertAlmostEqual(float(d[0]), 0.1, places=5)

    def test_a_value_outside_is_refused_naming_the_keyword(self):
        with self.assertRaises(sdfc.CompileError) as e:
            sdfc.Scene(self.SOURCE, params={"width": 500})
        self.assertIn('params={"width": 500}', str(e.exception))
