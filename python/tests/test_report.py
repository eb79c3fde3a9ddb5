"""The report, the per-patch table and the form factors: the command line's documents for the same run
(when an ``scx`` binary is at hand), and invariants that hold whatever the run."""

from __future__ import annotations

import json
import subprocess

import numpy as np
import pytest
import scx
from conftest import cube_grid, scx_binary

# The fields of a report that belong to the process, not the run: two processes computing the same
# numbers differ there.
PROCESS = {"command_line", "cpu", "threads", "seconds", "build_seconds"}


def run_cli(*args: str) -> dict:
    binary = scx_binary()
    if binary is None:
        pytest.skip("no scx binary (set SCX_BIN, or cargo build --release)")
    out = subprocess.run([binary, *args, "--format", "json", "-q"], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    return json.loads(out.stdout)


def without_process(doc: dict) -> dict:
    return {k: v for k, v in doc.items() if k not in PROCESS}


def test_to_dict_is_the_json_of_scx_analyze(tmp_path):
    a = scx.analyze("@cube:4", lines=2e5, seed=3)
    doc = a.to_dict()
    assert not {"command_line", "cpu", "threads"} & set(doc)
    cli = run_cli("analyze", "@cube:4", "--lines", "2e5", "--seed", "3", "--tracer", "rust")
    assert without_process(doc) == without_process(cli)


def test_to_dict_of_a_lit_scene_from_arrays_read_back_from_a_file(tmp_path):
    # The scene built from arrays, written as OBJ with its materials, analysed by both, per-patch
    # results (the objects' shares) and radiosity included; the command line with 2 threads, Python
    # with 1: the numbers do not depend on it.
    vertices, triangles, cells = cube_grid(3)
    emission = np.where(cells == 4, 5.0, 0.0)
    objects = np.where(cells < 9, "floor", "rest")
    scene = scx.Scene.from_arrays(
        vertices, triangles, patches=cells, reflectance=0.6, emission=emission, objects=objects
    )
    path = str(tmp_path / "lit.obj")
    scene.export(path)
    a = scx.analyze(scx.load(path), lines=3e5, seed=2, threads=1, per_patch=True, errors="jackknife")
    cli = run_cli(
        "analyze", path, "--lines", "3e5", "--seed", "2", "--tracer", "rust", "--threads", "2",
        "--errors", "jackknife", "--objects", str(tmp_path / "objects.csv"),
    )
    assert cli["radiosity"] is not None
    assert without_process(a.to_dict()) == without_process(cli)


def test_to_dict_of_shards_merged_is_the_json_of_scx_merge(tmp_path):
    scene = scx.load("@cube:3")
    parts = [str(tmp_path / f"s{k}.scx") for k in (1, 2)]
    for k, p in enumerate(parts, start=1):
        scx.analyze(scene, lines=3e5, seed=4, shard=(k, 2), save=p)
    merged = scx.merge(parts)
    cli = run_cli("merge", *parts)
    assert without_process(merged.to_dict()) == without_process(cli)


def test_per_patch_terms_add_up_to_the_scenes_measures():
    vertices, triangles, cells = cube_grid(3)
    scene = scx.Scene.from_arrays(vertices, triangles, patches=cells)
    a = scx.analyze(scene, lines=3e5, per_patch=True)
    p = a.patches()
    assert len(p["id"]) == scene.patch_count
    np.testing.assert_allclose(p["area"], scene.areas)
    total = lambda column: float(np.sum(p[column]))  # noqa: E731
    assert total("mutual_information_term") == pytest.approx(a.mutual_information.value, rel=1e-9)
    assert total("mutual_information_term_corrected") == pytest.approx(
        a.mutual_information_corrected.value, rel=1e-9
    )
    assert total("continuous_mutual_information_term") == pytest.approx(
        a.continuous_mutual_information.value, rel=1e-9
    )
    # H_s = sum a_i H_i (eq. 17), and the information lost is I_s^c - I_s, patch by patch.
    assert float(np.sum(p["area_fraction"] * p["row_entropy"])) == pytest.approx(a.entropy.value, rel=1e-9)
    assert total("lost_information") == pytest.approx(
        a.continuous_mutual_information.value - a.mutual_information.value, rel=1e-9
    )
    assert int(np.sum(p["segments"])) == 2 * a.pairs
    assert p["object"].dtype.kind == "U" and p["sampled"].dtype == bool
    with pytest.raises(ValueError, match="per_patch=True"):
        scx.analyze(scene, lines=1e5).patches()


def test_patches_frame_and_objects():
    pd = pytest.importorskip("pandas")
    a = scx.analyze("@cube:3", lines=2e5, per_patch=True)
    frame = a.patches_frame()
    assert isinstance(frame, pd.DataFrame) and frame.index.name == "id"
    assert len(frame) == 54
    assert frame["continuous_mutual_information_term"].sum() == pytest.approx(
        a.continuous_mutual_information.value, rel=1e-9
    )
    objects = a.objects_frame()
    assert objects.loc["@cube:3", "patches"] == 54


def test_form_factors_rows_sum_to_one_and_are_reciprocal():
    pytest.importorskip("scipy")
    vertices, triangles, cells = cube_grid(3, "centre")
    scene = scx.Scene.from_arrays(vertices, triangles, patches=cells)
    a = scx.analyze(scene, lines=1e6, seed=9)
    F, se = a.form_factors()
    n = scene.patch_count
    assert F.shape == (n, n) and se.shape == (n, n)
    assert F.format == "csr" and F.nnz == se.nnz
    # A closed scene: every segment ends on a patch, so each row of F sums to 1.
    np.testing.assert_allclose(np.asarray(F.sum(axis=1)).ravel(), 1.0, rtol=1e-12)
    # A patch does not see itself (planar patches), and reciprocity A_i F_ij = A_j F_ji within the
    # errors of the two estimates.
    assert F.diagonal().max() == 0
    A = scene.areas
    left = (F.multiply(A[:, None])).toarray()
    errors = (se.multiply(A[:, None])).toarray()
    gap = np.abs(left - left.T)
    bound = 4 * np.sqrt(errors**2 + errors.T**2)
    assert np.all(gap <= bound + 1e-15)
    # Opposite faces of the cube (cells 0-8 at x = 0, 9-17 at x = 1) see each other with the
    # closed-form form factor of two parallel unit squares a unit apart.
    face, other = np.arange(9), np.arange(9, 18)
    block = (F[face][:, other].multiply(A[face][:, None])).sum() / A[face].sum()
    x = 1.0
    s1 = np.sqrt(1 + x * x)
    exact = 2 / (np.pi * x * x) * (
        np.log(np.sqrt((1 + x * x) ** 2 / (1 + 2 * x * x)))
        + 2 * x * s1 * np.arctan(x / s1)
        - 2 * x * np.arctan(x)
    )
    assert exact == pytest.approx(0.19982, abs=1e-5)
    entries = a.form_factor_entries()
    segments = np.unique(np.stack([entries["i"], entries["n_i"]]), axis=1)
    n_face = segments[1][np.isin(segments[0], face)].sum()
    assert abs(block - exact) < 4 * np.sqrt(exact * (1 - exact) / n_face), (block, exact)
    assert set(entries) == {"i", "j", "n_ij", "n_i", "f_ij", "f_ij_stderr"}
    assert entries["n_ij"].sum() == 2 * a.pairs
    with pytest.raises(ValueError, match="no form factors"):
        scx.analyze(scene, lines=1e5, measures=["continuous"]).form_factors()


def test_to_dict_of_a_sobol_run_is_the_json_of_scx_analyze():
    a = scx.analyze("@cube:4", lines=2e5, seed=3, sampler="sobol", threads=1)
    assert a.to_dict()["sampler"] == "sobol"
    # lines_through="auto": a cube's box is smaller than its sphere, so sobol lines go through the box.
    assert a.to_dict()["lines_through"] == "box"
    cli = run_cli(
        "analyze", "@cube:4", "--lines", "2e5", "--seed", "3", "--tracer", "rust", "--sampler", "sobol"
    )
    assert without_process(a.to_dict()) == without_process(cli)
    independent = scx.analyze("@cube:4", lines=2e5, seed=3, threads=1)
    assert a.continuous_mutual_information.value != independent.continuous_mutual_information.value


def test_to_dict_of_a_run_through_the_box_is_the_json_of_scx_analyze():
    a = scx.analyze("@cube:4", lines=2e5, seed=3, sampler="sobol", lines_through="box", threads=1)
    d = a.to_dict()
    assert d["lines_through"] == "box"
    # lines counts lines through the sphere; a cube's box (half side 1/sqrt(3) in tracing space, grown
    # by 1e-6) meets a share 6 h^2 / pi of them, and the fewest worth 2e5 are drawn.
    h = 1 / np.sqrt(3) + 1e-6
    assert abs(d["lines"] - 2e5 * 6 * h * h / np.pi) < 1.001
    assert d["sphere_lines"] == 200000
    cli = run_cli(
        "analyze", "@cube:4", "--lines", "2e5", "--seed", "3", "--tracer", "rust", "--sampler", "sobol",
        "--lines-through", "box",
    )
    assert without_process(d) == without_process(cli)
    for kwargs in ({"lines_through": "sphere"}, {"sampler": "sobol", "lines_through": "sphere"}):
        d = scx.analyze("@cube:4", lines=2e5, seed=3, threads=1, **kwargs).to_dict()
        assert (d["lines_through"], d["lines"], d["sphere_lines"]) == ("sphere", 200000, 200000)
    # Independent lines (the default with every measure) go through the box too, as many as sobol's.
    independent = scx.analyze("@cube:4", lines=2e5, seed=3, threads=1).to_dict()
    assert (independent["lines_through"], independent["lines"]) == ("box", a.lines)
    # The octahedron is its own bounding polytope: auto draws through it; the icosahedron's faces lie in
    # none of the polytope's planes: auto keeps the sphere.
    for name, through in (("@octahedron", "polytope"), ("@icosahedron", "sphere")):
        assert scx.analyze(name, lines=1e4, sampler="sobol").to_dict()["lines_through"] == through


def test_the_default_sampler_draws_sobol_lines_for_i_s_c_alone():
    # sampler="auto" (the default): Sobol' lines through the box for a run of I_s^c alone, the same
    # numbers as the command line's default; independent lines (through the box too) for every run that
    # counts patch pairs.
    alone = scx.analyze("@cube:4", lines=2e5, seed=3, threads=1, measures=["continuous"]).to_dict()
    assert (alone["sampler"], alone["lines_through"]) == ("sobol", "box")
    cli = run_cli(
        "analyze", "@cube:4", "--lines", "2e5", "--seed", "3", "--tracer", "rust", "--measures", "continuous"
    )
    assert without_process(alone) == without_process(cli)
    # Sobol' runs take 8 groups unless told otherwise, as the command line's; independent ones 16.
    assert alone["groups"] == 8
    sixteen = scx.analyze("@cube:4", lines=2e5, seed=3, threads=1, measures=["continuous"], groups=16)
    cli16 = run_cli(
        "analyze", "@cube:4", "--lines", "2e5", "--seed", "3", "--tracer", "rust", "--measures", "continuous",
        "--groups", "16",
    )
    assert sixteen.to_dict()["groups"] == 16
    assert without_process(sixteen.to_dict()) == without_process(cli16)
    for kwargs in ({}, {"measures": ["continuous"], "sampler": "independent"}):
        d = scx.analyze("@cube:4", lines=2e5, seed=3, threads=1, **kwargs).to_dict()
        assert (d["sampler"], d["lines_through"], d["groups"]) == ("independent", "box", 16)


def test_an_enclosed_run_has_the_environment_as_its_last_patch(tmp_path):
    # An open box: the environment closes it, so every row of F (the environment's too) sums to 1 and
    # the per-patch terms, the environment's included, add up to the enclosed scene's measures.
    pytest.importorskip("scipy")
    scene = scx.load("@cornell-open:2")
    a = scx.analyze(scene, lines=3e5, seed=5, enclose=True, per_patch=True)
    p = a.patches()
    n = scene.patch_count
    assert len(p["id"]) == n + 1
    assert p["object"][-1] == "environment"
    assert float(np.sum(p["continuous_mutual_information_term"])) == pytest.approx(
        a.continuous_mutual_information.value, rel=1e-9
    )
    F, _ = a.form_factors()
    assert F.shape == (n + 1, n + 1)
    np.testing.assert_allclose(np.asarray(F.sum(axis=1)).ravel(), 1.0, rtol=1e-12)
    cli = run_cli(
        "analyze", "@cornell-open:2", "--lines", "3e5", "--seed", "5", "--tracer", "rust",
        "--enclose", "--patches", str(tmp_path / "p.csv"),
    )
    assert without_process(a.to_dict()) == without_process(cli)
