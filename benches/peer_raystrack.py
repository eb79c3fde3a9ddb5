"""Form factors against a peer (issue 31): scx's `--form-factors` beside raystrack 2.0's view-factor matrix on the
same scenes, each against the closed-form F of the unit cube's patches, as error against seconds. Run it through
benches/peer-raystrack.sh, which makes the venv (raystrack pinned) and passes the arguments on:

    python peer_raystrack.py --scx PATH [--scenes @cube:4,...] [--budgets-*] [--work DIR]
    python peer_raystrack.py --selftest        # the closed forms' tests only (numpy; no raystrack, no scx)

Error = relative Frobenius norm ||F - F_exact|| / ||F_exact|| over the whole patch matrix. The exact F comes
from the scene's own polygons (the OBJ `scx export` writes: one quad per patch, front side counter-clockwise)
by the contour-integral form of the form factor (Stokes), A_i F_ij = 1/(2 pi) sum over pairs of parallel
edges of the oriented double integral of ln r, evaluated in closed form for axis-aligned edges; it is tested
(--selftest, and again on every scene) against the textbook unit-square values, row sums, reciprocity and a
Gauss-Legendre quadrature of the kernel.

Interleaving: one process holds raystrack's solver (compiled once, by a warm-up whose time is printed on its
own) and, seed by seed, times raystrack's solves and scx's runs (subprocesses) at every budget, so both
tools share whatever else the machine does. Seconds are wall-clock: for raystrack the solve call (scene set
up beforehand, numba already compiled); for scx the whole process (start-up, scene, lines, every default
measure, writing the form-factor CSV). A budget's seconds are the median over the seeds, its error the rms
over the seeds.
"""
import argparse
import json
import math
import os
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

# ---------------------------------------------------------------------------------------------------------
# Exact form factors between axis-aligned polygons (contour integrals)


def _phi(u, d2):
    """A double antiderivative in u of ln sqrt(u^2 + d^2) (d^2 >= 0), the limits of 0 taken where they vanish."""
    r2 = u * u + d2
    d = np.sqrt(d2)
    log_term = np.where(r2 > 0, 0.25 * (u * u - d2) * np.log(np.where(r2 > 0, r2, 1.0)), 0.0)
    atan_term = np.where(d > 0, d * u * np.arctan(u / np.where(d > 0, d, 1.0)), 0.0)
    return log_term + atan_term - 0.75 * u * u


def exact_form_factors(polys):
    """F[i, j] for planar polygons with axis-aligned edges, polys of shape (n, k, 3), each counter-clockwise
    seen from its front side; polygons in one plane (or facing away) get 0. Assumes every other pair sees
    each other unoccluded (true inside a convex closed box)."""
    polys = np.asarray(polys, float)
    n, k, _ = polys.shape
    p0 = polys
    p1 = np.roll(polys, -1, axis=1)
    edge = p1 - p0
    axis = np.argmax(np.abs(edge), axis=2)  # (n, k)
    if not np.allclose(np.abs(edge).sum(axis=2), np.abs(edge).max(axis=2)):
        raise ValueError("a polygon edge is not axis-aligned")
    area, normal, centroid = polygon_geometry(polys)
    total = np.zeros((n, n))
    for a in range(k):
        for b in range(k):
            same = axis[:, a][:, None] == axis[:, b][None, :]
            ax = axis[:, a][:, None] * np.ones((1, n), int)
            x1 = np.take_along_axis(p0[:, a, :], axis[:, a][:, None], 1)  # (n, 1)
            x2 = np.take_along_axis(p1[:, a, :], axis[:, a][:, None], 1)
            xi1 = np.take_along_axis(p0[:, b, :], axis[:, b][:, None], 1).T  # (1, n)
            xi2 = np.take_along_axis(p1[:, b, :], axis[:, b][:, None], 1).T
            diff = p0[:, a, None, :] - p0[None, :, b, :]  # (n, n, 3)
            mask_axis = np.arange(3)[None, None, :] == ax[:, :, None]
            d2 = np.where(mask_axis, 0.0, diff * diff).sum(axis=2)
            term = _phi(x2 - xi1, d2) + _phi(x1 - xi2, d2) - _phi(x2 - xi2, d2) - _phi(x1 - xi1, d2)
            total += np.where(same, term, 0.0)
    af = total / (2.0 * math.pi)
    facing = ((centroid[None, :, :] - centroid[:, None, :]) * normal[:, None, :]).sum(axis=2) > 1e-12
    facing &= ((centroid[:, None, :] - centroid[None, :, :]) * normal[None, :, :]).sum(axis=2) > 1e-12
    af = np.where(facing, af, 0.0)
    return af / area[:, None]


