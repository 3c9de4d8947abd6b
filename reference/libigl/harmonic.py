"""libigl reference for conemesh's Tutte step (issue 7): harmonic maps of disk meshes with
the boundary fixed on the unit circle by arc length (igl.map_vertices_to_circle), with
cotangent weights (igl.harmonic, k=1) and uniform weights (graph Laplacian from
igl.adjacency_matrix, solved with igl.min_quad_with_fixed).

Regenerate (from this directory):  pip install libigl && python3 harmonic.py
Outputs per mesh NAME: harmonic_NAME.off (the disk), harmonic_NAME_bnd.txt (boundary loop
used, libigl order), harmonic_NAME_cotan.txt and harmonic_NAME_uniform.txt (uv per vertex,
%.17g). The meshes are generated here: a hexagonal grid of equilateral triangles lifted on a
paraboloid, and the same grid projected on a sphere (a curved cap); all their cotangent
weights are positive (checked), so conemesh's clamping does not apply.
"""

import igl
import numpy as np
import scipy.sparse as sp


def hex_grid(rings):
    """Triangulated regular hexagon of `rings` rings of equilateral triangles (unit spacing)."""
    idx = {}
    pts = []
    for q in range(-rings, rings + 1):
        for r in range(-rings, rings + 1):
            if abs(q + r) <= rings:
                idx[(q, r)] = len(pts)
                pts.append((q + 0.5 * r, r * np.sqrt(3) / 2))
    tris = []
    for (q, r), i in idx.items():
        a, b = idx.get((q + 1, r)), idx.get((q, r + 1))
        if a is not None and b is not None:
            tris.append((i, a, b))
        c = idx.get((q + 1, r - 1))
        if a is not None and c is not None:
            tris.append((i, c, a))
    return np.array(pts, dtype=float), np.array(tris, dtype=np.int64)


def write_off(path, V, F):
    with open(path, "w") as f:
        f.write("OFF\n%d %d 0\n" % (len(V), len(F)))
        for v in V:
            f.write("%.17g %.17g %.17g\n" % tuple(v))
        for t in F:
            f.write("3 %d %d %d\n" % tuple(t))


def meshes():
    p, F = hex_grid(8)
    p = p / 8.0
    parab = np.column_stack([p, 0.4 * (p[:, 0] ** 2 + p[:, 1] ** 2)])
    yield "paraboloid", parab, F
    p, F = hex_grid(10)
    p = p / 10.0 * 0.6
    r2 = p[:, 0] ** 2 + p[:, 1] ** 2
    cap = np.column_stack([p, np.sqrt(1.0 - r2)])
    cap = cap / np.linalg.norm(cap, axis=1)[:, None]
    yield "spherecap", cap, F


for name, V, F in meshes():
    L = igl.cotmatrix(V, F)
    off = sp.coo_matrix(L)
    off = off.data[off.row != off.col]
    assert off.min() > 0, "%s has a non-positive cotangent weight" % name
    bnd = igl.boundary_loop(F)
    bnd_uv = igl.map_vertices_to_circle(V, bnd.astype(np.int32))
    uv_cot = igl.harmonic(V, F, bnd.astype(np.int64), bnd_uv, 1)
    A = igl.adjacency_matrix(F).astype(float)
    Lu = sp.diags(np.asarray(A.sum(axis=1)).ravel()) - A
    uv_uni = igl.min_quad_with_fixed(
        sp.csc_matrix(Lu), np.zeros((len(V), 2)), bnd.astype(np.int64), bnd_uv,
        sp.csc_matrix((0, len(V))), np.zeros((0, 2)), True)
    write_off("harmonic_%s.off" % name, V, F)
    np.savetxt("harmonic_%s_bnd.txt" % name, bnd, fmt="%d")
    np.savetxt("harmonic_%s_cotan.txt" % name, uv_cot, fmt="%.17g")
    np.savetxt("harmonic_%s_uniform.txt" % name, uv_uni, fmt="%.17g")
    print(name, len(V), "vertices", len(F), "faces", len(bnd), "boundary vertices")
