"""Numbers against truth that does not come from scx's own output: closed forms, and invariants."""

from __future__ import annotations

import threading

import numpy as np
import pytest
import scx
from conftest import CUBE4_IS, CUBE_ISC, cube_grid


@pytest.mark.parametrize("n, split", [(1, "diagonal"), (3, "centre")])
def test_continuous_mutual_information_of_the_cube_whatever_its_triangulation(n, split):
    # I_s^c is a property of the surfaces, not of their discretisation (eq. 27): two unrelated
    # triangulations of the unit cube, each triangle its own patch, give its exact value.
    vertices, triangles, _ = cube_grid(n, split)
    scene = scx.Scene.from_arrays(vertices, triangles)
    assert scene.patch_count == len(triangles)
    assert scene.area == pytest.approx(6.0)
    a = scx.analyze(scene, lines=4e5, seed=7)
    isc = a["continuous_mutual_information"]
    assert isc.verdict == "ok"
    assert abs(isc.value - CUBE_ISC) < 4 * isc.stderr, isc
    # A closed scene: nothing escapes.
    assert a.escapes == 0


def test_patches_grouping_triangles_give_the_discrete_measures_of_the_grid():
    # The 4 x 4 cells of each face, each cut into four triangles about its centre and grouped into one
    # patch: the scene is @cube:4's discretisation, whose I_s has a closed form.
    vertices, triangles, cells = cube_grid(4, "centre")
    scene = scx.Scene.from_arrays(vertices, triangles, patches=cells)
    assert scene.patch_count == 96
    np.testing.assert_allclose(scene.areas, 1 / 16)
    a = scx.analyze(scene, lines=6e5, seed=3)
    i_s = a.mutual_information.corrected
    assert i_s.key == "mutual_information_corrected"
    assert abs(i_s.value - CUBE4_IS) < 4 * i_s.stderr, i_s
    # Positional entropy is exact: log2 of the 96 equal patches.
    assert a["positional_entropy"].value == pytest.approx(np.log2(96))
    assert a["positional_entropy"].stderr == 0


def test_the_same_seed_gives_the_same_numbers_for_any_thread_count(cube4):
    one = scx.analyze(cube4, lines=3e5, seed=5, threads=1)
    two = scx.analyze(cube4, lines=3e5, seed=5, threads=2)
    for key in one.keys():
        assert (one[key].value, one[key].stderr) == (two[key].value, two[key].stderr), key


def test_readings_by_key_and_attribute_and_the_catalogue(cube4):
    a = scx.analyze(cube4, lines=1e5)
    assert set(a.keys()) <= set(scx.MEASURES)
    assert a["entropy"].value == a.entropy.value
    assert float(a.entropy) == a.entropy.value
    assert a.entropy.corrected.key == "entropy_corrected"
    assert scx.MEASURES["continuous_mutual_information"].equation == "eq. 27"
    assert "continuous_mutual_information" in a and "nonsense" not in a
    lo, hi = a.entropy.interval_95
    assert lo < a.entropy.value < hi
    with pytest.raises(KeyError):
        a["nonsense"]
    with pytest.raises(AttributeError):
        a.nonsense
    assert a.radiosity is None and a.radiosity_skipped
    # Independent lines through the cube's box: fewer drawn, worth the 1e5 asked through the sphere.
    assert a.sphere_lines == 100_000 and a.lines < 100_000 and a.lines_through == "box"
    assert a.seed == 1 and a.seconds > 0
    assert "I_s^c" in repr(a)


def test_only_the_families_asked_for_are_computed(cube4):
    a = scx.analyze(cube4, lines=1e5, measures=["continuous"])
    assert a["continuous_mutual_information"] is not None
    assert a["mutual_information"] is None


def test_a_lit_scene_has_radiosity_measures():
    vertices, triangles, cells = cube_grid(2)
    emission = np.where(cells == 0, 1.0, 0.0)
    scene = scx.Scene.from_arrays(vertices, triangles, patches=cells, emission=emission, reflectance=0.7)
    a = scx.analyze(scene, lines=2e5)
    assert a.radiosity is not None
    assert set(a.radiosity) == set(scx.RADIOSITY_MEASURES)
    assert all(r.family == "radiosity" for r in a.radiosity.values())


def test_the_gil_is_released_while_lines_are_traced(cube4):
    # Another Python thread runs while the lines are traced: the run does not hold the GIL.
    counts = []
    done = threading.Event()

    def count():
        n = 0
        while not done.is_set():
            n += 1
        counts.append(n)

    worker = threading.Thread(target=count)
    worker.start()
    seen = []
    try:
        a = scx.analyze(cube4, lines=2e6, threads=1, progress=lambda d, t: seen.append(d))
    finally:
        done.set()
        worker.join()
    assert counts[0] > 10_000
    # The callback saw the run end, with the lines in all: those drawn (through the cube's box), worth
    # the 2e6 asked through the sphere.
    assert seen[-1] == a.lines and a.sphere_lines == 2_000_000


def test_trimesh_box_turned_inside_out_is_the_cube():
    trimesh = pytest.importorskip("trimesh")
    box = trimesh.creation.box(extents=(1.0, 1.0, 1.0))
    box.invert()
    scene = scx.Scene.from_trimesh(box)
    assert scene.patch_count == 12
    a = scx.analyze(scene, lines=3e5)
    isc = a["continuous_mutual_information"]
    assert abs(isc.value - CUBE_ISC) < 4 * isc.stderr, isc
