"""scx from Python: the information-theoretic scene complexity of Feixas, del Acebo, Bekaert and Sbert,
*An information theory framework for the analysis of scene complexity* (Eurographics 1999).

Global lines are cast through a triangle scene; from the pairs of mutually visible points come the form
factors, the visibility entropy H_s (eq. 17), the mutual information I_s (eq. 21), the continuous mutual
information I_s^c (eq. 27), E(MSE) (eq. 22) and, when the scene emits, the radiosity measures (sec. 4),
each with its standard error and a reliability verdict. The numbers are those of the command line ``scx``
for the same settings, to the bit.

>>> import numpy as np, scx
>>> scene = scx.load("@cube:4")                      # or scx.Scene.from_arrays(vertices, triangles)
>>> a = scx.analyze(scene, lines=2e5, seed=1)
>>> a["continuous_mutual_information"].value         # doctest: +SKIP
1.6...

This wheel traces with scx's pure-Rust tracer (no Embree): both tracers give the same hits.
"""

from __future__ import annotations

import os
import sys
from contextlib import contextmanager
from typing import Any, Callable, Dict, Iterator, Optional, Sequence, Tuple, Union

import numpy as np

from . import _native
from ._native import (
    COLORS,
    MEASURES,
    RADIOSITY_MEASURES,
    TRACER,
    Analysis,
    MeasureInfo,
    Reading,
    Scene,
    SceneError,
    __version__,
    load,
)

__all__ = [
    "COLORS",
    "MEASURES",
    "RADIOSITY_MEASURES",
    "TRACER",
    "Analysis",
    "MeasureInfo",
    "Reading",
    "Scene",
    "SceneError",
    "ScxWarning",
    "__version__",
    "analyze",
    "builtins",
    "load",
    "merge",
    "render",
    "resume",
]

PathLike = Union[str, "os.PathLike[str]"]
Progress = Union[bool, None, Callable[[int, Optional[int]], Any]]


class ScxWarning(UserWarning):
    """What scx says about a scene or a run without refusing it: dropped zero-area triangles, split
    non-planar polygons, an open scene, unsampled patches, a noisy picture. The command line prints the
    same sentences on standard error."""


def builtins() -> Dict[str, str]:
    """The built-in scenes: each usage (``"@cube[:N]"``) and what it is, as ``scx scenes`` lists them."""
    return dict(_native.builtins())


def _as_scene(scene: Union[Scene, PathLike]) -> Scene:
    """A Scene as it is; a path or a built-in name read with :func:`load`'s defaults."""
    if isinstance(scene, Scene):
        return scene
    if isinstance(scene, (str, os.PathLike)):
        return load(scene)
    raise ValueError(f"scene must be a Scene, a path or a built-in name such as '@cube:10', not {scene!r}")


class _TextProgress:
    """A percentage on standard error, when tqdm is not installed."""

    def __init__(self) -> None:
        self.shown = -1

    def __call__(self, done: int, total: Optional[int]) -> None:
        if total:
            percent = int(100 * done / total)
            if percent != self.shown:
                self.shown = percent
                sys.stderr.write(f"\rscx: {percent:3d}% of {total:.3g} lines")
        else:
            sys.stderr.write(f"\rscx: {done:.3g} lines")
        sys.stderr.flush()

    def close(self) -> None:
        sys.stderr.write("\n")


class _Tqdm:
    """A tqdm bar fed with the lines started."""

    def __init__(self) -> None:
        from tqdm.auto import tqdm  # type: ignore[import-untyped,unused-ignore]

        self.bar = tqdm(unit=" lines", unit_scale=True, dynamic_ncols=True)

    def __call__(self, done: int, total: Optional[int]) -> None:
        if total is not None and self.bar.total != total:
            self.bar.total = total
            self.bar.refresh()
        self.bar.update(done - self.bar.n)

    def close(self) -> None:
        self.bar.close()


