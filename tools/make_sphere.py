#!/usr/bin/env python3
"""Writes an icosphere OBJ with smooth vertex normals: the unit-radius sphere
that scenes/caustics.scene places (scale sets its radius).

    python3 tools/make_sphere.py SUBDIVISIONS MATERIAL_LIBRARY MATERIAL > out.obj

scenes/models/glass_sphere.obj is `make_sphere.py 3 glass_sphere.mtl glass`
(1,280 triangles)."""
import math
import sys


def icosphere(levels):
    t = (1.0 + 5.0 ** 0.5) / 2.0
    verts = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t),
             (0, -1, -t), (0, 1, -t), (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    verts = [normalize(v) for v in verts]
    faces = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4),
             (11, 10, 2), (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8),
             (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    for _ in range(levels):
        middle = {}

        def mid(a, b):
            key = (min(a, b), max(a, b))
            if key not in middle:
                pa, pb = verts[a], verts[b]
                verts.append(normalize(tuple((x + y) / 2 for x, y in zip(pa, pb))))
                middle[key] = len(verts) - 1
            return middle[key]

        next_faces = []
        for a, b, c in faces:
            ab, bc, ca = mid(a, b), mid(b, c), mid(c, a)
            next_faces += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        faces = next_faces
    return verts, faces


def normalize(v):
    length = math.sqrt(sum(x * x for x in v))
    return tuple(x / length for x in v)


def main():
    levels, library, material = int(sys.argv[1]), sys.argv[2], sys.argv[3]
    verts, faces = icosphere(levels)
    out = [f"# Icosphere, {len(faces)} triangles, unit radius (tools/make_sphere.py)",
           f"mtllib {library}", f"usemtl {material}"]
    out += [f"v {x:.6f} {y:.6f} {z:.6f}" for x, y, z in verts]
    out += [f"vn {x:.6f} {y:.6f} {z:.6f}" for x, y, z in verts]
    out += [f"f {a + 1}//{a + 1} {b + 1}//{b + 1} {c + 1}//{c + 1}" for a, b, c in faces]
    print("\n".join(out))


if __name__ == "__main__":
    main()
