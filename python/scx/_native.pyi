"""Types of ``scx._native``, the compiled half of scx (PyO3). The public API is :mod:`scx`, which
re-exports what is here; the functions it wraps (``analyze``, ``resume``, ``merge``, ``render``) are
documented there."""

import os
from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple, Union, final

import numpy as np
import numpy.typing as npt

_Path = Union[str, "os.PathLike[str]"]
_Objects = Union[bool, str, Sequence[str], None]
_Number = Union[int, float]
_Progress = Optional[Callable[[int, Optional[int]], Any]]

__all__ = [
    "Analysis",
    "COLORS",
    "MEASURES",
    "MeasureInfo",
    "RADIOSITY_MEASURES",
    "Reading",
    "Scene",
    "SceneError",
    "TRACER",
    "__version__",
    "analyze",
    "builtins",
    "load",
    "merge",
    "render",
    "resume",
]
__version__: str
TRACER: str
"""The tracer this wheel casts lines with: ``"rust"`` (scx's pure-Rust tracer; no Embree)."""
MEASURES: Dict[str, "MeasureInfo"]
"""The visibility measures (paper sec. 3), key to :class:`MeasureInfo`, in report order."""
RADIOSITY_MEASURES: Dict[str, "MeasureInfo"]
"""The radiosity measures (paper sec. 4), key to :class:`MeasureInfo`."""
COLORS: List[str]
"""The per-patch quantities :func:`scx.render` colours by."""

class SceneError(ValueError):
    """A scene that cannot be read or built: a bad file, a bad built-in name, bad arrays (shapes,
    non-finite coordinates, indices out of range). Its message is the library's."""

@final
class MeasureInfo:
    """One entry of the catalogue of measures."""

    @property
    def key(self) -> str:
        """The key (``"continuous_mutual_information"``): the JSON key of the command line's report."""
    @property
    def family(self) -> str:
        """``"visibility"`` or ``"radiosity"``."""
    @property
    def label(self) -> str:
        """What the report's table calls it."""
    @property
    def symbol(self) -> str:
        """Its symbol (``"I_s^c"``)."""
    @property
    def unit(self) -> str:
        """Its unit (``"bit"``, ``"ratio"``, ...)."""
    @property
    def equation(self) -> str:
        """Where the paper defines it (``"eq. 27"``)."""
    @property
    def corrects(self) -> Optional[str]:
        """The key of the plug-in reading this one corrects for bias."""
    @property
    def target(self) -> bool:
        """Whether ``target_stderr`` can watch it."""

@final
class Reading:
    """A measure's reading: value, standard error, verdict. ``float(reading)`` is its value."""

    @property
    def key(self) -> str:
        """The measure's key."""
    @property
    def family(self) -> str:
        """``"visibility"`` or ``"radiosity"``."""
    @property
    def label(self) -> str:
        """What the report's table calls it."""
    @property
    def unit(self) -> str:
        """Its unit."""
    @property
    def value(self) -> float:
        """The value."""
    @property
    def stderr(self) -> Optional[float]:
        """Its standard error (``None`` when it cannot be estimated; 0 for an exact value)."""
    @property
    def verdict(self) -> Optional[str]:
        """``"ok"``, ``"undersampled"`` or ``"unusable"`` (``None`` for an exact reading)."""
    @property
    def estimated_bias(self) -> Optional[float]:
        """The estimated bias, when estimated."""
    @property
    def lines_needed(self) -> Optional[int]:
        """Roughly how many lines in all would make it ``ok``."""
    @property
    def flags(self) -> List[str]:
        """The bounds of the theory it breaks, as sentences."""
    @property
    def interval_95(self) -> Optional[Tuple[float, float]]:
        """The 95% interval (Student's t over the groups)."""
    @property
    def corrected(self) -> Optional["Reading"]:
        """The bias-corrected reading of the same measure, where the catalogue has one."""
    def __float__(self) -> float: ...

