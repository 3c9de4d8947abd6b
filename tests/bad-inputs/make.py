#!/usr/bin/env python3
"""Regenerate the bad-input corpus: `python3 tests/bad-inputs/make.py` (deterministic).
Each file is small and malformed in one way; README.md lists the expected error kind."""
import os, random, struct

D = os.path.dirname(os.path.abspath(__file__))
rng = random.Random(20261125)

def w(name, data):
    with open(os.path.join(D, name), "wb") as f:
        f.write(data.encode() if isinstance(data, str) else data)

TRI_V = "0 0 0\n1 0 0\n0 1 0\n"
TET_V = "0 0 0\n1 0 0\n0 1 0\n0 0 1\n"
TET_F = "3 0 2 1\n3 0 1 3\n3 1 2 3\n3 0 3 2\n"

# ---- OFF
w("off-empty.off", "")
w("off-truncated-vertices.off", "OFF\n4 4 0\n0 0 0\n1 0 0\n")
w("off-truncated-faces.off", "OFF\n4 4 0\n" + TET_V + "3 0 2 1\n3 0 1 3\n")
w("off-nan.off", "OFF\n3 1 0\n0 0 0\n1 nan 0\n0 1 0\n3 0 1 2\n")
w("off-inf.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 -inf 0\n3 0 1 2\n")
w("off-index-out-of-range.off", "OFF\n3 1 0\n" + TRI_V + "3 0 1 3\n")
w("off-negative-index.off", "OFF\n3 1 0\n" + TRI_V + "3 0 -1 2\n")
w("off-repeated-vertex.off", "OFF\n3 1 0\n" + TRI_V + "3 0 1 1\n")
w("off-huge-count.off", "OFF\n1000000000000 1 0\n" + TRI_V + "3 0 1 2\n")
w("off-wrong-magic.off", "OFX\n3 1 0\n" + TRI_V + "3 0 1 2\n")
w("off-binary-garbage.off", bytes(rng.randrange(256) for _ in range(300)))
w("off-bad-number.off", "OFF\n3 1 0\n0 0 0\n1.0.0 0 0\n0 1 0\n3 0 1 2\n")
w("off-face-two-vertices.off", "OFF\n3 1 0\n" + TRI_V + "2 0 1\n")
w("off-no-faces.off", "OFF\n3 0 0\n" + TRI_V)
w("off-binary-variant.off", "OFF BINARY\n")
w("off-face-count-short.off", "OFF\n3 1 0\n" + TRI_V + "4 0 1 2\n")

# ---- OBJ
w("obj-empty.obj", "")
w("obj-index-zero.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n")
w("obj-index-out-of-range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n")
w("obj-negative-out-of-range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -4\n")
w("obj-nan.obj", "v 0 0 0\nv NaN 0 0\nv 0 1 0\nf 1 2 3\n")
w("obj-no-faces.obj", "# only vertices\nv 0 0 0\nv 1 0 0\nv 0 1 0\n")
w("obj-binary-garbage.obj", bytes(rng.randrange(256) for _ in range(300)))
w("obj-two-coordinates.obj", "v 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
w("obj-repeated-vertex.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 -3\n")
w("obj-bow-tie-polygon.obj", "v 0 0 0\nv 1 1 0\nv 1 0 0\nv 0 1 0\nf 1 2 3 4\n")
w("obj-pinched-polygon.obj", "v 0 0 0\nv 2 0 0\nv 1 1 0\nv 2 2 0\nv 0 2 0\nv 1 1 0\nf 1 2 3 4 5 6\n")

# ---- PLY
HDR = "ply\nformat {}\nelement vertex {}\nproperty {t} x\nproperty {t} y\nproperty {t} z\nelement face {}\nproperty list uchar int vertex_indices\nend_header\n"
def hdr(fmt, nv, nf, t="float"):
    return HDR.format(fmt + " 1.0", nv, nf, t=t)
w("ply-empty.ply", "")
w("ply-wrong-magic.ply", "plx\n" + hdr("ascii", 3, 1)[4:] + TRI_V + "3 0 1 2\n")
w("ply-truncated-ascii.ply", hdr("ascii", 4, 4) + TET_V + "3 0 2 1\n3 0 1")
tet = [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)]
body = b"".join(struct.pack("<3f", *p) for p in tet) + b"".join(
    struct.pack("<B3i", 3, *f) for f in [(0, 2, 1), (0, 1, 3), (1, 2, 3), (0, 3, 2)])
w("ply-truncated-binary.ply", hdr("binary_little_endian", 4, 4).encode() + body[:-7])
w("ply-huge-count.ply", hdr("binary_little_endian", 10**12, 1).encode() + body[:60])
w("ply-unknown-type.ply", hdr("ascii", 3, 1).replace("property float z", "property float z\nproperty int128 w") + "0 0 0 0\n1 0 0 0\n0 1 0 0\n3 0 1 2\n")
w("ply-list-count-float.ply", hdr("ascii", 3, 1).replace("list uchar int", "list float int") + TRI_V + "3 0 1 2\n")
w("ply-binary-garbage.ply", bytes(rng.randrange(256) for _ in range(300)))
w("ply-no-end-header.ply", hdr("ascii", 3, 1).replace("end_header\n", "") + TRI_V + "3 0 1 2\n")
w("ply-index-out-of-range.ply", hdr("binary_big_endian", 3, 1).encode()
  + b"".join(struct.pack(">3f", *p) for p in tet[:3]) + struct.pack(">B3i", 3, 0, 1, 3))
