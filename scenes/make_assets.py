#!/usr/bin/env python3
"""Generates the assets of the scenes in this folder (no dependencies beyond Python 3).

    python3 scenes/make_assets.py

writes scenes/assets/sky.hdr: a 256x128 lat-long sky in Mitsuba's orientation (+y up, u = 0
toward -z), a horizon-bright blue gradient, a dim ground, and a small bright sun. The file is
a flat (uncompressed) Radiance RGBE image. It also writes, into the same folder:
- blob.obj: a bumpy sphere of radius about 1 with 14,800 triangles, the sunlit room's mesh;
- leaves.obj: 4,000 small square leaves (8,000 triangles) scattered with a fixed seed through
  a slab 4 x 0.8 x 4 m, a canopy that occludes partly at every scale;
- ball.obj: a smooth sphere of radius 1 with 7,920 triangles, an emitting mesh;
- tiles.png: a 16 x 8 sRGB image of coloured tiles with a gradient, for bitmap textures;
- bumps.png: a 64 x 64 tangent-space normal map of domes, for normalmap;
- attributes.ply: a grid with a colour per vertex and a weight per face, for mesh_attribute;
- quad.obj: a unit square with texture coordinates (OBJ's v up), for textured meshes;
- shapes.serialized: Mitsuba's serialized format (version 4) with two shapes: a square with
  texture coordinates in single precision, and a pyramid with vertex normals in double
  precision.
"""
import math
import os
import random
import struct
import zlib

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


BLOB_COLUMNS, BLOB_ROWS = 100, 75


def uv_sphere(columns, rows, radius):
    """The OBJ lines of a UV sphere with outward winding: `rows` + 1 rings of `columns`
    vertices at distance radius(theta, phi) from the centre, 2 x columns x (rows - 1)
    triangles."""
    lines = []
    for row in range(rows + 1):
        theta = math.pi * row / rows
        for column in range(columns):
            phi = 2.0 * math.pi * column / columns
            r = radius(theta, phi)
            x = r * math.sin(theta) * math.cos(phi)
            y = r * math.cos(theta)
            z = r * math.sin(theta) * math.sin(phi)
            lines.append(f"v {x:.6f} {y:.6f} {z:.6f}")

    def index(row, column):
        return row * columns + column % columns + 1
    for row in range(rows):
        for column in range(columns):
            a, b = index(row, column), index(row, column + 1)
            c, d = index(row + 1, column + 1), index(row + 1, column)
            if row > 0:
                lines.append(f"f {a} {b} {c}")
            if row < rows - 1:
                lines.append(f"f {a} {c} {d}")
    return lines


def write_blob(path):
    """A UV sphere whose radius is modulated by bumps: 2 x 100 x 74 triangles."""
    bumps = lambda theta, phi: 1.0 + 0.08 * math.sin(7.0 * theta) * math.sin(9.0 * phi)
    write_obj(path, uv_sphere(BLOB_COLUMNS, BLOB_ROWS, bumps))


def write_obj(path, lines):
    temporary = path + ".tmp"
    with open(temporary, "w") as f:
        f.write("\n".join(lines) + "\n")
    os.replace(temporary, path)
    print(f"wrote {path}")


LEAVES, LEAF_SIZE = 4000, 0.09


