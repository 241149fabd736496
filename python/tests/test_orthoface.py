"""The Python module against the command line it shares its code with.

Run from ctest (python/CMakeLists.txt): PYTHONPATH holds the built module, ORTHOFACE_CLI the
built `orthoface` binary that makes the simulated pair and the reference outputs.
"""

import json
import os
import pathlib
import subprocess
import tempfile
import unittest

import numpy as np

import orthoface

CLI = os.environ.get("ORTHOFACE_CLI", "")


def cli(*args, cwd):
    """Runs `orthoface ARGS` in cwd; fails the test with its stderr when it fails."""
    r = subprocess.run([CLI, *map(str, args)], cwd=cwd, capture_output=True, text=True)
    if r.returncode != 0:
        raise AssertionError(f"orthoface {' '.join(map(str, args))}: {r.stderr}")
    return r


def psnr(a, b):
    """Peak signal-to-noise ratio in dB of two 8-bit images (inf when equal)."""
    mse = np.mean((a.astype(np.float64) - b.astype(np.float64)) ** 2)
    return float("inf") if mse == 0 else 10 * np.log10(255.0**2 / mse)


@unittest.skipUnless(os.path.isfile(CLI), "ORTHOFACE_CLI does not name the built orthoface")
class OrthofaceTest(unittest.TestCase):
    """One simulated subject, reconstructed by the CLI and from Python, shared by every test."""

    @classmethod
    def setUpClass(cls):
        cls._tmp = tempfile.TemporaryDirectory(prefix="orthoface_python_")
        cls.work = pathlib.Path(cls._tmp.name)
        cli("simulate", "--subject", 2, "--out", "sim", cwd=cls.work)
        cls.sim = cls.work / "sim"
        cli("reconstruct", "--front", "sim/front.png", "--side", "sim/side.png", "--rig",
            "sim/rig.yaml", "--out", "rec", cwd=cls.work)
        cli("render", "rec", "--yaw", 30, "-o", "v.png", cwd=cls.work)
        cls.model = orthoface.reconstruct(cls.sim / "front.png", str(cls.sim / "side.png"),
                                          rig=cls.sim / "rig.yaml")

    @classmethod
    def tearDownClass(cls):
        cls._tmp.cleanup()

    def test_model_arrays(self):
        m = self.model
        self.assertEqual(m.vertices.dtype, np.float64)
        self.assertEqual(m.vertices.ndim, 2)
        self.assertEqual(m.vertices.shape[1], 3)
        self.assertGreater(m.vertices.shape[0], 100)
        self.assertEqual(m.triangles.dtype, np.int32)
        self.assertEqual(m.triangles.shape[1], 3)
        self.assertGreaterEqual(m.triangles.min(), 0)
        self.assertLess(m.triangles.max(), m.vertices.shape[0])
        self.assertEqual(m.texture.dtype, np.uint8)
        self.assertEqual(m.texture.ndim, 3)
        self.assertEqual(m.texture.shape[2], 3)
        self.assertGreater(len(m.landmarks), 5)
        for name, p in m.landmarks.items():
            self.assertIsInstance(name, str)
            self.assertEqual(len(p), 3)
        with self.assertRaises(ValueError):  # read-only
            m.vertices[0, 0] = 1.0
        self.assertIn("vertices", repr(m))

    def test_arrays_give_the_same_model_as_paths(self):
        front = orthoface.read_image(self.sim / "front.png")
        side = orthoface.read_image(self.sim / "side.png")
        self.assertEqual(front.dtype, np.uint8)
        self.assertEqual(front.shape[2], 3)
        m = orthoface.reconstruct(front, side[:, :, :], rig=str(self.sim / "rig.yaml"))
        np.testing.assert_allclose(m.vertices, self.model.vertices, atol=1e-9)
        np.testing.assert_array_equal(m.triangles, self.model.triangles)
        # A non-contiguous view of the same pixels is the same image.
        wide = np.zeros((front.shape[0], front.shape[1] * 2, 3), np.uint8)
        wide[:, ::2] = front
        m2 = orthoface.reconstruct(wide[:, ::2], side, rig=self.sim / "rig.yaml")
        np.testing.assert_allclose(m2.vertices, self.model.vertices, atol=1e-9)

    def test_report_has_the_cli_keys(self):
        with open(self.work / "rec" / "report.json") as f:
            cli_report = json.load(f)
        report = self.model.report
        self.assertEqual(set(report), set(cli_report))
        self.assertEqual(report["format"], "orthoface-report")
        self.assertEqual(report["mesh"]["vertices"], self.model.vertices.shape[0])

    def test_render_matches_the_cli(self):
        view = orthoface.render(self.model, yaw=30)
        cli_view = orthoface.read_image(self.work / "v.png")
        self.assertEqual(view.dtype, np.uint8)
        self.assertEqual(view.shape, cli_view.shape)
        value = psnr(view, cli_view)
        print(f"\nPSNR Python render vs CLI render, yaw 30: {value:.2f} dB")
        self.assertGreaterEqual(value, 60.0)
        # The CLI's folder loaded into Python renders the same view.
        loaded = orthoface.load(self.work / "rec")
        self.assertGreaterEqual(psnr(orthoface.render(loaded, yaw=30), cli_view), 60.0)

    def test_render_options(self):
        t = orthoface.render(self.model, yaw=-20, pitch=10, background="transparent",
                             size=(160, 120))
        self.assertEqual(t.shape, (120, 160, 4))
        self.assertEqual(t[0, 0, 3], 0)
        self.assertEqual(t[60, 80, 3], 255)
        b = orthoface.render(self.model, yaw=0, background="#ff0000", head="face",
                             size=(80, 60), blend="pick", unseen="front", equalize=False,
                             float_textures=False)
        self.assertEqual(b.shape, (60, 80, 3))
        self.assertEqual(tuple(b[0, 0]), (0, 0, 255))  # BGR

    def test_save_and_load(self):
        out = self.work / "saved"
        self.model.save(out)
        self.assertEqual(sorted(p.name for p in out.iterdir()),
                         sorted(p.name for p in (self.work / "rec").iterdir()))
        loaded = orthoface.load(str(out))
        self.assertEqual(loaded.report, self.model.report)
        self.assertIsNone(loaded.texture)
        self.assertEqual(set(loaded.landmarks), set(self.model.landmarks))
        self.assertEqual(loaded.triangles.shape, self.model.triangles.shape)
        again = self.work / "saved_again"
        loaded.save(again)
        with open(again / "report.json") as f:
            self.assertEqual(json.load(f), self.model.report)

    def test_mesh_analyses(self):
        mesh = orthoface.load_mesh(self.sim / "truth.obj")
        self.assertEqual(mesh.vertices.dtype, np.float64)
        self.assertEqual(mesh.triangles.dtype, np.int32)
        self.assertEqual(mesh.vertices.shape[1], 3)
        f = orthoface.features(mesh)
        for key in ("key_vertices", "feature_points", "missing"):
            self.assertIn(key, f)
        self.assertGreater(len(f["feature_points"]), 0)
        p = f["feature_points"][0]
        self.assertEqual(set(p), {"name", "description", "vertex", "position"})
        s = orthoface.similarity(mesh, self.sim / "truth.obj")
        for key in ("mean", "gaussian", "shape_index", "curvedness"):
            self.assertAlmostEqual(s[key], 1.0, places=6)
        cli_out = cli("similarity", "sim/truth.obj", "sim/truth.obj", cwd=self.work).stdout
        self.assertIn(f"shape_index {s['shape_index']:.6f}", cli_out)

    def test_input_check_options(self):
        front, side = self.sim / "front.png", self.sim / "side.png"
        # Swapped photos: refused, or with force modelled and the failure first in the warnings.
        self.assert_refused(ValueError, "input check", orthoface.reconstruct, side, front)
        forced = orthoface.reconstruct(side, front, force=True)
        self.assertTrue(forced.report["warnings"][0].startswith("input check"))
        self.assert_refused(ValueError, "side_camera", orthoface.reconstruct, front, side,
                            side_camera="sideways")
        # The sim's side camera stands on the subject's left: the other side is refused.
        self.assert_refused(ValueError, "input check side_camera", orthoface.reconstruct, front,
                            side, side_camera="right")
        try:
            checked = orthoface.reconstruct(front, side, rig=self.sim / "rig.yaml",
                                            side_camera="left", check_identity=True)
        except RuntimeError as e:
            if "face-recognition weights" in str(e):
                self.skipTest("no face-recognition weights (scripts/fetch-face-model.sh)")
            raise
        self.assertTrue(checked.report["input_check"]["same_person_face"]["passed"])
        self.assertNotIn("same_person_face", self.model.report["input_check"])

    def assert_refused(self, error, needle, fn, *args, **kwargs):
        with self.assertRaises(error) as c:
            fn(*args, **kwargs)
        self.assertIn(needle, str(c.exception))

    def test_bad_input(self):
        missing = self.work / "no_such.png"
        side = self.sim / "side.png"
        front = orthoface.read_image(self.sim / "front.png")
        # reconstruct
        self.assert_refused(RuntimeError, str(missing), orthoface.reconstruct, missing, side)
        self.assert_refused(RuntimeError, "rig", orthoface.reconstruct, front, side,
                            rig=self.work / "no_rig.yaml")
        self.assert_refused(ValueError, "front", orthoface.reconstruct, front[:, :, 0], side)
        self.assert_refused(ValueError, "dtype", orthoface.reconstruct, front.astype(np.float32),
                            side)
        self.assert_refused(ValueError, "side", orthoface.reconstruct, front, front[:, :, :2])
        self.assert_refused(TypeError, "front", orthoface.reconstruct, 42, side)
        self.assert_refused(RuntimeError, "not a readable image", orthoface.reconstruct,
                            self.sim / "landmarks.json", side)
        # render
        self.assert_refused(ValueError, "yaw", orthoface.render, self.model, yaw=200,
                            background="black", size=(40, 30))
        self.assert_refused(ValueError, "pitch", orthoface.render, self.model, pitch=-90,
                            background="black", size=(40, 30))
        self.assert_refused(ValueError, "background", orthoface.render, self.model,
                            background="purple")
        self.assert_refused(ValueError, "purple", orthoface.render, self.model,
                            background="purple")
        self.assert_refused(ValueError, "head", orthoface.render, self.model, head="shoulders")
        self.assert_refused(ValueError, "size", orthoface.render, self.model, size=(0, 10))
        self.assert_refused(ValueError, "blend", orthoface.render, self.model, blend="sharp")
        self.assert_refused(ValueError, "unseen", orthoface.render, self.model, unseen="sideways")
        # load / save / read_image / load_mesh
        self.assert_refused(RuntimeError, "no_dir", orthoface.load, self.work / "no_dir")
        self.assert_refused(RuntimeError, str(missing), orthoface.read_image, missing)
        self.assert_refused(RuntimeError, "not a readable image", orthoface.read_image,
                            self.sim / "landmarks.json")
        self.assert_refused(RuntimeError, "no_mesh.obj", orthoface.load_mesh,
                            self.work / "no_mesh.obj")
        self.assert_refused(TypeError, "mesh", orthoface.load_mesh, 3.5)
        blocker = self.work / "a_file"
        blocker.write_text("x")
        self.assert_refused(RuntimeError, "a_file", self.model.save, blocker)
        # features / similarity
        mesh = orthoface.load_mesh(self.sim / "truth.obj")
        self.assert_refused(ValueError, "neighbourhood", orthoface.features, mesh,
                            neighbourhood=0.9)
        self.assert_refused(TypeError, "orthoface.Mesh", orthoface.similarity, mesh, 7)
        self.assert_refused(ValueError, "geodesics", orthoface.similarity, mesh, mesh, geodesics=1)
        self.assert_refused(ValueError, "radius", orthoface.similarity, mesh, mesh, radius=-1)
        self.assert_refused(RuntimeError, "no_mesh.obj", orthoface.similarity, mesh,
                            self.work / "no_mesh.obj")

    def test_docstrings(self):
        for name in ("reconstruct", "load", "render", "load_mesh", "features", "similarity",
                     "read_image"):
            self.assertTrue(getattr(orthoface, name).__doc__, name)
        for cls, props in ((orthoface.Model, ("vertices", "triangles", "texture", "landmarks",
                                              "report", "save")),
                           (orthoface.Mesh, ("vertices", "triangles"))):
            for p in props:
                self.assertTrue(getattr(cls, p).__doc__, p)


if __name__ == "__main__":
    unittest.main()
