#!/usr/bin/env python3
"""Meshes for the importer's side-by-side scene tests/data/import/meshes.xml, generated here:
a torus as binary little-endian PLY with vertex normals and texture coordinates
(tests/data/import/torus.ply), the same torus's outer half as big-endian PLY without normals
(tests/data/import/half.ply), and a faceted pyramid as OBJ (tests/data/import/pyramid.obj).

Usage: python3 bench/import_assets.py   (plain Python, no packages)
"""

import math
import os
import struct

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
OUT = os.path.join(ROOT, "tests/data/import")


def torus(n_major=48, n_minor=24, r_major=0.6, r_minor=0.22):
    verts, faces = [], []
    for i in range(n_major):
        phi = 2 * math.pi * i / n_major
        for j in range(n_minor):
            theta = 2 * math.pi * j / n_minor
            cx, cz = math.cos(phi), math.sin(phi)
            nx, ny, nz = math.cos(theta) * cx, math.sin(theta), math.cos(theta) * cz
            x = r_major * cx + r_minor * nx
            y = r_minor * ny
            z = r_major * cz + r_minor * nz
            verts.append((x, y, z, nx, ny, nz, i / n_major, j / n_minor))
    for i in range(n_major):
        for j in range(n_minor):
            a = i * n_minor + j
            b = ((i + 1) % n_major) * n_minor + j
            c = ((i + 1) % n_major) * n_minor + (j + 1) % n_minor
            d = i * n_minor + (j + 1) % n_minor
            faces += [(a, d, c), (a, c, b)]
    return verts, faces


def write_ply(path, verts, faces, big=False, normals=True):
    e = ">" if big else "<"
    props = "property float x\nproperty float y\nproperty float z\n"
    if normals:
        props += "property float nx\nproperty float ny\nproperty float nz\n"
    props += "property float u\nproperty float v\n"
    head = (f"ply\nformat binary_{'big' if big else 'little'}_endian 1.0\n"
            f"element vertex {len(verts)}\n{props}"
            f"element face {len(faces)}\nproperty list uchar int vertex_indices\nend_header\n")
    with open(path, "wb") as f:
        f.write(head.encode())
        for v in verts:
            vals = v if normals else v[:3] + v[6:]
            f.write(struct.pack(e + "f" * len(vals), *vals))
        for face in faces:
            f.write(struct.pack(e + "B" + "i" * len(face), len(face), *face))


def main():
    verts, faces = torus()
    write_ply(os.path.join(OUT, "torus.ply"), verts, faces)
    # The outer half (cos(theta) > 0): a strip, as big-endian without normals.
    n_minor = 24
    outer = [f for f in faces if all(math.cos(2 * math.pi * (k % n_minor) / n_minor) > -0.01 for k in f)]
    # Mitsuba reads triangles only: the OBJ keeps a quad (its base), split by both readers.
    write_ply(os.path.join(OUT, "half.ply"), verts, outer, big=True, normals=False)
    with open(os.path.join(OUT, "pyramid.obj"), "w") as f:
        f.write("# A square pyramid, faceted.\n")
        for v in [(-1, 0, -1), (1, 0, -1), (1, 0, 1), (-1, 0, 1), (0, 1.5, 0)]:
            f.write("v %g %g %g\n" % v)
        for face in [(1, 5, 2), (2, 5, 3), (3, 5, 4), (4, 5, 1), (1, 2, 3, 4)]:
            f.write("f " + " ".join(str(i) for i in face) + "\n")


if __name__ == "__main__":
    main()


def write_serialized(path, meshes):
    """A Mitsuba serialized file (version 4, single precision) of `meshes`, each (name,
    vertices [(x, y, z)], triangles [(i, j, k)], uvs or None), with its dictionary."""
    import zlib
    out, offsets = b"", []
    for name, verts, tris, uvs in meshes:
        offsets.append(len(out))
        raw = struct.pack("<I", 0x1000 | (0x0002 if uvs else 0)) + name.encode() + b"\0"
        raw += struct.pack("<QQ", len(verts), len(tris))
        raw += b"".join(struct.pack("<3f", *v) for v in verts)
        if uvs:
            raw += b"".join(struct.pack("<2f", *t) for t in uvs)
        raw += b"".join(struct.pack("<3I", *t) for t in tris)
        out += struct.pack("<HH", 0x041C, 4) + zlib.compress(raw)
    out += b"".join(struct.pack("<Q", o) for o in offsets) + struct.pack("<I", len(offsets))
    with open(path, "wb") as f:
        f.write(out)


def serialized_assets():
    """tests/data/import/shapes.serialized: a tetrahedron (mesh 0) and the torus without its
    normals (mesh 1, with texture coordinates)."""
    tet = [(0, 0, 0), (1, 0, 0), (0.5, 0, 0.9), (0.5, 0.8, 0.3)]
    tet_faces = [(0, 2, 1), (0, 1, 3), (1, 2, 3), (2, 0, 3)]
    verts, faces = torus()
    write_serialized(os.path.join(OUT, "shapes.serialized"), [
        ("tetrahedron", tet, tet_faces, None),
        ("torus", [v[:3] for v in verts], faces, [v[6:] for v in verts]),
    ])


serialized_assets()
