"""Shared pieces of the binding's tests: scenes built as numpy arrays, and the ``scx`` binary the
command-line comparisons run (``SCX_BIN``, else the repository's target/release or target/debug)."""

from __future__ import annotations

import os
import shutil
from pathlib import Path
from typing import Optional, Tuple

import numpy as np
import pytest

REPO = Path(__file__).resolve().parents[2]

# I_s^c of the unit cube, exactly (to the precision of its integrals): the library's
# calibrate::truth::cube_continuous_mutual_information() (src/calibrate/truth.rs), 1.6093 in the
# paper's Table 4 from 10^6 lines.
CUBE_ISC = 1.610473346468777

# I_s of @cube:4 (4 x 4 patches per face) from the closed-form form factors (src/lib.rs's example).
CUBE4_IS = 1.12257


def scx_binary() -> Optional[str]:
    """The ``scx`` command-line program, or None."""
    env = os.environ.get("SCX_BIN")
    if env:
        return env if Path(env).exists() or shutil.which(env) else None
    for profile in ("release", "debug"):
        candidate = REPO / "target" / profile / "scx"
        if candidate.exists():
            return str(candidate)
    return None


def _orient(tris: np.ndarray, vertices: np.ndarray, inside: np.ndarray) -> np.ndarray:
    """Each triangle ordered counter-clockwise seen from `inside` (its front side faces the point)."""
    a, b, c = (vertices[tris[:, k]] for k in range(3))
    normal = np.cross(b - a, c - a)
    wrong = np.einsum("ij,ij->i", normal, inside - a) < 0
    tris = tris.copy()
    tris[wrong] = tris[wrong][:, [0, 2, 1]]
    return tris


def cube_grid(n: int, split: str = "diagonal") -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The unit cube [0, 1]^3 seen from inside, each face an n x n grid of cells: vertices, triangles
    (each cell two triangles on one diagonal, or four about its centre when `split` is "centre") and
    the cell of each triangle (6 n^2 cells)."""
    vertices, tris, cells = [], [], []
    cell = 0
    for axis in range(3):
        for side in (0.0, 1.0):
            u, v = [k for k in range(3) if k != axis]
            for i in range(n):
                for j in range(n):
                    corners = []
                    for di, dj in ((0, 0), (1, 0), (1, 1), (0, 1)):
                        p = np.zeros(3)
                        p[axis], p[u], p[v] = side, (i + di) / n, (j + dj) / n
                        corners.append(p)
                    base = len(vertices)
                    vertices.extend(corners)
                    if split == "diagonal":
                        tris += [[base, base + 1, base + 2], [base, base + 2, base + 3]]
                        cells += [cell, cell]
                    else:
                        vertices.append(sum(corners) / 4)
                        centre = base + 4
                        tris += [[base + k, base + (k + 1) % 4, centre] for k in range(4)]
                        cells += [cell] * 4
                    cell += 1
    vertices = np.array(vertices)
    tris = _orient(np.array(tris), vertices, np.array([0.5, 0.5, 0.5]))
    return vertices, tris, np.array(cells)


@pytest.fixture(scope="session")
def cube4():
    """@cube:4 as loaded by the library."""
    import scx

    return scx.load("@cube:4")
