#!/usr/bin/env python3
"""Writes the STL assets of tests/extremes/test_extreme_stl.cpp (units: mm).

extreme_sliver_cone.stl: a 32-facet cone (base radius 0.115 mm, length 1 mm, tip at the
origin, body toward +z) whose every side and cap triangle is split at 1e-4 of its base edge:
64 slivers with a corner angle near 0.0006 deg, still closed, manifold and outward.
extreme_near_degenerate.stl: the same cone whose cap has a vertex 1e-5 of the radius inside
each base edge's midpoint, giving 32 near-degenerate triangles (aspect ratio ~ 2e4) in the cap.
"""
import math


def write_ascii(path, triangles, name):
    with open(path, "w") as f:
        f.write(f"solid {name}\n")
        for a, b, c in triangles:
            u = [b[i] - a[i] for i in range(3)]
            v = [c[i] - a[i] for i in range(3)]
            n = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]]
            length = math.sqrt(sum(x * x for x in n)) or 1.0
            f.write("  facet normal %.9e %.9e %.9e\n    outer loop\n" % tuple(x / length for x in n))
            for p in (a, b, c):
                f.write("      vertex %.9e %.9e %.9e\n" % tuple(p))
            f.write("    endloop\n  endfacet\n")
        f.write(f"endsolid {name}\n")


def oriented(tri, outward):
    a, b, c = tri
    u = [b[i] - a[i] for i in range(3)]
    v = [c[i] - a[i] for i in range(3)]
    n = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]]
    return tri if sum(n[i] * outward[i] for i in range(3)) > 0 else (a, c, b)


R, L, N = 0.115, 1.0, 32
apex, centre = (0.0, 0.0, 0.0), (0.0, 0.0, L)
ring = [(R * math.cos(2 * math.pi * i / N), R * math.sin(2 * math.pi * i / N), L) for i in range(N)]


def lerp(p, q, t):
    return tuple(p[i] + t * (q[i] - p[i]) for i in range(3))


def side_normal(p, q):
    m = lerp(p, q, 0.5)
    return (m[0], m[1], -0.2)


sliver = []
for i in range(N):
    b0, b1 = ring[i], ring[(i + 1) % N]
    p = lerp(b0, b1, 1e-4)
    out = side_normal(b0, b1)
    sliver += [oriented((apex, b0, p), out), oriented((apex, p, b1), out)]
    sliver += [oriented((centre, p, b0), (0, 0, 1)), oriented((centre, b1, p), (0, 0, 1))]
write_ascii("extreme_sliver_cone.stl", sliver, "extreme_sliver_cone")

near = []
for i in range(N):
    b0, b1 = ring[i], ring[(i + 1) % N]
    p = lerp(lerp(b0, b1, 0.5), centre, 1e-5)
    near.append(oriented((apex, b0, b1), side_normal(b0, b1)))
    near += [oriented((centre, p, b0), (0, 0, 1)), oriented((centre, b1, p), (0, 0, 1))]
    near.append(oriented((b0, p, b1), (0, 0, 1)))
write_ascii("extreme_near_degenerate.stl", near, "extreme_near_degenerate")