def polygon_geometry(polys):
    """Areas, unit normals (right-hand rule of the vertex order) and centroids of planar polygons."""
    polys = np.asarray(polys, float)
    cross = np.cross(polys, np.roll(polys, -1, axis=1)).sum(axis=1)
    area = 0.5 * np.linalg.norm(cross, axis=1)
    return area, cross / (2.0 * area[:, None]), polys.mean(axis=1)


def quadrature_form_factor(pi, pj, order=24):
    """F between two axis-aligned rectangles (corners counter-clockwise) by tensor Gauss-Legendre quadrature
    of cos cos / (pi r^2): an independent check of the contour formula for pairs that do not touch."""
    g, w = np.polynomial.legendre.leggauss(order)
    g, w = 0.5 * (g + 1.0), 0.5 * w

    def points(p):
        e1, e2 = p[1] - p[0], p[3] - p[0]
        s, t = np.meshgrid(g, g, indexing="ij")
        x = p[0] + s[..., None] * e1 + t[..., None] * e2
        ww = np.outer(w, w) * np.linalg.norm(np.cross(e1, e2))
        return x.reshape(-1, 3), ww.ravel()

    (xa, wa), (xb, wb) = points(pi), points(pj)
    area, normal, _ = polygon_geometry(np.array([pi, pj]))
    r = xb[None, :, :] - xa[:, None, :]
    r2 = (r * r).sum(axis=2)
    ci = (r * normal[0]).sum(axis=2)
    cj = -(r * normal[1]).sum(axis=2)
    kernel = np.clip(ci, 0, None) * np.clip(cj, 0, None) / (math.pi * r2 * r2)
    return float(wa @ kernel @ wb) / area[0]


def cube_faces(m=1):
    """The unit cube's faces split m x m, inward normals, counter-clockwise seen from inside."""
    out = []
    s = np.arange(m + 1) / m
    for fixed in range(3):
        u, v = [a for a in range(3) if a != fixed]
        for level, inward in ((0.0, 1.0), (1.0, -1.0)):
            for i in range(m):
                for j in range(m):
                    quad = []
                    for du, dv in ((0, 0), (1, 0), (1, 1), (0, 1)):
                        p = np.zeros(3)
                        p[fixed], p[u], p[v] = level, s[i + du], s[j + dv]
                        quad.append(p)
                    quad = np.array(quad)
                    _, nrm, _ = polygon_geometry(quad[None])
                    if nrm[0, fixed] * inward < 0:
                        quad = quad[::-1]
                    out.append(quad)
    return np.array(out)