def write_leaves(path):
    """Square leaves of side LEAF_SIZE, random centres in [-2, 2] x [0, 0.8] x [-2, 2] and
    random orientations (seed 7), each two triangles."""
    rng = random.Random(7)
    lines = []
    for leaf in range(LEAVES):
        centre = (rng.uniform(-2, 2), rng.uniform(0, 0.8), rng.uniform(-2, 2))
        normal = [rng.gauss(0, 1) for _ in range(3)]
        length = math.sqrt(sum(c * c for c in normal)) or 1.0
        normal = [c / length for c in normal]
        helper = (1.0, 0.0, 0.0) if abs(normal[0]) < 0.9 else (0.0, 1.0, 0.0)
        a = [helper[1] * normal[2] - helper[2] * normal[1], helper[2] * normal[0] - helper[0] * normal[2],
             helper[0] * normal[1] - helper[1] * normal[0]]
        length = math.sqrt(sum(c * c for c in a))
        a = [c / length for c in a]
        b = [normal[1] * a[2] - normal[2] * a[1], normal[2] * a[0] - normal[0] * a[2],
             normal[0] * a[1] - normal[1] * a[0]]
        h = LEAF_SIZE / 2
        for sa, sb in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
            x, y, z = (centre[i] + h * (sa * a[i] + sb * b[i]) for i in range(3))
            lines.append(f"v {x:.6f} {y:.6f} {z:.6f}")
        first = 4 * leaf + 1
        lines.append(f"f {first} {first + 1} {first + 2}")
        lines.append(f"f {first} {first + 2} {first + 3}")
    write_obj(path, lines)


BALL_COLUMNS, BALL_ROWS = 60, 67


def write_ball(path):
    """A UV sphere of radius 1 with outward winding: 2 x 60 x 66 triangles."""
    write_obj(path, uv_sphere(BALL_COLUMNS, BALL_ROWS, lambda theta, phi: 1.0))


def write_png(path, width, height, texel):
    """An 8-bit RGB PNG whose texel (column, row) is texel(column, row), row 0 on top."""
    def chunk(kind, data):
        body = kind + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body) & 0xFFFFFFFF)

    raw = b"".join(b"\x00" + bytes(c for x in range(width) for c in texel(x, y)) for y in range(height))
    header = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    with open(path + ".tmp", "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(raw))
                + chunk(b"IEND", b""))
    os.replace(path + ".tmp", path)


