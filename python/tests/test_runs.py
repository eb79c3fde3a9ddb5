"""Runs in parts: saved, resumed, sharded, merged, interrupted. The invariant: the analysis is that of the
run cast at once, to the bit."""

from __future__ import annotations

import numpy as np
import pytest
import scx
from conftest import cube_grid

# From 64 x 4096 lines on, every run cuts its lines into batches of 4096: runs of these lengths can be
# parts of one another.
SHORT, LONG = 300_000, 600_000


def numbers(a: scx.Analysis) -> dict:
    """Every number of an analysis that a part of the run could change."""
    out = {"lines": a.lines, "pairs": a.pairs, "escapes": a.escapes, "complete": a.complete}
    for key, r in a.readings().items():
        out[key] = (r.value, r.stderr, r.verdict, r.estimated_bias, r.lines_needed)
    return out


@pytest.fixture(scope="module")
def full(cube4):
    return scx.analyze(cube4, lines=LONG, seed=11)


def test_save_then_resume_to_more_lines_is_the_longer_run(cube4, full, tmp_path):
    state = tmp_path / "run.scx"
    short = scx.analyze(cube4, lines=SHORT, seed=11)
    short.save(state)
    resumed = scx.resume(state, lines=LONG)
    assert numbers(resumed) == numbers(full)
    # The state was saved back: resuming it again casts nothing more and changes nothing.
    again = scx.resume(state)
    assert numbers(again) == numbers(full)


def test_a_state_of_another_scx_version_is_merged_but_not_resumed(cube4, full, tmp_path):
    import struct
    import zlib

    state = tmp_path / "run.scx"
    scx.analyze(cube4, lines=SHORT, seed=11).save(state)
    data = state.read_bytes()
    payload = data[24:]
    here = scx.__version__.encode()
    # The version is a CBOR text string in the identity; stamp it as another of the same length.
    tag = bytes([0x60 + len(here)])
    stamped = payload.replace(tag + here, tag + b"0" * len(here), 1)
    assert stamped != payload
    other = tmp_path / "other.scx"
    other.write_bytes(data[:12] + struct.pack("<QI", len(stamped), zlib.crc32(stamped)) + stamped)
    with pytest.raises(ValueError, match="started by scx 0+, and this is scx"):
        scx.resume(other, lines=LONG)
    assert other.read_bytes()[24:] == stamped
    assert scx.merge([other]).lines == scx.merge([state]).lines


def test_shards_merged_are_the_whole_run(cube4, full, tmp_path):
    parts = [tmp_path / f"shard{k}.scx" for k in (1, 2, 3)]
    for k, path in enumerate(parts, start=1):
        scx.analyze(cube4, lines=LONG, seed=11, shard=(k, 3), save=path)
    merged = scx.merge(reversed(parts))
    assert numbers(merged) == numbers(full)
    with pytest.raises(ValueError, match="lines .* are missing"):
        scx.merge(parts[:2])
    with pytest.warns(scx.ScxWarning, match="lines .* are missing"):
        partial = scx.merge(parts[:2], partial=True)
    assert not partial.complete
    with pytest.raises(ValueError, match="is given twice"):
        scx.merge([parts[0], parts[0]])
    with pytest.raises(ValueError, match="a list of state files"):
        scx.merge(parts[0])


def test_an_interrupted_run_saved_and_resumed_is_the_whole_run(cube4, full, tmp_path):
    state = tmp_path / "interrupted.scx"

    class Stop(Exception):
        pass

    def stop(done, total):
        if done > 100_000:
            raise Stop()

    with pytest.raises(Stop):
        scx.analyze(cube4, lines=LONG, seed=11, save=state, progress=stop)
    assert numbers(scx.resume(state)) == numbers(full)


def test_a_scene_from_arrays_is_passed_again_and_its_fingerprint_checked(tmp_path):
    vertices, triangles, cells = cube_grid(2)
    scene = scx.Scene.from_arrays(vertices, triangles, patches=cells, name="grid")
    state = tmp_path / "arrays.scx"
    scx.analyze(scene, lines=SHORT, save=state)
    with pytest.raises(scx.SceneError, match="must be passed again"):
        scx.resume(state, lines=LONG)
    other = scx.Scene.from_arrays(vertices, triangles, name="grid")
    with pytest.raises(ValueError, match="another scene"):
        scx.resume(state, lines=LONG, scene=other)
    resumed = scx.resume(state, lines=LONG, scene=scene)
    assert numbers(resumed) == numbers(scx.analyze(scene, lines=LONG))


def test_resuming_to_fewer_lines_or_a_damaged_state_is_refused(cube4, tmp_path):
    state = tmp_path / "run.scx"
    scx.analyze(cube4, lines=SHORT, save=state)
    with pytest.raises(ValueError, match="fewer lines"):
        scx.resume(state, lines=SHORT // 2)
    bad = tmp_path / "bad.scx"
    bad.write_bytes(b"not a state")
    with pytest.raises(ValueError, match="not an scx run state"):
        scx.resume(bad)
    with pytest.raises(OSError):
        scx.resume(tmp_path / "missing.scx")


def test_an_analysis_without_its_state_cannot_be_saved(cube4, tmp_path):
    a = scx.analyze(cube4, lines=1e5, keep_state=False)
    with pytest.raises(ValueError, match="keeps no run state"):
        a.save(tmp_path / "x.scx")


def test_a_budget_ends_the_run(cube4):
    a = scx.analyze(cube4, target_stderr=0.05, target_measure="continuous_mutual_information")
    assert a.stop_reason == "target_stderr"
    assert a["continuous_mutual_information"].stderr <= 0.05
