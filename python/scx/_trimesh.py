"""Scenes from trimesh (``Scene.from_trimesh``): pure Python over :meth:`scx.Scene.from_arrays`."""

from __future__ import annotations

from typing import Any, Optional

import numpy as np


def from_trimesh(mesh: Any, name: Optional[str] = None, **kwargs: Any) -> Any:
    """A :class:`scx.Scene` from a ``trimesh.Trimesh`` (each face a patch, in order) or a
    ``trimesh.Scene`` (its geometries placed by their transforms, each node an object, in the order
    ``Scene.dump`` gives them); ``kwargs`` go to :meth:`scx.Scene.from_arrays`."""
    try:
        import trimesh
    except ImportError as e:  # pragma: no cover - the message is the point
        raise ImportError("Scene.from_trimesh needs trimesh: pip install trimesh") from e
    from . import Scene, SceneError

    if isinstance(mesh, trimesh.Scene):
        parts = [g for g in mesh.dump() if isinstance(g, trimesh.Trimesh) and len(g.faces)]
        if not parts:
            raise SceneError("the trimesh scene has no triangle meshes")
        vertices, faces, objects, offset = [], [], [], 0
        for k, g in enumerate(parts):
            vertices.append(np.asarray(g.vertices, dtype=np.float64))
            faces.append(np.asarray(g.faces, dtype=np.int64) + offset)
            label = g.metadata.get("node") or g.metadata.get("name") or f"geometry {k}"
            objects.extend([str(label)] * len(g.faces))
            offset += len(g.vertices)
        kwargs.setdefault("objects", np.asarray(objects))
        vertices_all, faces_all = np.concatenate(vertices), np.concatenate(faces)
        default_name = mesh.metadata.get("file_name") or "<trimesh>"
    elif isinstance(mesh, trimesh.Trimesh):
        vertices_all, faces_all = mesh.vertices, mesh.faces
        default_name = mesh.metadata.get("file_name") or "<trimesh>"
    else:
        raise SceneError(f"from_trimesh takes a trimesh.Trimesh or trimesh.Scene, not {type(mesh).__name__}")
    return Scene.from_arrays(vertices_all, faces_all, name=name or default_name, **kwargs)