def check_exact(polys, F, label, quad_pairs=6):
    """Invariants of an exact closed-cube matrix; raises on failure, returns a one-line summary."""
    area, _, _ = polygon_geometry(polys)
    rows = np.abs(F.sum(axis=1) - 1.0).max()
    recip = np.abs(area[:, None] * F - (area[:, None] * F).T).max()
    assert rows < 1e-12, f"{label}: rows of F_exact leave 1 by {rows:.2e}"
    assert recip < 1e-13, f"{label}: reciprocity off by {recip:.2e}"
    assert F.min() >= 0.0, f"{label}: a negative form factor"
    # Quadrature only for pairs that share no corner (the kernel is singular where patches touch).
    shares = lambda i, j: np.any(np.all(np.abs(polys[i][:, None, :] - polys[j][None, :, :]) < 1e-12, axis=2))
    cands = [(i, j) for i, j in np.argwhere(F > 0) if not shares(i, j)]
    rng = np.random.default_rng(7)
    picks = [cands[k] for k in rng.choice(len(cands), size=min(quad_pairs, len(cands)), replace=False)]
    assert picks, f"{label}: no pair to check by quadrature"
    worst = max(abs(quadrature_form_factor(polys[i], polys[j]) - F[i, j]) / F[i, j] for i, j in picks)
    assert worst < 1e-6, f"{label}: quadrature differs by {worst:.2e} relative"
    return (f"{label}: rows sum to 1 within {rows:.1e}, reciprocity within {recip:.1e}, "
            f"{len(picks)} pairs by quadrature within {worst:.1e}")


def selftest():
    """The closed forms' tests; prints what was checked."""
    faces = cube_faces(1)
    F = exact_form_factors(faces)
    # Textbook values for unit squares (Howell C-11 and C-14): parallel at distance 1, perpendicular sharing
    # an edge.
    x = 1.0
    par = 2 / (math.pi * x * x) * (math.log(math.sqrt((1 + x * x) ** 2 / (1 + 2 * x * x)))
                                   + 2 * x * math.sqrt(1 + x * x) * math.atan(x / math.sqrt(1 + x * x))
                                   - 2 * x * math.atan(x))
    w2 = h2 = 1.0
    a = (1 + w2) * (1 + h2) / (1 + w2 + h2)
    b = (w2 * (1 + w2 + h2) / ((1 + w2) * (w2 + h2))) ** w2
    perp = 1 / math.pi * (2 * math.atan(1.0) - math.sqrt(2) * math.atan(1 / math.sqrt(2)) + 0.25 * math.log(a * b * b))
    opp = F[0, 1]  # faces 0 and 1: x = 0 and x = 1
    adj = F[0, 2]  # x = 0 and y = 0
    assert abs(opp - par) < 1e-12 and abs(round(opp, 4) - 0.1998) < 1e-12, (opp, par)
    assert abs(adj - perp) < 1e-12 and abs(round(adj, 4) - 0.2000) < 1e-12, (adj, perp)
    assert abs(F[0, 0]) == 0.0
    print(f"selftest: unit squares parallel {opp:.6f} (C-11 {par:.6f}), perpendicular {adj:.6f} (C-14 {perp:.6f})")
    print("selftest: " + check_exact(faces, F, "cube faces"))
    for m in (2, 3, 4):
        polys = cube_faces(m)
        Fm = exact_form_factors(polys)
        print("selftest: " + check_exact(polys, Fm, f"cube split {m}x{m}"))
        # Summing the patches' blocks gives the faces' F back (an identity between the two levels).
        per = m * m
        area, _, _ = polygon_geometry(polys)
        agg = np.zeros((6, 6))
        for i in range(6):
            for j in range(6):
                blk = slice(i * per, (i + 1) * per), slice(j * per, (j + 1) * per)
                agg[i, j] = (area[blk[0], None] * Fm[blk]).sum() / area[blk[0]].sum()
        assert np.abs(agg - F).max() < 1e-12, np.abs(agg - F).max()
    print("selftest: patch blocks sum to the face-to-face values for 2x2, 3x3, 4x4 splits")


# ---------------------------------------------------------------------------------------------------------
# Scenes, tools, errors


def read_obj_polygons(path):
    """The faces of an OBJ as vertex arrays, in the file's order."""
    V, faces = [], []
    for line in open(path):
        s = line.split()
        if s and s[0] == "v":
            V.append([float(t) for t in s[1:4]])
        elif s and s[0] == "f":
            faces.append([int(t.split("/")[0]) - 1 for t in s[1:]])
    V = np.array(V)
    return [V[f] for f in faces]


