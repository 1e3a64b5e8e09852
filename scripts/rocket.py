#!/usr/bin/env python3
"""Write scenes/rocket.obj and scenes/rocket-paint.png: a textured model for the demo of a model
passing at 0.9c against a star field (scenes/rocket.toml), made here so the repository holds its
source. Python's standard library only; the same files on every run.

The rocket lies along +x (nose at +x), 4 units long, radius 0.3: a body of revolution (a
cylinder, an ogive nose, a boat tail) with vertex normals for smooth shading and texture
coordinates (u around the body, v along it), and four flat fins. Its paint is the black and
white roll pattern of early test rockets (quadrants alternating along the body), so that a turn
of the body (Terrell rotation) reads at a glance. Materials by `usemtl`: `hull`, `fins`."""

import math

from pngfile import write_png

SEG = 48  # around
profile = []  # (x, r) from tail to nose
for i in range(7):  # boat tail: x from -2 to -1.6
    t = i / 6
    profile.append((-2.0 + 0.4 * t, 0.22 + 0.08 * math.sin(t * math.pi / 2)))
for i in range(1, 13):  # body: to x = 0.8
    profile.append((-1.6 + 2.4 * i / 12, 0.3))
for i in range(1, 17):  # ogive nose: to x = 2
    t = i / 16
    profile.append((0.8 + 1.2 * t, 0.3 * math.sqrt(max(0.0, 1 - t * t))))

# Slopes for normals: dr/dx by central differences.
def slope(k):
    a, b = profile[max(0, k - 1)], profile[min(len(profile) - 1, k + 1)]
    return (b[1] - a[1]) / (b[0] - a[0])

lines = ["# rest-embree demo rocket (scripts/rocket.py)", "mtllib rocket.mtl"]
length = profile[-1][0] - profile[0][0]
for k, (x, r) in enumerate(profile):
    for j in range(SEG + 1):
        a = 2 * math.pi * j / SEG
        lines.append(f"v {x:.6f} {r * math.cos(a):.6f} {r * math.sin(a):.6f}")
for k, (x, r) in enumerate(profile):
    s = slope(k)
    n = 1 / math.sqrt(1 + s * s)
    for j in range(SEG + 1):
        a = 2 * math.pi * j / SEG
        lines.append(f"vn {-s * n:.6f} {n * math.cos(a):.6f} {n * math.sin(a):.6f}")
for k, (x, r) in enumerate(profile):
    for j in range(SEG + 1):
        lines.append(f"vt {j / SEG:.6f} {(x - profile[0][0]) / length:.6f}")
lines.append("usemtl hull")
ring = SEG + 1
for k in range(len(profile) - 1):
    for j in range(SEG):
        a, b = k * ring + j + 1, k * ring + j + 2
        c, d = a + ring, b + ring
        lines.append(f"f {a}/{a}/{a} {b}/{b}/{b} {d}/{d}/{d}")
        lines.append(f"f {a}/{a}/{a} {d}/{d}/{d} {c}/{c}/{c}")
# The tail closed by a disc (a fan to a centre vertex), facing -x.
nv = len(profile) * ring
lines.append(f"v {profile[0][0]:.6f} 0 0")
lines.append("vn -1 0 0")
lines.append("vt 0.5 0")
centre = nv + 1
for j in range(SEG):
    a, b = j + 1, j + 2
    lines.append(f"f {centre}/{centre}/{centre} {b}/{b}/{centre} {a}/{a}/{centre}")
# Four fins: flat quads (two sided), at 45 degrees, from x = -2 to -1.1, reaching r = 0.8.
lines.append("usemtl fins")
base = nv + 1
fin_vertices = []
for f in range(4):
    a = math.pi / 4 + f * math.pi / 2
    c, s = math.cos(a), math.sin(a)
    for x, r in [(-2.0, 0.25), (-1.1, 0.3), (-1.75, 0.8), (-2.1, 0.8)]:
        fin_vertices.append((x, r * c, r * s))
for p in fin_vertices:
    lines.append(f"v {p[0]:.6f} {p[1]:.6f} {p[2]:.6f}")
for f in range(4):
    q = [base + 1 + 4 * f + i for i in range(4)]
    lines.append(f"f {q[0]} {q[1]} {q[2]} {q[3]}")
open("scenes/rocket.obj", "w").write("\n".join(lines) + "\n")
open("scenes/rocket.mtl", "w").write(
    "# Names only: rest-embree maps them to the scene's [[material]]s.\n"
    "newmtl hull\nKd 0.9 0.9 0.9\nnewmtl fins\nKd 0.8 0.1 0.1\n"
)

# The paint: u around (4 quadrants), v along (bands); a red ring near the nose.
W, H = 256, 128
rows = []
for y in range(H):
    v = 1 - (y + 0.5) / H  # v up from the image's bottom, as OBJ has it
    row = bytearray([0])
    for x in range(W):
        u = (x + 0.5) / W
        quadrant = int(u * 4) % 2
        band = int(v * 5) % 2
        if 0.66 < v < 0.70:
            rgb = (200, 30, 30)
        elif quadrant ^ band:
            rgb = (20, 20, 22)
        else:
            rgb = (235, 235, 228)
        row += bytes(rgb)
    rows.append(bytes(row))


write_png("scenes/rocket-paint.png", W, H, rows)
print("wrote scenes/rocket.obj, scenes/rocket.mtl, scenes/rocket-paint.png")
