#!/usr/bin/env python3
"""Writes the crafted test meshes in this folder (units: mm). Re-run to regenerate them.

The valid shape is a square pyramid with its apex (the needle tip) at (0.5, 0.25, 1) and its
2 x 2 base at z = 4: volume 4 mm^3, area 4 + 4*sqrt(10) mm^2. The defect files each carry one
defect named by the file.
"""
import math
import struct
from pathlib import Path

HERE = Path(__file__).resolve().parent
APEX = (0.5, 0.25, 1.0)


def pyramid():
    x, y, z = APEX
    v = [(x - 1, y - 1, z + 3), (x + 1, y - 1, z + 3), (x + 1, y + 1, z + 3), (x - 1, y + 1, z + 3), APEX]
    # Outward: sides seen from outside are counter-clockwise; the base (normal +z) too.
    t = [(4, 1, 0), (4, 2, 1), (4, 3, 2), (4, 0, 3), (0, 1, 2), (0, 2, 3)]
    return v, t


def box(lo, hi):
    (x0, y0, z0), (x1, y1, z1) = lo, hi
    v = [(x0, y0, z0), (x1, y0, z0), (x1, y1, z0), (x0, y1, z0),
         (x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)]
    quads = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7)]
    t = []
    for a, b, c, d in quads:
        t += [(a, b, c), (a, c, d)]
    return v, t


def normal(p, q, r):
    u = [q[i] - p[i] for i in range(3)]
    w = [r[i] - p[i] for i in range(3)]
    n = [u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]]
    length = math.sqrt(sum(c * c for c in n)) or 1.0
    return [c / length for c in n]


def fmt(c):
    return c if isinstance(c, str) else repr(float(c))


def ascii_stl(name, v, t):
    lines = [f"solid {name}"]
    for tri in t:
        p = [v[i] for i in tri]
        n = normal(*p) if all(not isinstance(c, str) for q in p for c in q) else [0, 0, 0]
        lines.append("  facet normal " + " ".join(fmt(c) for c in n))
        lines.append("    outer loop")
        for q in p:
            lines.append("      vertex " + " ".join(fmt(c) for c in q))
        lines.append("    endloop")
        lines.append("  endfacet")
    lines.append(f"endsolid {name}")
    (HERE / f"{name}.stl").write_text("\n".join(lines) + "\n")


def binary_stl_bytes(v, t):
    out = bytearray(b"mneedle test mesh".ljust(80, b"\0"))
    out += struct.pack("<I", len(t))
    for tri in t:
        p = [v[i] for i in tri]
        out += struct.pack("<3f", *normal(*p))
        for q in p:
            out += struct.pack("<3f", *q)
        out += struct.pack("<H", 0)
    return bytes(out)


def write_obj(name, v, faces):
    lines = ["# square pyramid, mm", "o pyramid"]
    lines += [f"v {x!r} {y!r} {z!r}" for x, y, z in v]
    lines += ["f " + " ".join(str(i + 1) for i in f) for f in faces]
    (HERE / f"{name}.obj").write_text("\n".join(lines) + "\n")


def write_off(name, v, faces):
    lines = ["OFF", f"{len(v)} {len(faces)} 0"]
    lines += [f"{x!r} {y!r} {z!r}" for x, y, z in v]
    lines += [f"{len(f)} " + " ".join(str(i) for i in f) for f in faces]
    (HERE / f"{name}.off").write_text("\n".join(lines) + "\n")


def write_ply_ascii(name, v, faces):
    lines = ["ply", "format ascii 1.0", f"element vertex {len(v)}", "property float x",
             "property float y", "property float z", f"element face {len(faces)}",
             "property list uchar int vertex_indices", "end_header"]
    lines += [f"{x!r} {y!r} {z!r}" for x, y, z in v]
    lines += [f"{len(f)} " + " ".join(str(i) for i in f) for f in faces]
    (HERE / f"{name}.ply").write_text("\n".join(lines) + "\n")


def write_ply_binary(name, v, faces):
    header = "\n".join(["ply", "format binary_little_endian 1.0", f"element vertex {len(v)}",
                        "property float x", "property float y", "property float z",
                        f"element face {len(faces)}", "property list uchar int vertex_indices",
                        "end_header"]) + "\n"
    out = bytearray(header.encode())
    for q in v:
        out += struct.pack("<3f", *q)
    for f in faces:
        out += struct.pack("<B", len(f)) + struct.pack(f"<{len(f)}i", *f)
    (HERE / f"{name}.ply").write_bytes(bytes(out))


def main():
    v, t = pyramid()
    pyramid_faces = t[:4] + [(0, 1, 2, 3)]  # a quad base exercises triangulation
    ascii_stl("pyramid_ascii", v, t)
    (HERE / "pyramid_binary.stl").write_bytes(binary_stl_bytes(v, t))
    write_obj("pyramid", v, pyramid_faces)
    write_off("pyramid", v, pyramid_faces)
    write_ply_ascii("pyramid_ascii", v, pyramid_faces)
    write_ply_binary("pyramid_binary", v, pyramid_faces)

    bv, bt = box((0, 0, 0), (1, 1, 1))
    ascii_stl("open_box", bv, bt[:2] + bt[4:])  # top (two triangles) missing: 4 border edges
    flipped = list(bt)
    a, b, c = flipped[5]
    flipped[5] = (a, c, b)
    ascii_stl("one_flipped_face", bv, flipped)
    ascii_stl("all_flipped", v, [(a, c, b) for a, b, c in t])
    cv, ct = box((0.5, 0.5, 0.5), (1.5, 1.5, 1.5))
    ascii_stl("self_intersecting", bv + cv, bt + [(a + 8, b + 8, c + 8) for a, b, c in ct])
    # Two pyramids touching apex to apex: one vertex shared by two separate fans.
    mirrored = [(x, y, 2 * APEX[2] - z) for x, y, z in v[:4]] + [APEX]
    bowtie_v = v + mirrored[:4]
    bowtie_t = t + [(4 if i == 4 else i + 5, 4 if k == 4 else k + 5, 4 if j == 4 else j + 5)
                    for i, j, k in t]
    ascii_stl("non_manifold_vertex", bowtie_v, bowtie_t)
    # Tetrahedron A B C D with edge AB split at M on one side and a zero-area sliver A B M.
    A, B, C, D, M = (0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1), (0.5, 0, 0)
    tv = [A, B, C, D, M]
    # Face A C B split at M into A C M and M C B; the sliver A M B closes the gap it leaves.
    tt = [(0, 2, 4), (4, 2, 1), (0, 4, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)]
    ascii_stl("degenerate_face", tv, tt)
    nan_v = list(v)
    nan_v[2] = (nan_v[2][0], "nan", nan_v[2][2])
    ascii_stl("nan_vertex_ascii", nan_v, t)
    raw = bytearray(binary_stl_bytes(v, t))
    struct.pack_into("<f", raw, 84 + 50 * 3 + 12 + 4, float("nan"))  # triangle 3, vertex 1, y
    (HERE / "nan_vertex_binary.stl").write_bytes(bytes(raw))
    (HERE / "empty_solid.stl").write_text("solid x\nendsolid x\n")
    (HERE / "truncated_binary.stl").write_bytes(binary_stl_bytes(v, t)[:-20])
    (HERE / "not_a_mesh.txt").write_text("This is a shopping list, not a mesh.\nmilk\neggs\n")
    (HERE / "not_a_mesh.stl").write_text("This is a shopping list, not a mesh.\nmilk\neggs\n")
    (HERE / "zero_bytes.stl").write_bytes(b"")


if __name__ == "__main__":
    main()