def check_patch_order(polys, patches_csv):
    """OBJ face k must be scx patch k: same area, centroid and normal (scx's --patches file)."""
    import csv

    rows = list(csv.DictReader(open(patches_csv)))
    area, normal, centroid = polygon_geometry(polys)
    assert len(rows) == len(polys), f"{len(rows)} patches against {len(polys)} OBJ faces"
    for k, r in enumerate(rows):
        c = np.array([float(r[f"centroid_{a}"]) for a in "xyz"])
        nn = np.array([float(r[f"normal_{a}"]) for a in "xyz"])
        ok = int(r["id"]) == k and abs(float(r["area"]) - area[k]) < 1e-9
        ok &= np.abs(c - centroid[k]).max() < 1e-9 and np.abs(nn - normal[k]).max() < 1e-9
        assert ok, f"OBJ face {k} is not scx patch {r['id']} (area, centroid or normal differ)"


def rel_error(F, exact):
    return float(np.linalg.norm(F - exact) / np.linalg.norm(exact))


def scx_matrix(csv_path, n):
    data = np.genfromtxt(csv_path, delimiter=",", names=True)
    F = np.zeros((n, n))
    data = np.atleast_1d(data)
    F[data["i"].astype(int), data["j"].astype(int)] = data["f_ij"]
    return F


def run_scx(scx, scene, series, lines, seed, threads, work):
    """One scx run of `series`: a sampler, then `box` for lines through the bounding box."""
    out = os.path.join(work, "ff.csv")
    sampler, *through = series.split()
    cmd = [scx, "analyze", scene, "--form-factors", out, "--lines", f"{lines:g}", "--threads", str(threads),
           "--sampler", sampler, "--lines-through", through[0] if through else "sphere", "--seed", str(seed),
           "--format", "json", "-q"]
    t = time.perf_counter()
    res = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.perf_counter() - t
    if res.returncode != 0:
        raise SystemExit(f"scx failed ({res.returncode}): {' '.join(cmd)}\n{res.stderr}")
    report = json.loads(res.stdout)
    return wall, report["seconds"], out


class Raystrack:
    """raystrack's solver over one OBJ, one surface per face (as the shared harness does)."""

    def __init__(self, polys):
        from raystrack import Scene, Mesh, Solver

        meshes = {}
        for k, p in enumerate(polys):
            tris = np.array([[0, a, a + 1] for a in range(1, len(p) - 1)], np.int32)
            meshes[f"p{k}"] = Mesh(np.asarray(p, np.float32), tris)
        self.ids = list(meshes)
        self.index = {name: i for i, name in enumerate(self.ids)}
        self.solver = Solver(Scene.from_meshes(meshes), device="cpu", bvh="builtin", auto_tune=False)
        self.solver.__enter__()

    def solve(self, rays, seed):
        from raystrack import Query, SolveOptions, Sampling, Accuracy, Budget

        opts = SolveOptions(sampling=Sampling(density=16, rays_per_cell=128, seed=seed),
                            accuracy=Accuracy(max_replicates=1000, min_replicates=2, tolerance=0.0),
                            batch_size=65536)
        t = time.perf_counter()
        result = self.solver.solve(Query.matrix(), opts, Budget(rays=int(rays)))
        seconds = time.perf_counter() - t
        n = len(self.ids)
        F = np.zeros((n, n))
        for i, sender in enumerate(self.ids):
            for channel, value in result.row(sender).items():
                if channel.kind == "surface" and channel.surface_id in self.index and value is not None:
                    F[i, self.index[channel.surface_id]] += float(value)
        return seconds, F, result.rays_used

    def close(self):
        self.solver.__exit__(None, None, None)


# ---------------------------------------------------------------------------------------------------------
# Time to a target error


