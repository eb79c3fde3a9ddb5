"""Scenes: what Python reads of them, exports, and pictures."""

from __future__ import annotations

import struct
import zlib

import numpy as np
import pytest
import scx
from conftest import cube_grid


def test_a_scene_from_arrays_keeps_its_geometry_and_objects():
    vertices, triangles, cells = cube_grid(2)
    objects = np.where(cells < 4, "floor", "walls")
    scene = scx.Scene.from_arrays(vertices, triangles, patches=cells, objects=objects, name="box")
    assert scene.name == "box" and len(scene) == 24
    assert scene.objects == ["floor", "walls"]
    assert np.bincount(scene.patch_object).tolist() == [4, 20]
    # Welded: the 6 x 4 x 4 corners given are the cube's 26 grid points on its surface.
    assert scene.vertices.shape == (26, 3)
    assert scene.triangles.shape[1] == 3 and scene.triangle_patch.shape == (len(scene.triangles),)
    np.testing.assert_allclose(np.linalg.norm(scene.normals, axis=1), 1.0)
    # Each normal points into the cube (its front side faces the inside).
    centres = np.array([scene.vertices[scene.triangles[scene.triangle_patch == p]].mean(axis=(0, 1))
                        for p in range(len(scene))])
    assert np.all(np.einsum("ij,ij->i", scene.normals, 0.5 - centres) > 0)


def test_export_and_load_give_the_same_scene(tmp_path):
    vertices, triangles, cells = cube_grid(2)
    scene = scx.Scene.from_arrays(vertices, triangles, patches=cells)
    for ext in ("ply", "obj"):
        path = tmp_path / f"box.{ext}"
        scene.export(path)
        again = scx.load(path)
        assert again.patch_count == scene.patch_count
        np.testing.assert_allclose(np.sort(again.areas), np.sort(scene.areas))
    # glTF holds triangles: each its own patch, the same surface.
    scene.export(tmp_path / "box.glb")
    again = scx.load(tmp_path / "box.glb")
    assert again.patch_count == scene.triangle_count
    assert again.area == pytest.approx(scene.area)
    with pytest.raises(scx.SceneError):
        scene.export(tmp_path / "box.xyz")


def test_reading_options_reach_the_reader(tmp_path):
    scx.Scene.from_arrays(*cube_grid(1)[:2]).export(tmp_path / "cube.obj")
    one = scx.load(tmp_path / "cube.obj")
    both = scx.load(tmp_path / "cube.obj", two_sided=True)
    assert both.patch_count == 2 * one.patch_count
    flipped = scx.load(tmp_path / "cube.obj", flip_normals=True)
    np.testing.assert_allclose(flipped.normals, -one.normals)
    with pytest.raises(scx.SceneError, match="no object named"):
        scx.load(tmp_path / "cube.obj", two_sided=["nothing"])


def test_warnings_are_python_warnings():
    vertices, triangles, _ = cube_grid(1)
    triangles = np.vstack([triangles, [[0, 0, 1]]])
    with pytest.warns(scx.ScxWarning, match="zero-area"):
        scene = scx.Scene.from_arrays(vertices, triangles)
    assert any("zero-area" in w for w in scene.warnings)


def png_size(path):
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    width, height = struct.unpack(">II", data[16:24])
    return width, height


def test_render_gives_an_rgb_array_and_a_png(cube4, tmp_path):
    a = scx.analyze(cube4, lines=2e5, per_patch=True)
    picture = scx.render(a, "continuous-mutual-information", size=(96, 64), path=tmp_path / "a.png")
    assert picture.shape == (64, 96, 3) and picture.dtype == np.uint8
    assert png_size(tmp_path / "a.png") == (96, 64)
    # The view from inside the cube sees patches of several colours.
    assert len(np.unique(picture.reshape(-1, 3), axis=0)) > 10
    plain = scx.render(cube4, None, size=[32, 32])
    assert plain.shape == (32, 32, 3)
    # The same per-patch column, by its name in the per-patch results.
    same = scx.render(a, "continuous_mutual_information_term", size=(96, 64))
    assert np.array_equal(same, picture)
    camera = (0.5, 0.5, 0.05, 0.5, 0.5, 1.0, 0.0, 1.0, 0.0, 60.0)
    assert scx.render(a, "segments", size=(32, 32), camera=camera).shape == (32, 32, 3)


def test_render_refuses_what_it_cannot_draw(cube4, tmp_path):
    a = scx.analyze(cube4, lines=1e5)
    with pytest.raises(ValueError, match="no per-patch results"):
        scx.render(a, "segments")
    b = scx.analyze(cube4, lines=1e5, per_patch=True)
    with pytest.raises(ValueError, match="is not one of"):
        scx.render(b, "nope")
    with pytest.raises(ValueError, match="needs light"):
        scx.render(b, "radiosity")
    with pytest.raises(ValueError, match="camera"):
        scx.render(b, "segments", camera=(0, 0, 0))
    with pytest.raises(ValueError, match=".png"):
        scx.render(b, "segments", path=tmp_path / "x.jpg")
    with pytest.raises(OSError):
        scx.render(b, "segments", size=(32, 32), path=tmp_path / "missing" / "x.png")