w("ply-negative-index.ply", hdr("ascii", 3, 1) + TRI_V + "3 0 -2 1\n")
w("ply-inf.ply", hdr("binary_little_endian", 3, 1, t="double").encode()
  + struct.pack("<9d", 0, 0, 0, 1, 0, float("inf"), 0, 1, 0) + struct.pack("<B3i", 3, 0, 1, 2))
w("ply-face-without-indices.ply", hdr("ascii", 3, 1).replace("vertex_indices", "corners") + TRI_V + "3 0 1 2\n")
w("ply-bad-format.ply", hdr("ascii", 3, 1).replace("ascii 1.0", "binary_middle_endian 1.0") + TRI_V + "3 0 1 2\n")

# ---- STL
def stl_bin(facets, count=None):
    out = b"garbage header".ljust(80, b" ") + struct.pack("<I", len(facets) if count is None else count)
    for f in facets:
        out += struct.pack("<3f", 0, 0, 1) + b"".join(struct.pack("<3f", *p) for p in f) + b"\0\0"
    return out
TRI = [(0, 0, 0), (1, 0, 0), (0, 1, 0)]
w("stl-empty.stl", "")
w("stl-truncated-binary.stl", stl_bin([TRI, TRI], count=2)[:-30])
w("stl-claims-billions.stl", stl_bin([TRI], count=4000000000))
w("stl-truncated-ascii.stl", "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n")
w("stl-binary-garbage.stl", bytes(rng.randrange(256) for _ in range(300)))
w("stl-nan-binary.stl", stl_bin([[(0, 0, 0), (1, float("nan"), 0), (0, 1, 0)]]))
w("stl-degenerate-facet.stl", stl_bin([[(0, 0, 0), (1, 0, 0), (1, 0, 0)]]))
w("stl-ascii-bad-keyword.stl", "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvortex 0 1 0\nendloop\nendfacet\nendsolid t\n")
w("stl-no-facets.stl", stl_bin([]))

# ---- Medit
MH = "MeshVersionFormatted 2\nDimension 3\n"
w("mesh-empty.mesh", "")
w("mesh-wrong-magic.mesh", "MeshVersion 2\nDimension 3\nVertices\n3\n0 0 0 0\n1 0 0 0\n0 1 0 0\nTriangles\n1\n1 2 3 0\nEnd\n")
w("mesh-huge-count.mesh", MH + "Vertices\n1000000000000\n0 0 0 0\n")
w("mesh-index-zero.mesh", MH + "Vertices\n3\n0 0 0 0\n1 0 0 0\n0 1 0 0\nTriangles\n1\n0 1 2 0\nEnd\n")
w("mesh-truncated.mesh", MH + "Vertices\n3\n0 0 0 0\n1 0 0 0\n0 1")
w("mesh-unknown-section.mesh", MH + "Vertices\n3\n0 0 0 0\n1 0 0 0\n0 1 0 0\nBananas\n2\n1 2\nTriangles\n1\n1 2 3 0\nEnd\n")
w("mesh-dimension-4.mesh", "MeshVersionFormatted 2\nDimension 4\n")

# ---- other
w("unknown-extension.xyz", "0 0 0\n1 0 0\n0 1 0\n")

# ---- topological: files read fine, `conemesh check` must report them invalid
# three triangles on the edge (0,1)
w("topo-nonmanifold-edge.off", "OFF\n5 3 0\n0 0 0\n1 0 0\n0.5 1 0\n0.5 -1 0\n0.5 0 1\n3 0 1 2\n3 1 0 3\n3 0 1 4\n")
# two closed pyramids (tetrahedra) touching at their apex v0
w("topo-nonmanifold-vertex.off", "OFF\n7 8 0\n0 0 0\n1 0 1\n-1 1 1\n-1 -1 1\n1 0 -1\n-1 1 -1\n-1 -1 -1\n"
  "3 1 2 3\n3 0 2 1\n3 0 3 2\n3 0 1 3\n3 4 6 5\n3 0 4 5\n3 0 5 6\n3 0 6 4\n")
# tetrahedron with one face reversed
w("topo-inconsistent-orientation.off", "OFF\n4 4 0\n" + TET_V + "3 0 2 1\n3 0 1 3\n3 1 2 3\n3 0 2 3\n")
w("topo-nonmanifold-edge.obj", "v 0 0 0\nv 1 0 0\nv 0.5 1 0\nv 0.5 -1 0\nv 0.5 0 1\nf 1 2 3\nf 2 1 4\nf 1 2 5\n")