def time_to(points, target):
    """Seconds to reach `target` error: log-log interpolation between the budgets that bracket it, else the
    power law fitted to all points, extrapolated (flagged). points: [(seconds, error)]."""
    pts = sorted(points)
    for (t0, e0), (t1, e1) in zip(pts, pts[1:]):
        if (e0 - target) * (e1 - target) <= 0 and e0 != e1:
            s = (math.log(target) - math.log(e0)) / (math.log(e1) - math.log(e0))
            return math.exp(math.log(t0) + s * (math.log(t1) - math.log(t0))), ""
    slope, icept = fit_power(points)
    return math.exp((math.log(target) - icept) / slope), " (extrap.)"


def fit_power(points):
    """Least-squares slope and intercept of log error against log seconds."""
    lt = np.log([p[0] for p in points])
    le = np.log([p[1] for p in points])
    slope, icept = np.polyfit(lt, le, 1)
    return float(slope), float(icept)


def time_to_sqrt(points, target):
    """Seconds to `target` under error = c / sqrt(seconds), c fitted (least squares in log)."""
    c = math.exp(np.mean([math.log(e) + 0.5 * math.log(t) for t, e in points]))
    return (c / target) ** 2


# ---------------------------------------------------------------------------------------------------------


def log_run(tool, seed, budget, seconds, error):
    """One line per run as it ends, with the machine's load (the machine is shared)."""
    print(f"  run: {tool}, seed {seed}, {budget:.0e}: {seconds:.3f} s, error {100 * error:.3f}%, "
          f"load {os.getloadavg()[0]:.2f}", flush=True)


