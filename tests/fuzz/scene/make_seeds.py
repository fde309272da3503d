"""Writes the seed inputs of fuzz/scene_fuzz.cpp into this folder (seed-*; rerun after
changing the input layout there). FuzzedDataProvider reads integers from the END of the
input, first byte read = most significant, so each seed is built in reading order and
written reversed."""
import os
import struct

HERE = os.path.dirname(os.path.abspath(__file__))
NORMALS, UVS, MATERIAL_IDS, LENGTH_MISMATCH, PARALLEL = 1, 2, 4, 8, 16
SCALES = [1.0, 1e-3, 1e5, 1e-7, 0.5, 1e-30, 1e30, 3e36]


class Seed:
    def __init__(self):
        self.data = []

    def byte(self, b):
        self.data.append(b & 0xFF)

    def coordinate(self, value):
        """An int8 grid value, or raw float bits (NaN, Inf, anything off the grid)."""
        if isinstance(value, int) and -127 <= value <= 127 and value != -128:
            self.byte(value)
        else:
            self.byte(0x80)
            for b in struct.pack(">f", value):
                self.byte(b)

    def header(self, vertices, triangles, flags, leaf=4, bins=16, materials=1, scale=0):
        self.byte(vertices)             # 0..48
        self.byte(triangles)            # 0..64
        self.byte(flags)
        self.byte(leaf)                 # 0..8
        self.byte(bins - 1)             # 1..40
        self.byte(materials - 1)        # 1..4
        self.byte(scale)                # index into SCALES

    def mesh(self, positions, triangles, flags=0, normals=None, uvs=None, ids=None, **kw):
        self.header(len(positions), len(triangles), flags, **kw)
        for p in positions:
            for c in p:
                self.coordinate(c)
        for t in triangles:
            for i in t:
                self.byte(i)
        for n in normals or []:
            for c in n:
                self.coordinate(c)
        for uv in uvs or []:
            for c in uv:
                self.coordinate(c)
        for i in ids or []:
            self.byte(i)

    def ray(self, kind, origin, pick=0, direction=None, tmin=None, tmax=None):
        """kind & 3: 0 random direction, 1 at a vertex, 2 at an edge midpoint, 3 at a
        centroid; & 4, & 8 zero a direction component; & 64 tmin, & 128 tmax follow."""
        self.byte(kind)
        for c in origin:
            self.coordinate(c)
        self.byte(pick)
        if kind & 3 == 0:
            for c in direction:
                self.coordinate(c)
        if kind & 64:
            self.coordinate(tmin)
        if kind & 128:
            self.coordinate(tmax)

    def write(self, name):
        with open(os.path.join(HERE, name), "wb") as f:
            f.write(bytes(reversed(self.data)))


def cube(half=10):
    p = [(x, y, z) for z in (-half, half) for y in (-half, half) for x in (-half, half)]
    faces = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    t = []
    for a, b, c, d in faces:
        t += [(a, b, c), (a, c, d)]
    return p, t


def plane(n=4, step=10):
    p = [(x * step, y * step, 0) for y in range(n + 1) for x in range(n + 1)]
    t = []
    for y in range(n):
        for x in range(n):
            a = y * (n + 1) + x
            t += [(a, a + 1, a + n + 2), (a, a + n + 2, a + n + 1)]
    return p, t


def cube_rays(s):
    for k in range(12):
        s.ray(1 + k % 3, (50 - k * 9, 40 - k * 7, -60 + k * 11), pick=k)
    s.ray(0 | 4 | 16, (0, 0, -50), direction=(0, 0, 1))      # axis-parallel through the centre
    s.ray(0 | 4 | 8, (10, 10, -50), direction=(0, 0, 1))     # along a cube edge
    s.ray(0 | 64 | 128, (0, 0, 0), direction=(1, 2, 3), tmin=5, tmax=20)


def main():
    p, t = cube()
    s = Seed()
    s.mesh(p, t, NORMALS | UVS | MATERIAL_IDS, normals=[(0, 0, 64)] * 8,
           uvs=[(i, i) for i in range(8)], ids=[i % 2 for i in range(12)], materials=2)
    cube_rays(s)
    s.write("seed-cube")

    for name, scale in (("seed-cube-1e-7", 3), ("seed-cube-1e5", 2), ("seed-cube-1e30", 6)):
        s = Seed()
        s.mesh(p, t, PARALLEL, leaf=1, bins=2, scale=scale)
        cube_rays(s)
        s.write(name)

    p, t = plane()
    s = Seed()
    s.mesh(p, t, 0, leaf=2)
    for k in range(5):  # grazing rays along the seams and diagonals of the plane
        s.ray(0, (-5, k * 10, 0), direction=(1, 0, 0))
        s.ray(2, (k * 10 - 3, -20, 30), pick=k * 6)
        s.ray(0, (-5, -5, 0), direction=(1, 1, 0))
    s.write("seed-plane-seams")

    for name, bad in (("seed-nan", float("nan")), ("seed-inf", float("inf"))):
        q = list(p)
        q[7] = (10, bad, 0)
        s = Seed()
        s.mesh(q, t)
        s.write(name)

    s = Seed()
    s.mesh(p, t[:5] + [(0, 1, 0xF9)] + t[6:])
    s.write("seed-index-out-of-range")

    s = Seed()  # degenerate: collinear, coincident, repeated index, next to good ones
    s.mesh([(0, 0, 0), (10, 0, 0), (20, 0, 0), (0, 10, 0), (0, 0, 0)],
           [(0, 1, 2), (0, 4, 3), (0, 0, 3), (0, 1, 3), (1, 1, 1)])
    s.ray(3, (5, 5, 30), pick=0)
    s.write("seed-degenerate")

    s = Seed()
    s.mesh(p[:3], t[:1], MATERIAL_IDS, ids=[0xF3], materials=2)
    s.write("seed-bad-material")

    s = Seed()
    s.mesh(p, t, NORMALS | LENGTH_MISMATCH, normals=[(0, 0, 1)] * (len(p) - 1))
    s.write("seed-normals-short")


if __name__ == "__main__":
    main()
