"""Mesh files of `sdfc mesh` read by outside libraries (issue 51 item 6): the 3MF Consortium's
lib3mf reads every 3MF package (millimetres, an object per material with its colour), and
manifold3d checks every mesh, STL and 3MF, a closed 2-manifold, on a few parts of examples/.
The parts of a 3MF do not overlap: their volumes add up to the STL's.

Run by .ci/run against $SDFC_BIN (else target/release/sdfc); needs no wheel. Without lib3mf or
manifold3d these tests are skipped, except under SDFC_REQUIRE_DEVICES=1 (CI), where that
fails them."""

import os
import subprocess
import tempfile
import unittest
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]

try:
    import lib3mf
    import manifold3d
except ImportError as e:  # pragma: no cover - depends on the environment
    MISSING = str(e)
else:
    MISSING = None

if MISSING and os.environ.get("SDFC_REQUIRE_DEVICES") == "1":
    raise ImportError(f"lib3mf and manifold3d are required here (SDFC_REQUIRE_DEVICES=1): {MISSING}")

# (scene, bounds or None, cells along the longest side, the materials of its objects in order)
PARTS = [
    ("examples/mesh/parts.sdf", None, 48, ["clay", "steel", "teal", "slate"]),
    ("examples/mesh/bracket.sdf", None, 64, ["steel"]),
    ("examples/knob.sdf", "-1.2,-0.2,-1.2,1.2,1.3314,1.2", 64, ["floor", "black", "white"]),
    ("examples/gear.sdf", "-2.7877,-0.6146,-2.7877,2.7877,0.6146,2.7877", 64, ["floor", "steel"]),
]


def sdfc_bin() -> str:
    path = os.environ.get("SDFC_BIN") or str(ROOT / "target" / "release" / "sdfc")
    if not os.path.exists(path):
        raise AssertionError(f"the sdfc binary is needed: build it (cargo build --release) or set SDFC_BIN; not found at {path}")
    return path


def mesh(scene: str, out: Path, bounds, resolution: int) -> str:
    args = [sdfc_bin(), "mesh", str(ROOT / scene), "-o", str(out), "--resolution", str(resolution)]
    if bounds:
        args.append(f"--bounds={bounds}")
    run = subprocess.run(args, capture_output=True, text=True)
    if run.returncode != 0:
        raise AssertionError(f"{' '.join(args)}: {run.stderr}")
    return run.stderr


def read_stl(path: Path):
    """A binary STL's triangles, vertices merged by their exact coordinates."""
    data = path.read_bytes()
    count = int.from_bytes(data[80:84], "little")
    rows = np.frombuffer(data, dtype=np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")]), count=count, offset=84)
    corners = rows["v"].reshape(-1, 3)
    vertices, index = np.unique(corners, axis=0, return_inverse=True)
    return vertices.astype(np.float32), index.reshape(-1, 3).astype(np.uint32)


def checked(vertices, triangles, what: str):
    """The manifold3d solid of a mesh, which must be a closed 2-manifold."""
    solid = manifold3d.Manifold(manifold3d.Mesh(np.ascontiguousarray(vertices, dtype=np.float32), np.ascontiguousarray(triangles, dtype=np.uint32)))
    if solid.status() != manifold3d.Error.NoError:
        raise AssertionError(f"{what}: manifold3d says {solid.status()}")
    return solid


def read_3mf(path: Path):
    """The unit, the base materials ({property id: (name, #RRGGBB)}) and the objects (name,
    the property id of its base material, vertices, triangles, manifold by lib3mf) of a 3MF
    package, as lib3mf reads it."""
    wrapper = lib3mf.get_wrapper()
    model = wrapper.CreateModel()
    reader = model.QueryReader("3mf")
    reader.ReadFromFile(str(path))
    if reader.GetWarningCount() != 0:
        raise AssertionError(f"{path.name}: lib3mf warns: {reader.GetWarning(0)}")
    bases = {}
    groups = model.GetBaseMaterialGroups()
    while groups.MoveNext():
        g = groups.GetCurrentBaseMaterialGroup()
        for pid in g.GetAllPropertyIDs():
            c = g.GetDisplayColor(pid)
            bases[pid] = (g.GetName(pid), f"#{c.Red:02X}{c.Green:02X}{c.Blue:02X}")
    objects = []
    it = model.GetMeshObjects()
    while it.MoveNext():
        o = it.GetCurrentMeshObject()
        vertices = np.array([v.Coordinates[0:3] for v in o.GetVertices()], dtype=np.float32)
        triangles = np.array([t.Indices[0:3] for t in o.GetTriangleIndices()], dtype=np.uint32)
        _, pid, has = o.GetObjectLevelProperty()
        objects.append((o.GetName(), pid if has else None, vertices, triangles, o.IsManifoldAndOriented()))
    return model.GetUnit(), bases, objects


@unittest.skipIf(MISSING is not None, f"lib3mf and manifold3d are not installed: {MISSING}")
class MeshFiles(unittest.TestCase):
    def test_parts_are_manifold_in_stl_and_3mf(self):
        with tempfile.TemporaryDirectory() as d:
            for scene, bounds, resolution, materials in PARTS:
                with self.subTest(scene=scene):
                    name = Path(scene).stem
                    stl, tmf = Path(d) / f"{name}.stl", Path(d) / f"{name}.3mf"
                    mesh(scene, stl, bounds, resolution)
                    whole = checked(*read_stl(stl), f"{name}.stl")
                    said = mesh(scene, tmf, bounds, resolution)
                    unit, bases, objects = read_3mf(tmf)
                    self.assertEqual(unit, lib3mf.ModelUnit.MilliMeter)
                    self.assertEqual([o[0] for o in objects], materials, said)
                    volume = 0.0
                    for label, pid, vertices, triangles, manifold in objects:
                        self.assertTrue(manifold, f"{name}.3mf, {label}: lib3mf finds it not manifold")
                        self.assertEqual(bases[pid][0], label)
                        volume += checked(vertices, triangles, f"{name}.3mf, {label}").volume()
                    # The parts do not overlap and make up the solid: their volumes add up to
                    # the whole's, within what the meshes' differences at the seams allow.
                    self.assertAlmostEqual(volume / whole.volume(), 1.0, delta=0.01)

    def test_colours_are_the_materials(self):
        with tempfile.TemporaryDirectory() as d:
            out = Path(d) / "parts.3mf"
            mesh("examples/mesh/parts.sdf", out, None, 32)
            _, bases, _ = read_3mf(out)
            colours = dict(bases.values())

            def srgb(c):  # IEC 61966-2-1's transfer function, to a byte
                e = [12.92 * x if x <= 0.0031308 else 1.055 * x ** (1 / 2.4) - 0.055 for x in c]
                return "#" + "".join(f"{round(255 * x):02X}" for x in e)

            # The scene's colours are linear; 3MF's display colours are sRGB.
            self.assertEqual(colours["clay"], srgb((0.85, 0.45, 0.25)))
            self.assertEqual(colours["slate"], srgb((0.3, 0.32, 0.36)))
            self.assertEqual(colours["teal"], srgb((0.15, 0.6, 0.6)))


if __name__ == "__main__":
    unittest.main()