def budgets(text):
    return [float(b) for b in text.split(",") if b]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--selftest", action="store_true")
    ap.add_argument("--scx", default="target/release/scx")
    ap.add_argument("--scenes", default="@cube:4")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--seeds", default="1,2,3", help="one run per seed and budget (timing median, error rms)")
    ap.add_argument("--budgets-raystrack", default="3e5,1e6,3e6,1e7,3e7", type=budgets)
    ap.add_argument("--budgets-independent", default="3e5,1e6,3e6,1e7,3e7", type=budgets)
    ap.add_argument("--budgets-sobol", default="3e5,1e6,3e6,1e7,3e7", type=budgets)
    ap.add_argument("--budgets-independent-box", default="", type=budgets,
                    help="scx --lines-through box (none by default)")
    ap.add_argument("--budgets-sobol-box", default="", type=budgets,
                    help="scx --sampler sobol --lines-through box (none by default)")
    ap.add_argument("--targets", default="0.01,0.005", type=budgets)
    ap.add_argument("--work", default=None)
    args = ap.parse_args()
    selftest()
    if args.selftest:
        return
    work = args.work or tempfile.mkdtemp(prefix="scx-peer-")
    os.makedirs(work, exist_ok=True)
    seeds = [int(s) for s in args.seeds.split(",")]

    import raystrack

    version = getattr(raystrack, "__version__", None)
    if version is None:
        from importlib.metadata import version as v

        version = v("raystrack")
    load = os.getloadavg()
    print(f"# peer: raystrack {version} (numba {__import__('numba').__version__}, NUMBA_NUM_THREADS="
          f"{os.environ.get('NUMBA_NUM_THREADS')}), scx {args.scx}; {args.threads} threads each")
    print(f"# machine: {os.cpu_count()} CPUs, shared with other jobs; load average at start "
          f"{load[0]:.2f} {load[1]:.2f} {load[2]:.2f}")
    for scene in args.scenes.split(","):
        obj = os.path.join(work, scene.strip("@").replace(":", "") + ".obj")
        subprocess.run([args.scx, "export", scene, "-o", obj, "-q"], check=True)
        polys = read_obj_polygons(obj)
        n = len(polys)
        patches = os.path.join(work, "patches.csv")
        subprocess.run([args.scx, "analyze", scene, "--lines", "1e4", "--threads", str(args.threads),
                        "--patches", patches, "-q", "--format", "json"], check=True, capture_output=True)
        check_patch_order(polys, patches)
        exact = exact_form_factors(np.array(polys))
        print(f"\n## {scene}: {n} patches (OBJ face k = scx patch k: areas, centroids, normals agree); "
              + check_exact(np.array(polys), exact, "F_exact"))

        rs = Raystrack(polys)
        t = time.perf_counter()
        rs.solve(n * 1000, seeds[0])
        first = time.perf_counter() - t
        t = time.perf_counter()
        rs.solve(n * 1000, seeds[0])
        second = time.perf_counter() - t
        print(f"raystrack warm-up: first solve ({n * 1000} rays, including numba's compilation or its cache "
              f"load) {first:.2f} s; the same solve again {second:.3f} s; compile/load ~ {first - second:.2f} s")

        runs = {}  # (tool, sampler, budget) -> list of (wall, error, extra)
        for seed in seeds:
            for b in args.budgets_raystrack:
                sec, F, used = rs.solve(b, seed + 10)
                runs.setdefault(("raystrack", "shifted Halton", b), []).append((sec, rel_error(F, exact), used))
                log_run("raystrack", seed + 10, b, sec, runs[("raystrack", "shifted Halton", b)][-1][1])
            for sampler, bs in (("independent", args.budgets_independent), ("sobol", args.budgets_sobol),
                                ("independent box", args.budgets_independent_box),
                                ("sobol box", args.budgets_sobol_box)):
                for b in bs:
                    wall, inner, csv_path = run_scx(args.scx, scene, sampler, b, seed, args.threads, work)
                    F = scx_matrix(csv_path, n)
                    runs.setdefault(("scx", sampler, b), []).append((wall, rel_error(F, exact), inner))
                    log_run(f"scx {sampler}", seed, b, wall, runs[("scx", sampler, b)][-1][1])
        rs.close()

        print(f"\n| tool | sampler | budget | seconds (wall, median of {len(seeds)}) | error (rms of {len(seeds)} "
              "seeds) | time to 1% (this tool) | note |")
        print("|---|---|---|---:|---:|---:|---|")
        curves = {}
        for (tool, sampler, b), rr in runs.items():
            sec = statistics.median(r[0] for r in rr)
            err = math.sqrt(statistics.fmean(r[1] ** 2 for r in rr))
            curves.setdefault((tool, sampler), []).append((b, sec, err, rr))
        for key, pts in curves.items():
            t1, flag = time_to([(s, e) for _, s, e, _ in pts], 0.01)
            for k, (b, sec, err, rr) in enumerate(pts):
                unit = "rays" if key[0] == "raystrack" else "lines"
                last = f"{t1:.3g} s{flag}" if k == 0 else ""
                if key[0] == "raystrack":
                    note = "rays used " + "/".join(f"{r[2]:.3g}" for r in rr)
                else:
                    note = f"report's seconds {statistics.median(r[2] for r in rr):.3f}"
                print(f"| {key[0]} | {key[1]} | {b:.0e} {unit} | {sec:.3f} | {100 * err:.3f}% | {last} | {note} |")
        print(f"\n| tool | sampler | slope of log error on log seconds | "
              + " | ".join(f"time to {100 * t:g}% (interp.) | c/sqrt(t) fit" for t in args.targets)
              + " | raystrack / this (1%) |")
        print("|---|---|---:|" + "---:|---:|" * len(args.targets) + "---:|")
        ref = time_to([(s, e) for _, s, e, _ in curves[("raystrack", "shifted Halton")]], 0.01)[0]
        for key, pts in curves.items():
            pe = [(s, e) for _, s, e, _ in pts]
            slope, _ = fit_power(pe)
            cells = []
            for target in args.targets:
                t, flag = time_to(pe, target)
                cells.append(f"{t:.3g} s{flag} | {time_to_sqrt(pe, target):.3g} s")
            t1 = time_to(pe, 0.01)[0]
            print(f"| {key[0]} | {key[1]} | {slope:.2f} | " + " | ".join(cells) + f" | {ref / t1:.2f} |")
    load = os.getloadavg()
    print(f"\n# load average at end {load[0]:.2f} {load[1]:.2f} {load[2]:.2f}; work files in {work}")


if __name__ == "__main__":
    main()