@final
class Scene:
    """A triangle scene ready to analyse: patches (the unit of the discretisation), each one or more
    coplanar triangles with an area, a normal, a material and an object. Immutable."""

    @staticmethod
    def from_arrays(
        vertices: npt.ArrayLike,
        triangles: npt.ArrayLike,
        patches: Optional[npt.ArrayLike] = None,
        reflectance: Union[float, npt.ArrayLike, None] = None,
        emission: Union[float, npt.ArrayLike, None] = None,
        objects: Optional[npt.ArrayLike] = None,
        *,
        name: str = "<arrays>",
        planarity: Optional[float] = None,
        strict_planarity: bool = False,
        flip_normals: _Objects = None,
        two_sided: _Objects = None,
    ) -> "Scene":
        """A scene from numpy arrays, built by the library's ``SceneBuilder``.

        Args:
            vertices: ``(n, 3)`` float coordinates.
            triangles: ``(m, 3)`` integer vertex indices (from 0), counter-clockwise seen from the
                triangle's front side (the side that is a surface).
            patches: ``(m,)`` integer patch id of each triangle; the triangles of one id must form one
                planar polygon without holes and share a material and an object. Patches are numbered
                by ascending id. Default: each triangle its own patch, in order.
            reflectance: diffuse reflectance in [0, 1]: a number, ``(m,)`` or ``(m, 3)`` (RGB).
            emission: emitted radiosity >= 0, in the same shapes.
            objects: ``(m,)`` object of each triangle: integers (named ``"object K"``) or names.
            name: the scene's name in reports and saved runs.
            planarity, strict_planarity, flip_normals, two_sided: as for :func:`load`.

        Raises:
            SceneError: wrong shapes or kinds, non-finite coordinates, indices out of range, patches
                that are not one polygon, unphysical materials, a scene without area.
        """
    @staticmethod
    def from_trimesh(mesh: Any, *, name: Optional[str] = None, **kwargs: Any) -> "Scene":
        """A scene from a ``trimesh.Trimesh`` (each face a patch) or ``trimesh.Scene`` (each node an
        object); ``kwargs`` go to :meth:`from_arrays`. Needs trimesh."""
    @property
    def name(self) -> str:
        """The scene's name."""
    @property
    def patch_count(self) -> int:
        """The number of patches."""
    @property
    def triangle_count(self) -> int:
        """The number of triangles."""
    @property
    def areas(self) -> npt.NDArray[np.float64]:
        """Each patch's area in the scene's units, ``(n_p,)``."""
    @property
    def normals(self) -> npt.NDArray[np.float64]:
        """Each patch's unit normal, ``(n_p, 3)``."""
    @property
    def area(self) -> float:
        """The total area in the scene's units."""
    @property
    def vertices(self) -> npt.NDArray[np.float64]:
        """The scene's (welded) vertices in its own units, ``(n, 3)``."""
    @property
    def triangles(self) -> npt.NDArray[np.int64]:
        """The scene's triangles as indices into :attr:`vertices`, ``(t, 3)``."""
    @property
    def triangle_patch(self) -> npt.NDArray[np.int64]:
        """The patch of each of :attr:`triangles`, ``(t,)``."""
    @property
    def objects(self) -> List[str]:
        """The names of the scene's objects."""
    @property
    def patch_object(self) -> npt.NDArray[np.int64]:
        """The object of each patch, as an index into :attr:`objects`."""
    @property
    def warnings(self) -> List[str]:
        """What loading found wrong but not fatal."""
    @property
    def fingerprint(self) -> str:
        """A SHA-256 fingerprint of the geometry and materials (hex)."""
    def export(self, path: _Path) -> None:
        """Writes the scene as its extension says: ``.obj``, ``.ply``, ``.stl``, ``.gltf``, ``.glb``."""
    def __len__(self) -> int: ...

@final
class Analysis:
    """The results of a run: each measure of :data:`MEASURES` by key or attribute, a :class:`Reading`
    (``None`` when not computed)."""

    def __getitem__(self, key: str, /) -> Optional[Reading]:
        """The reading of the visibility measure ``key``, or ``None`` when not computed.

        Raises:
            KeyError: ``key`` is not a measure's.
        """
    def __getattr__(self, name: str, /) -> Optional[Reading]: ...
    def __contains__(self, key: str, /) -> bool: ...
    def keys(self) -> List[str]:
        """The keys of the visibility measures the run computed."""
    def readings(self) -> Dict[str, Reading]:
        """Every computed visibility reading."""
    @property
    def radiosity(self) -> Optional[Dict[str, Reading]]:
        """The radiosity readings, or ``None`` (see :attr:`radiosity_skipped`)."""
    @property
    def radiosity_skipped(self) -> Optional[str]:
        """Why the radiosity measures are missing."""
    @property
    def scene(self) -> Scene:
        """The scene analysed."""
    @property
    def lines(self) -> int:
        """Lines cast: drawn through the bound of :attr:`lines_through`."""
    @property
    def sphere_lines(self) -> int:
        """What the lines cast are worth in lines through the bounding sphere, the unit of ``lines=``."""
    @property
    def lines_through(self) -> str:
        """Where the lines were drawn: ``"sphere"``, ``"box"`` or ``"polytope"``."""
    @property
    def seed(self) -> int:
        """The seed of the line streams."""
    @property
    def seconds(self) -> float:
        """Wall-clock seconds of the run (summed over resumes and merged parts)."""
    @property
    def stop_reason(self) -> str:
        """``"lines"``, ``"seconds"``, ``"target_stderr"``, ``"f32_floor"`` or ``"interrupted"``."""
    @property
    def complete(self) -> bool:
        """Whether the analysis covers every batch of its run."""
    @property
    def groups(self) -> int:
        """The standard-error groups."""
    @property
    def pairs(self) -> int:
        """Visible pairs found."""
    @property
    def escapes(self) -> int:
        """Segments escaping from a front side."""
    @property
    def escape_fraction(self) -> Optional[float]:
        """The fraction of segments that escape."""
    @property
    def warnings(self) -> List[str]:
        """What the user must know about these numbers."""
    @property
    def has_patches(self) -> bool:
        """Whether the run gathered per-patch results."""
    @property
    def spec(self) -> Dict[str, Any]:
        """The run's settings, as its saved state keeps them."""
    def to_dict(self) -> Dict[str, Any]:
        """The document of ``scx analyze --format json`` for the same run, without the fields of the
        process (``command_line``, ``cpu``, ``threads``)."""
    def patches(self) -> Dict[str, npt.NDArray[Any]]:
        """The per-patch results, one numpy array per column of ``scx analyze --patches`` (same
        names). Needs ``per_patch=True``."""
    def patches_frame(self) -> Any:
        """:meth:`patches` as a pandas DataFrame indexed by ``id``. Needs pandas."""
    def objects(self) -> Dict[str, npt.NDArray[Any]]:
        """Each object's results (``scx analyze --objects``), one numpy array per column."""
    def objects_frame(self) -> Any:
        """:meth:`objects` as a pandas DataFrame indexed by object name. Needs pandas."""
    def form_factors(self) -> Tuple[Any, Any]:
        """``(F, F_stderr)``: two ``scipy.sparse.csr_matrix`` of ``n_p x n_p``, ``F_ij = N_ij / N_i``
        and ``sqrt(F_ij (1 - F_ij) / N_i)``. Needs scipy and the discrete measures."""
    def form_factor_entries(self) -> Dict[str, npt.NDArray[Any]]:
        """The entries of F as arrays ``i``, ``j``, ``n_ij``, ``n_i``, ``f_ij``, ``f_ij_stderr``."""
    def save(self, path: _Path) -> None:
        """Saves the run's state (the command line's state file), atomically. Needs
        ``keep_state=True`` (the default)."""