@contextmanager
def _progress(progress: Progress) -> Iterator[Optional[Callable[[int, Optional[int]], Any]]]:
    """The callback the run calls with (lines started, lines in all or None): the caller's own, a tqdm
    bar for ``True`` (a percentage on standard error without tqdm), or none."""
    if progress is None or progress is False:
        yield None
        return
    if progress is True:
        try:
            shown: Any = _Tqdm()
        except ImportError:
            shown = _TextProgress()
        try:
            yield shown
        finally:
            shown.close()
        return
    if not callable(progress):
        raise ValueError(f"progress must be True, False or a callable (done, total), not {progress!r}")
    yield progress


def analyze(
    scene: Union[Scene, PathLike],
    lines: Union[int, float, None] = None,
    seed: Union[int, float] = 1,
    *,
    threads: int = 0,
    measures: Union[str, Sequence[str], None] = None,
    target_stderr: Optional[float] = None,
    target_measure: str = "mutual_information_corrected",
    seconds: Optional[float] = None,
    enclose: bool = False,
    groups: Optional[int] = None,
    estimator: str = "chao-wang-jost",
    errors: str = "groups",
    bundle: int = 0,
    sampler: str = "auto",
    lines_through: str = "auto",
    per_patch: bool = False,
    shard: Optional[Tuple[int, int]] = None,
    save: Optional[PathLike] = None,
    keep_state: bool = True,
    progress: Progress = False,
) -> Analysis:
    """Analyses a scene: casts global lines through it and estimates every measure of the paper with its
    standard error and reliability verdict, exactly as ``scx analyze --tracer rust`` does for the same
    settings (the same numbers, to the bit, for any number of threads).

    The GIL is released while the lines are traced; Ctrl-C stops the run after the batches under way and
    raises ``KeyboardInterrupt`` (having saved the state first when ``save`` is given).

    Args:
        scene: a :class:`Scene`, or a path or built-in name (``"@cube:10"``) read with :func:`load`.
        lines: global lines to cast (``1e7`` is fine), counted as lines through the bounding sphere
            (``lines_through``). Default 1e6, or no limit with ``seconds`` or ``target_stderr`` (then
            ``lines`` only caps the run).
        seed: seed of the line streams: the same seed gives the same lines and the same numbers.
        threads: worker threads; 0 for every core. The numbers do not depend on it.
        measures: which families to compute: a list of ``"discrete"``, ``"continuous"``,
            ``"radiosity"``. Default: all that apply (radiosity needs an emitting material).
        target_stderr: stop when the standard error of ``target_measure`` is at most this and its
            verdict is ``ok``.
        target_measure: the measure ``target_stderr`` watches (a key of :data:`MEASURES` whose
            ``target`` is true).
        seconds: stop after this many seconds.
        enclose: close an open scene with a virtual absorbing sphere (``scx analyze --enclose``).
        groups: independent groups behind each standard error (2 to 1024); default 16, or 8 for
            ``sobol`` lines (each group one randomised sequence, tighter when longer).
        estimator: the bias-corrected entropies' estimator: ``plug-in``, ``miller-madow``,
            ``grassberger``, ``chao-shen``, ``chao-wang-jost``.
        errors: standard errors of the count-based measures: ``"groups"`` (batch means) or
            ``"jackknife"``.
        bundle: cast bundles of ``bundle x bundle`` parallel lines; 0 for independent lines.
        sampler: ``"independent"`` lines, ``"sobol"``: randomised quasi-Monte Carlo lines (one
            scrambled Sobol' sequence per group), tighter for I_s^c, form factors and E(MSE); not with
            ``bundle`` (docs/sampling.md); or ``"auto"``: ``"sobol"`` for a run that counts no patch
            pairs (``measures=["continuous"]`` without ``per_patch``), ``"independent"`` otherwise.
        lines_through: ``"sphere"`` (the paper's global lines, through the bounding sphere), ``"box"``
            (through the scene's bounding box, the sphere's lines that meet it, so none is spent missing
            it; with ``sampler="sobol"`` far tighter on scenes of axis-aligned walls), ``"polytope"``
            (through the box with its edges and corners cut off; with ``sampler="sobol"`` far tighter on
            solids whose faces it shares, such as the octahedron) (neither with ``bundle`` or
            ``enclose``), or ``"auto"``: for ``sampler="sobol"`` the box when it is smaller than the
            sphere, else the polytope when the scene lies mostly in its faces, else the sphere; for
            independent lines the smallest of the three (the same estimates for less time); the sphere
            with ``bundle`` or ``enclose``. ``lines`` counts lines through the sphere either way: through
            the box fewer are drawn (``to_dict()["lines"]``), worth as many (``["sphere_lines"]``)
            (docs/sampling.md).
        per_patch: also share the measures out among the patches, for :meth:`Analysis.patches`,
            :func:`render` and the objects' shares (with ``enclose``, the environment is the last row) (memory grows with the patches times the groups).
        shard: ``(k, m)``: cast only shard k (from 1) of m of the run's batches; needs ``save``
            (:func:`merge` joins the shards).
        save: write the run's state to this file at the end (and when interrupted), as
            ``scx analyze --save``.
        keep_state: keep the run's state in the analysis, for :meth:`Analysis.save` (it takes about as
            much memory as the pair counts).
        progress: ``True`` for a tqdm bar (a percentage on standard error without tqdm), or a callable
            ``progress(done, total)`` called every 50 ms with the lines started and the lines in all
            (``None`` for a run with a budget); an exception it raises stops the run and is raised.

    Returns:
        Analysis: every reading, by key (``a["continuous_mutual_information"]``) or attribute.

    Raises:
        SceneError: the scene's materials are unphysical (radiosity).
        ValueError: a bad argument (the message says what is allowed).
        KeyboardInterrupt: Ctrl-C during the run.
    """
    scene = _as_scene(scene)
    with _progress(progress) as callback:
        return _native.analyze(
            scene,
            lines,
            seed,
            threads=threads,
            measures=measures,
            target_stderr=target_stderr,
            target_measure=target_measure,
            seconds=seconds,
            enclose=enclose,
            groups=groups,
            estimator=estimator,
            errors=errors,
            bundle=bundle,
            sampler=sampler,
            lines_through=lines_through,
            per_patch=per_patch,
            shard=shard,
            save=save,
            keep_state=keep_state,
            progress=callback,
        )