def tile(x, y):
    """Coloured tiles of 4 x 4 texels with a gradient across the image."""
    colours = [(220, 60, 40), (40, 160, 90), (50, 80, 200), (230, 200, 60)]
    r, g, b = colours[(x // 4 + 2 * (y // 4)) % 4]
    shade = 0.55 + 0.45 * x / 15
    return (int(r * shade), int(g * shade), int(b * shade))


def bump_normal(x, y):
    """A tangent-space normal map of 4 x 4 domes over 64 x 64 texels, encoded (n + 1) / 2
    (read it raw): the normals of the height field 0.04 sin(2 pi 4 u) sin(2 pi 4 v) per texel."""
    u, v = (x + 0.5) / 64, (y + 0.5) / 64
    k = 2 * math.pi * 4
    slope = 0.04 * k
    dx = slope * math.cos(k * u) * math.sin(k * v)
    dy = slope * math.sin(k * u) * math.cos(k * v)
    n = (-dx, -dy, 1.0)
    length = math.sqrt(sum(c * c for c in n))
    return tuple(int(round((c / length * 0.5 + 0.5) * 255)) for c in n)


def write_attribute_grid(path):
    """An ASCII PLY grid of 8 x 8 squares over [-1, 1]^2 at z = 0 (2 triangles each), with a
    colour per vertex (`red green blue`, a smooth gradient) and a weight per face
    (`weight_0`, a checkerboard of 0.1 and 0.9), for mesh_attribute textures."""
    n = 8
    vertices = []
    for j in range(n + 1):
        for i in range(n + 1):
            x, y = -1 + 2 * i / n, -1 + 2 * j / n
            colour = (0.2 + 0.7 * i / n, 0.3 + 0.5 * j / n, 0.9 - 0.6 * (i + j) / (2 * n))
            vertices.append(f"{x:.6f} {y:.6f} 0 {colour[0]:.6f} {colour[1]:.6f} {colour[2]:.6f}")
    faces = []
    for j in range(n):
        for i in range(n):
            a, b = j * (n + 1) + i, j * (n + 1) + i + 1
            c, d = b + n + 1, a + n + 1
            weight = 0.9 if (i + j) % 2 == 0 else 0.1
            faces.append(f"3 {a} {b} {c} {weight}")
            faces.append(f"3 {a} {c} {d} {weight}")
    header = ["ply", "format ascii 1.0", f"element vertex {len(vertices)}", "property float x",
              "property float y", "property float z", "property float red", "property float green",
              "property float blue", f"element face {len(faces)}",
              "property list uchar int vertex_indices", "property float weight_0", "end_header"]
    with open(path + ".tmp", "w") as f:
        f.write("\n".join(header + vertices + faces) + "\n")
    os.replace(path + ".tmp", path)
    print(f"wrote {path}")


def write_quad(path):
    """The square [-1, 1]^2 at z = 0 with texture coordinates running over [0, 2] x [0, 1]."""
    write_obj(path, ["v -1 -1 0", "v 1 -1 0", "v 1 1 0", "v -1 1 0",
                     "vt 0 0", "vt 2 0", "vt 2 1", "vt 0 1",
                     "f 1/1 2/2 3/3", "f 1/1 3/3 4/4"])


def serialized_shape(name, positions, triangles, normals=None, texcoords=None, double=False):
    """One shape of a serialized file: its header, then its zlib-compressed stream."""
    real = "d" if double else "f"
    flags = (0x2000 if double else 0x1000) | (0x0001 if normals else 0) | (0x0002 if texcoords else 0)
    body = struct.pack("<I", flags) + name.encode() + b"\0" + struct.pack("<QQ", len(positions), len(triangles))
    for block, width in ((positions, 3), (normals, 3), (texcoords, 2)):
        if block:
            body += b"".join(struct.pack("<" + real * width, *item) for item in block)
    body += b"".join(struct.pack("<3I", *t) for t in triangles)
    return struct.pack("<HH", 0x041C, 4) + zlib.compress(body)


def write_serialized(path):
    """A square with texture coordinates and a pyramid with normals, in one file."""
    square = serialized_shape("square", [(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)],
                              [(0, 1, 2), (0, 2, 3)], texcoords=[(0, 0), (3, 0), (3, 3), (0, 3)])
    apex, base = (0, 0, 1), [(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)]
    positions, triangles, normals = [], [], []
    for i in range(4):
        a, b = base[i], base[(i + 1) % 4]
        ux, uy, uz = b[0] - a[0], b[1] - a[1], b[2] - a[2]
        vx, vy, vz = apex[0] - a[0], apex[1] - a[1], apex[2] - a[2]
        n = (uy * vz - uz * vy, uz * vx - ux * vz, ux * vy - uy * vx)
        length = math.sqrt(sum(c * c for c in n))
        n = tuple(c / length for c in n)
        triangles.append((len(positions), len(positions) + 1, len(positions) + 2))
        positions += [a, b, apex]
        normals += [n, n, n]
    pyramid = serialized_shape("pyramid", positions, triangles, normals=normals, double=True)
    data, offsets = b"", []
    for shape in (square, pyramid):
        offsets.append(len(data))
        data += shape
    data += b"".join(struct.pack("<Q", o) for o in offsets) + struct.pack("<I", len(offsets))
    with open(path + ".tmp", "wb") as f:
        f.write(data)
    os.replace(path + ".tmp", path)


def main():
    folder = os.path.join(os.path.dirname(os.path.abspath(__file__)), "assets")
    os.makedirs(folder, exist_ok=True)
    write_serialized(os.path.join(folder, "shapes.serialized"))
    write_png(os.path.join(folder, "tiles.png"), 16, 8, tile)
    write_png(os.path.join(folder, "bumps.png"), 64, 64, bump_normal)
    write_quad(os.path.join(folder, "quad.obj"))
    write_attribute_grid(os.path.join(folder, "attributes.ply"))
    write_blob(os.path.join(folder, "blob.obj"))
    write_leaves(os.path.join(folder, "leaves.obj"))
    write_ball(os.path.join(folder, "ball.obj"))
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
