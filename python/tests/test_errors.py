"""Bad input is a Python exception with a message that names the problem, never a crash: SceneError (a
ValueError) for scenes and arrays, ValueError for other arguments, KeyboardInterrupt for Ctrl-C."""

from __future__ import annotations

import signal
import subprocess
import sys
import textwrap
import time

import numpy as np
import pytest
import scx
from conftest import cube_grid

V, T, CELLS = cube_grid(1)


def test_scene_error_is_a_value_error():
    assert issubclass(scx.SceneError, ValueError)


@pytest.mark.parametrize(
    "vertices, triangles, words",
    [
        (np.where(np.arange(V.size).reshape(V.shape) == 4, np.nan, V), T, "vertices[1] has a non-finite"),
        (np.where(np.arange(V.size).reshape(V.shape) == 0, np.inf, V), T, "vertices[0] has a non-finite"),
        (V, np.where(T == T.max(), len(V), T), f"numbered from 0 to {len(V) - 1}"),
        (V, np.where(T == 0, -1, T), "names vertex -1"),
        (V[:, :2], T, f"vertices must have shape (n, 3), not ({len(V)}, 2)"),
        (V, T[:, :2], "triangles must have shape (m, 3), not (12, 2)"),
        (V.ravel(), T, "vertices must have shape (n, 3)"),
        (V, T.astype(float), "triangles must hold integers, not floats"),
        (V.astype(str), T, "vertices must hold real numbers, not text"),
        (V, T[:0], "triangles is empty"),
        ([[0, 0, 0], [1, 0], [0, 1, 0]], [[0, 1, 2]], "vertices is not an array of numbers"),
        (np.zeros((3, 3)), [[0, 1, 2]], "the scene has no"),
        (np.zeros((0, 3)), [[0, 1, 2]], "vertices is empty"),
    ],
)
def test_bad_arrays(vertices, triangles, words):
    with pytest.raises(scx.SceneError) as e:
        scx.Scene.from_arrays(vertices, triangles)
    assert words in str(e.value)


def test_bad_per_triangle_arrays():
    with pytest.raises(scx.SceneError, match="patches must have shape"):
        scx.Scene.from_arrays(V, T, patches=np.zeros(5, dtype=int))
    with pytest.raises(scx.SceneError, match="patches must hold integers"):
        scx.Scene.from_arrays(V, T, patches=np.zeros(len(T)))
    with pytest.raises(scx.SceneError, match="reflectance must be a number, or have shape"):
        scx.Scene.from_arrays(V, T, reflectance=np.ones(3))
    with pytest.raises(scx.SceneError, match=r"emission\[2\] is not finite"):
        scx.Scene.from_arrays(V, T, emission=np.where(np.arange(len(T)) == 2, np.nan, 0.0))
    # The library's own message for an unphysical material.
    with pytest.raises(scx.SceneError, match=r"reflectance \(Kd\) red channel is 2"):
        scx.Scene.from_arrays(V, T, reflectance=2.0)
    with pytest.raises(scx.SceneError, match="objects must have shape"):
        scx.Scene.from_arrays(V, T, objects=[1, 2])
    # A patch of two faces that meet at an edge only is not one polygon... of one plane either way:
    # here, two opposite faces of the cube (apart).
    apart = np.zeros(len(T), dtype=int)
    with pytest.raises(scx.SceneError, match="not one polygon"):
        scx.Scene.from_arrays(V, T, patches=apart)
    with pytest.raises(scx.SceneError, match="different reflectance"):
        scx.Scene.from_arrays(V, T, patches=CELLS, reflectance=np.linspace(0, 1, len(T)))


def test_bad_files_and_built_ins(tmp_path):
    with pytest.raises(scx.SceneError) as e:
        scx.load(tmp_path / "missing.obj")
    assert "missing.obj" in str(e.value)
    bad = tmp_path / "bad.obj"
    bad.write_text("v 0 0 0\nf 1 2 3\n")
    with pytest.raises(scx.SceneError, match="bad.obj"):
        scx.load(bad)
    with pytest.raises(scx.SceneError, match="nosuchscene"):
        scx.load("@nosuchscene")
    with pytest.raises(scx.SceneError):
        scx.load("@cube:0")
    with pytest.raises(ValueError, match="must be a path"):
        scx.load(3)


