#!/usr/bin/env python3
"""Reference principal curvatures from libigl, for tests/metric_libigl.rs.

For each mesh, runs igl.principal_curvature(V, F, radius=5, useKring=True) on the raw file
(file units, file vertex order) and writes <name>.txt beside this script:

    # libigl <version> principal_curvature radius=5 useKring=True mesh=<file> vertices=<n>
    # bad_vertices: <indices or none>
    # columns: pv1 pv2 pd1x pd1y pd1z pd2x pd2y pd2z   (pv1 = libigl's "maximal", pd1 its direction)
    <one line per vertex>

Usage: python3 principal_curvature.py [MESH_DIR]   (default ../../../shared/meshes)
"""
import importlib.metadata
import os
import sys

import igl
import numpy as np

MESHES = ["fandisk.off", "bunny.off", "fertility.off", "3holes.off"]
RADIUS = 5


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    mesh_dir = sys.argv[1] if len(sys.argv) > 1 else os.path.join(here, "..", "..", "..", "shared", "meshes")
    version = importlib.metadata.version("libigl")
    for name in MESHES:
        v, f = igl.read_triangle_mesh(os.path.join(mesh_dir, name))
        v = np.ascontiguousarray(v, dtype=np.float64)
        f = np.ascontiguousarray(f, dtype=np.int64)
        pd1, pd2, pv1, pv2, bad = igl.principal_curvature(v, f, radius=RADIUS, useKring=True)
        out = os.path.join(here, os.path.splitext(name)[0] + ".txt")
        with open(out, "w") as fh:
            fh.write(f"# libigl {version} principal_curvature radius={RADIUS} useKring=True "
                     f"mesh={name} vertices={v.shape[0]}\n")
            fh.write("# bad_vertices: " + (" ".join(str(i) for i in bad) if len(bad) else "none") + "\n")
            fh.write("# columns: pv1 pv2 pd1x pd1y pd1z pd2x pd2y pd2z\n")
            for i in range(v.shape[0]):
                row = [pv1[i], pv2[i], *pd1[i], *pd2[i]]
                fh.write(" ".join(f"{x:.7g}" for x in row) + "\n")
        print(f"{name}: {v.shape[0]} vertices, {len(bad)} bad, -> {os.path.basename(out)}")


if __name__ == "__main__":
    main()