def resume(
    path: PathLike,
    lines: Union[int, float, None] = None,
    *,
    scene: Union[Scene, PathLike, None] = None,
    threads: int = 0,
    per_patch: bool = False,
    keep_state: bool = True,
    progress: Progress = False,
    read_anywhere: bool = False,
    max_file_size: Optional[int] = None,
) -> Analysis:
    """Continues the run saved in ``path`` (by ``analyze(..., save=...)``, :meth:`Analysis.save` or
    ``scx analyze --save``) with its own settings up to ``lines``, and saves it back to ``path``, as
    ``scx analyze --resume`` does: the result equals the run cast at once, to the bit.

    Args:
        path: the state file.
        lines: the line count to continue to (more than first asked is fine; through the sphere, as
            :func:`analyze` counts them); default the run's own.
        scene: the run's scene when it cannot be read from the name the state keeps: a :class:`Scene`
            (a scene built from arrays must be passed again) or a path; its fingerprint is checked.
        threads, per_patch, keep_state, progress: as for :func:`analyze`.
        read_anywhere, max_file_size: as for :func:`load`, when the scene is read again.

    Raises:
        ValueError: a damaged state, the state of another scene, fewer lines than the run has.
        SceneError: the scene cannot be read again.
    """
    if scene is not None and not isinstance(scene, Scene):
        scene = os.fspath(scene)
    with _progress(progress) as callback:
        return _native.resume(
            path,
            lines,
            scene=scene,
            threads=threads,
            per_patch=per_patch,
            keep_state=keep_state,
            progress=callback,
            read_anywhere=read_anywhere,
            max_file_size=max_file_size,
        )