def load(
    path: _Path,
    *,
    planarity: Optional[float] = None,
    strict_planarity: bool = False,
    flip_normals: _Objects = None,
    two_sided: _Objects = None,
    read_anywhere: bool = False,
    max_file_size: Optional[int] = None,
) -> Scene:
    """Reads a scene: a file in OBJ, glTF/GLB, PLY or STL, or a built-in such as ``"@cube:10"``.

    Args:
        path: the file or the built-in's name.
        planarity: the planarity tolerance (fraction of a polygon's size; default 1e-4).
        strict_planarity: refuse non-planar polygons instead of splitting them.
        flip_normals: ``True`` for every object, or the names of the objects whose normals to reverse.
        two_sided: ``True`` or the names of the objects to make two-sided.
        read_anywhere: let the scene's references name files outside its folder.
        max_file_size: the largest file read, in bytes (default 256 MiB).

    Raises:
        SceneError: a missing or bad file, a bad built-in, unusable geometry.
    """

def builtins() -> List[Tuple[str, str]]:
    """The built-in scenes: usage and description."""

def analyze(
    scene: Scene,
    lines: Optional[_Number] = None,
    seed: Optional[_Number] = None,
    *,
    threads: Optional[int] = None,
    measures: Union[str, Sequence[str], None] = None,
    target_stderr: Optional[float] = None,
    target_measure: str = "mutual_information_corrected",
    seconds: Optional[float] = None,
    enclose: bool = False,
    groups: Optional[int] = None,
    estimator: str = "chao-wang-jost",
    errors: str = "groups",
    bundle: Optional[int] = None,
    sampler: str = "auto",
    lines_through: str = "auto",
    per_patch: bool = False,
    shard: Optional[Tuple[int, int]] = None,
    save: Optional[_Path] = None,
    keep_state: bool = True,
    progress: _Progress = None,
) -> Analysis:
    """See :func:`scx.analyze`."""

def resume(
    path: _Path,
    lines: Optional[_Number] = None,
    *,
    scene: Union[Scene, str, None] = None,
    threads: Optional[int] = None,
    per_patch: bool = False,
    keep_state: bool = True,
    progress: _Progress = None,
    read_anywhere: bool = False,
    max_file_size: Optional[int] = None,
) -> Analysis:
    """See :func:`scx.resume`."""

def merge(
    paths: Sequence[_Path],
    *,
    scene: Union[Scene, str, None] = None,
    partial: bool = False,
    threads: Optional[int] = None,
    per_patch: bool = False,
    save: Optional[_Path] = None,
    keep_state: bool = True,
    read_anywhere: bool = False,
    max_file_size: Optional[int] = None,
) -> Analysis:
    """See :func:`scx.merge`."""

def render(
    subject: Union[Scene, Analysis],
    color: Optional[str] = None,
    *,
    size: Optional[Tuple[int, int]] = None,
    camera: Optional[Sequence[float]] = None,
    path: Optional[_Path] = None,
    threads: Optional[int] = None,
    per_area: bool = False,
    range: Optional[Tuple[float, float]] = None,
    scale: str = "auto",
) -> npt.NDArray[np.uint8]:
    """See :func:`scx.render`."""
