#!/usr/bin/env python3
"""Write scenes/planet-map.png: an equirectangular map of an imaginary planet for the
fast-moving planet demo (scenes/planet.toml), made here so the repository holds its source.

Oceans and continents from a sum of low-frequency waves in longitude and latitude (seeded,
so the file is the same on every run), ice at the poles, and a graticule every 30 degrees
(meridians and parallels in a pale line) so that the shear and turn of the sphere read at a
glance. 512 x 256 texels, 8-bit sRGB RGB. Python's standard library only."""

import math

from pngfile import write_png
import random

W, H = 512, 256
rng = random.Random(1989)
waves = [
    (rng.randint(1, 5), rng.randint(1, 4), rng.uniform(0, 2 * math.pi), rng.uniform(0.3, 1.0))
    for _ in range(9)
]


def land(lon, lat):
    return sum(a * math.sin(k * lon + p) * math.cos(m * lat) for k, m, p, a in waves)


rows = []
for y in range(H):
    lat = math.pi / 2 - (y + 0.5) / H * math.pi
    row = bytearray([0])  # filter: none
    for x in range(W):
        lon = (x + 0.5) / W * 2 * math.pi - math.pi
        h = land(lon, lat)
        if abs(lat) > math.radians(72):
            rgb = (235, 240, 245)
        elif h > 0.35:
            t = min(1.0, (h - 0.35) / 1.5)
            rgb = (int(70 + 110 * t), int(140 - 30 * t), int(60 + 20 * t))
        else:
            t = max(0.0, min(1.0, (h + 1.5) / 1.85))
            rgb = (int(10 + 20 * t), int(40 + 60 * t), int(110 + 80 * t))
        on_meridian = min((math.degrees(lon) + 180) % 30, 30 - (math.degrees(lon) + 180) % 30) < 0.8
        on_parallel = min(math.degrees(lat) % 30, 30 - math.degrees(lat) % 30) < 0.8
        if on_meridian or on_parallel:
            rgb = (250, 230, 150)
        row += bytes(rgb)
    rows.append(bytes(row))


write_png("scenes/planet-map.png", W, H, rows)
print("wrote scenes/planet-map.png")