@pytest.mark.parametrize(
    "kwargs, words",
    [
        ({"lines": 0}, "lines must be a whole number from 1 to 1e15"),
        ({"lines": -5}, "lines must be a whole number"),
        ({"lines": 1.5}, "lines must be a whole number"),
        ({"lines": "1e6"}, "lines must be a whole number"),
        ({"lines": float("nan")}, "lines must be a whole number"),
        ({"seed": -1}, "seed must be a whole number from 0"),
        ({"threads": 5000}, "from 0 to 4096"),
        ({"groups": 1}, "groups must be a whole number from 2 to 1024"),
        ({"measures": ["nope"]}, "`nope` is not one of discrete, continuous, radiosity"),
        ({"measures": []}, "measures is empty"),
        ({"target_measure": "nope"}, "target_measure: `nope` is not one of"),
        ({"target_stderr": -1.0}, "target_stderr must be a positive number"),
        ({"seconds": 0}, "seconds must be a positive number"),
        ({"estimator": "nope"}, "estimator: `nope` is not one of"),
        ({"errors": "nope"}, "errors: `nope` is not one of groups, jackknife"),
        ({"bundle": 10_000}, "bundle"),
        ({"shard": (1, 2)}, "shard needs save=PATH"),
        ({"shard": (3, 2), "save": "x.scx"}, "the shard k must be a whole number from 1 to 2"),
        ({"sampler": "halton"}, "sampler: `halton` is not one of auto, independent, sobol"),
        ({"sampler": "sobol", "bundle": 4}, "does not take bundles"),
        ({"lines_through": "cube"}, "lines_through: `cube` is not one of auto, sphere, box, polytope"),
        ({"lines_through": "box", "bundle": 4}, "do not come in bundles"),
        ({"lines_through": "box", "enclose": True}, "use lines through the sphere with --enclose"),
        ({"progress": 3}, "progress must be True, False or a callable"),
    ],
)
def test_bad_arguments(cube4, kwargs, words):
    with pytest.raises(ValueError) as e:
        scx.analyze(cube4, **kwargs)
    assert words in str(e.value)
    assert not isinstance(e.value, scx.SceneError)


def test_an_exception_in_the_progress_callback_stops_the_run_and_is_raised(cube4):
    class Enough(Exception):
        pass

    def stop(done, total):
        if done > 0:
            raise Enough()

    with pytest.raises(Enough):
        scx.analyze(cube4, lines=1e10, progress=stop)


def test_ctrl_c_raises_keyboard_interrupt_promptly_and_the_interpreter_lives_on():
    # A run of 1e12 lines (hours) in a child interpreter, interrupted once it is casting.
    script = textwrap.dedent(
        """
        import signal, sys, time, scx
        signal.signal(signal.SIGINT, signal.default_int_handler)
        scene = scx.load("@cube:10")
        started = []
        def progress(done, total):
            if done and not started:
                started.append(time.monotonic())
                print("casting", flush=True)
        try:
            scx.analyze(scene, lines=1e12, progress=progress)
        except KeyboardInterrupt:
            print("KeyboardInterrupt", flush=True)
        print("alive", sum(range(10)), flush=True)
        """
    )
    child = subprocess.Popen(
        [sys.executable, "-c", script], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True
    )
    try:
        assert child.stdout.readline().strip() == "casting"
        sent = time.monotonic()
        child.send_signal(signal.SIGINT)
        out, err = child.communicate(timeout=30)
        waited = time.monotonic() - sent
    finally:
        if child.poll() is None:
            child.kill()
    assert out.split("\n")[:2] == ["KeyboardInterrupt", "alive 45"], (out, err)
    assert child.returncode == 0, err
    # Promptly: the batches under way finish, then the exception (the interpreter's exit included).
    assert waited < 2.0, waited