def merge(
    paths: Sequence[PathLike],
    *,
    scene: Union[Scene, PathLike, None] = None,
    partial: bool = False,
    threads: int = 0,
    per_patch: bool = False,
    save: Optional[PathLike] = None,
    keep_state: bool = True,
    read_anywhere: bool = False,
    max_file_size: Optional[int] = None,
) -> Analysis:
    """Joins the saved states of a run's shards (or any parts of one run) into the analysis of the whole
    run, identical to the run cast at once, as ``scx merge`` does.

    Args:
        paths: the state files, in any order.
        scene: the run's scene when it is not where the states say (see :func:`resume`).
        partial: analyse the lines the states cover even when batches are missing (with a warning);
            without it, missing batches are an error naming the missing lines.
        threads, per_patch, keep_state: as for :func:`analyze`.
        save: also save the merged state to this file.
        read_anywhere, max_file_size: as for :func:`load`.

    Raises:
        ValueError: states of different runs, overlapping states, missing batches.
    """
    if scene is not None and not isinstance(scene, Scene):
        scene = os.fspath(scene)
    if isinstance(paths, (str, bytes, os.PathLike)):
        raise ValueError(f"paths must be a list of state files, not one path: {paths!r}")
    return _native.merge(
        list(paths),
        scene=scene,
        partial=partial,
        threads=threads,
        per_patch=per_patch,
        save=save,
        keep_state=keep_state,
        read_anywhere=read_anywhere,
        max_file_size=max_file_size,
    )


def render(
    subject: Union[Scene, Analysis, PathLike],
    color: Optional[str] = "continuous-mutual-information",
    *,
    size: Tuple[int, int] = (800, 600),
    camera: Optional[Sequence[float]] = None,
    path: Optional[PathLike] = None,
    lines: Union[int, float] = 1e6,
    seed: Union[int, float] = 1,
    threads: int = 0,
    per_area: bool = False,
    range: Optional[Tuple[float, float]] = None,
    scale: str = "auto",
) -> np.ndarray:
    """A picture of the scene with each patch coloured by a per-patch result, through viridis: the
    picture of ``scx render`` without its colour bar, as an ``(h, w, 3)`` uint8 array.

    Args:
        subject: an :class:`Analysis` with per-patch results (``analyze(..., per_patch=True)``), or a
            :class:`Scene` (or path), for which a run of ``lines`` lines from ``seed`` is made, as
            ``scx render`` does.
        color: the per-patch quantity (one of :data:`COLORS`, or its per-patch column name), or
            ``None`` for the scene in plain grey (no run).
        size: ``(width, height)`` in pixels.
        camera: ``(eye, target, up, fov_degrees)`` as 10 numbers in the scene's units; default chosen
            from the geometry (``scx render``'s).
        path: also write the picture to this ``.png`` file.
        lines, seed, threads: the run made for a scene.
        per_area: divide the shares of a sum over patches by the patch's area fraction.
        range: the values at the two ends of the colour scale (default: the 1% and 99% area quantiles).
        scale: ``"linear"``, ``"log"``, or ``"auto"`` (log for the radiosities).

    Returns:
        numpy.ndarray: ``(height, width, 3)`` uint8 RGB, row 0 at the top.

    Raises:
        ValueError: an unknown colour, an analysis without per-patch results, a bad camera or size.
    """
    if not isinstance(subject, (Scene, Analysis)):
        subject = _as_scene(subject)
    if color is not None and isinstance(subject, Scene):
        subject = analyze(subject, lines, seed, threads=threads, per_patch=True)
    return _native.render(
        subject,
        color,
        size=size,
        camera=camera,
        path=path,
        threads=threads,
        per_area=per_area,
        range=range,
        scale=scale,
    )
