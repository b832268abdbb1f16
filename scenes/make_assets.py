#!/usr/bin/env python3
"""Generates the assets of the scenes in this folder (no dependencies beyond Python 3).

    python3 scenes/make_assets.py

writes scenes/assets/sky.hdr: a 256x128 lat-long sky in Mitsuba's orientation (+y up, u = 0
toward -z), a horizon-bright blue gradient, a dim ground, and a small bright sun. The file is
a flat (uncompressed) Radiance RGBE image.
"""
import math
import os
import struct

WIDTH, HEIGHT = 256, 128
SUN = (0.55, 0.62, 0.56)
SUN_RADIUS_DEGREES = 2.0


def rgbe(r, g, b):
    v = max(r, g, b)
    if v < 1e-32:
        return bytes((0, 0, 0, 0))
    mantissa, exponent = math.frexp(v)
    scale = mantissa * 256.0 / v
    return bytes((int(r * scale), int(g * scale), int(b * scale), exponent + 128))


def radiance(x, y, z):
    norm = math.sqrt(sum(c * c for c in SUN))
    sun = [c / norm for c in SUN]
    if x * sun[0] + y * sun[1] + z * sun[2] >= math.cos(math.radians(SUN_RADIUS_DEGREES)):
        return (600.0, 550.0, 480.0)
    if y >= 0.0:
        horizon = (1.0 - y) ** 3
        k = 0.6 + 0.8 * horizon
        return (0.35 * k, 0.55 * k, 1.0 * k)
    return (0.18, 0.16, 0.14)


def main():
    folder = os.path.join(os.path.dirname(os.path.abspath(__file__)), "assets")
    os.makedirs(folder, exist_ok=True)
    path = os.path.join(folder, "sky.hdr")
    rows = []
    for row in range(HEIGHT):
        theta = math.pi * (row + 0.5) / HEIGHT
        line = bytearray()
        for column in range(WIDTH):
            phi = 2.0 * math.pi * (column + 0.5) / WIDTH
            x = math.sin(phi) * math.sin(theta)
            y = math.cos(theta)
            z = -math.cos(phi) * math.sin(theta)
            line += rgbe(*radiance(x, y, z))
        rows.append(bytes(line))
    header = f"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y {HEIGHT} +X {WIDTH}\n".encode()
    temporary = path + ".tmp"
    with open(temporary, "wb") as f:
        f.write(header)
        for line in rows:
            f.write(line)
    os.replace(temporary, path)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
