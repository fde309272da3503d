"""Geometry at the extremes: watertight meshes leak no light, rays along
shared edges and at grazing angles find no holes, triangles 1e-7 of the scene size and
triangles spanning the whole scene render, bad bit patterns are named, degenerate triangles
are dropped and counted.

Most checks use emission seen directly: an emissive black surface (colour 0, so no photon
adds anything) seen by a pixel gives exactly Le on every pass, so a pixel below Le is a
hole, exactly, without noise. The plain NaN/Inf/out-of-range cases are in
test_scene_validation.py; here are the bit patterns and extreme values it does not try.
"""
import math

import numpy as np
import pytest

from conftest import look_at, merge, quad

LE = 1.0


def emitter(g, le=LE):
    return g.Material("diffuse", color=(0.0, 0.0, 0.0), emission=(le, le, le))


def grid(n, lo, hi, z=0.0):
    """An n x n grid of quads in the plane z, vertices shared, counter-clockwise from +z."""
    xs = np.linspace(lo, hi, n + 1, dtype=np.float64)
    x, y = np.meshgrid(xs, xs, indexing="xy")
    p = np.stack([x.ravel(), y.ravel(), np.full(x.size, z)], axis=1).astype(np.float32)
    a = (np.arange(n)[None, :] + (n + 1) * np.arange(n)[:, None]).ravel()
    t = np.concatenate([np.stack([a, a + 1, a + n + 2], 1), np.stack([a, a + n + 2, a + n + 1], 1)])
    return p, t.astype(np.uint32)


def icosphere(subdivisions):
    """A unit icosphere with shared vertices (watertight by construction), outward winding."""
    f = (1.0 + 5.0 ** 0.5) / 2.0
    verts = [(-1, f, 0), (1, f, 0), (-1, -f, 0), (1, -f, 0), (0, -1, f), (0, 1, f),
             (0, -1, -f), (0, 1, -f), (f, 0, -1), (f, 0, 1), (-f, 0, -1), (-f, 0, 1)]
    verts = [np.array(v, float) / np.linalg.norm(v) for v in verts]
    faces = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4),
             (11, 10, 2), (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8),
             (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    for _ in range(subdivisions):
        midpoint = {}

        def mid(i, j):
            key = (min(i, j), max(i, j))
            if key not in midpoint:
                m = verts[i] + verts[j]
                verts.append(m / np.linalg.norm(m))
                midpoint[key] = len(verts) - 1
            return midpoint[key]

        new = []
        for a, b, c in faces:
            ab, bc, ca = mid(a, b), mid(b, c), mid(c, a)
            new += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        faces = new
    return np.array(verts, np.float32), np.array(faces, np.uint32)


def box(lo, hi, n):
    """A closed axis-aligned box, each face an n x n grid, vertices shared across faces
    (one vertex per lattice point on the surface), outward winding."""
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    index = {}
    positions, tris = [], []

    def vertex(ijk):
        if ijk not in index:
            index[ijk] = len(positions)
            positions.append(lo + (hi - lo) * np.array(ijk, float) / n)
        return index[ijk]

    for axis in range(3):
        u, v = (axis + 1) % 3, (axis + 2) % 3
        for side in (0, n):
            for i in range(n):
                for j in range(n):
                    corners = []
                    for di, dj in ((0, 0), (1, 0), (1, 1), (0, 1)):
                        ijk = [0, 0, 0]
                        ijk[axis], ijk[u], ijk[v] = side, i + di, j + dj
                        corners.append(vertex(tuple(ijk)))
                    a, b, c, d = corners
                    # (u, v, axis) is right-handed: counter-clockwise in (u, v) faces +axis.
                    if side == n:
                        tris += [(a, b, c), (a, c, d)]
                    else:
                        tris += [(a, c, b), (a, d, c)]
    return np.array(positions, np.float32), np.array(tris, np.uint32)


def stored_photons(renderer):
    photons = renderer.photons()
    return photons[photons[:, 11] > 0.0]


@pytest.mark.parametrize("normals", ["geometric", "smooth"])
def test_closed_icosphere_keeps_every_photon_inside(glslppm, normals):
    """A point light inside a watertight icosphere (shared vertices, 1280 triangles): every
    photon thread stores a photon on every pass (nothing escapes through an edge or a
    vertex), and every stored photon lies on the sphere's surface, between its inscribed
    and circumscribed radius (relative rounding 1e-5). With smooth vertex normals too:
    shading normals must not let a bounce leave through the surface (they did: 5-10 of
    16384 photons per pass, until photon_trace.comp mirrored such bounces back out)."""
    g = glslppm
    p, t = icosphere(3)
    vertex_normals = p.copy() if normals == "smooth" else None
    a, b, c = (p[t[:, k]].astype(np.float64) for k in range(3))
    n = np.cross(b - a, c - a)
    inscribed = np.min(np.abs(np.einsum("ij,ij->i", n, a)) / np.linalg.norm(n, axis=1))
    count = 16384
    scene = g.Scene(p, t, normals=vertex_normals,
                    materials=[g.Material("diffuse", color=(0.9, 0.9, 0.9))],
                    lights=[g.Light("point", power=10.0, position=(0.21, -0.13, 0.34))],
                    camera=g.Camera(look_at((0, 0, 0.5), (0, 0, 0))))
    # Photons alone, which store every hit (light sampling skips each path's first).
    r = g.Renderer(scene, g.Settings(width=8, height=8, photons_per_pass=count, seed=3,
                                     direct_light="photons"))
    for _ in range(6):
        r.run(1)
        photons = r.photons()
        assert int((photons[:, 11] > 0.0).sum()) == count
        radius = np.linalg.norm(photons[:, :3].astype(np.float64), axis=1)
        assert radius.max() <= 1.0 + 1e-5, radius.max()
        assert radius.min() >= inscribed * (1.0 - 1e-5), (radius.min(), inscribed)


def test_light_outside_a_closed_box_leaves_it_dark(glslppm):
    """A point light and a floor outside a closed box (each face a 4 x 4 grid, vertices
    shared between faces), a camera and a small block inside: the film is exactly zero, no
    photon lands on the inner block, and every photon stored on the box came from outside."""
    g = glslppm
    outer = box((-1, -1, -1), (1, 1, 1), 4)
    inner = box((-0.3, -0.9, -0.6), (0.2, -0.4, -0.1), 1)
    floor = quad((-6, -1.5, -6), (-6, -1.5, 6), (6, -1.5, 6), (6, -1.5, -6))
    positions, indices, ids = merge((*outer, 0), (*inner, 0), (*floor, 0))
    white = g.Material("diffuse", color=(0.8, 0.8, 0.8))
    camera = g.Camera(look_at((0.5, 0.3, 0.7), (-0.2, -0.5, -0.5)), fov_x=math.radians(100))
    scene = g.Scene(positions, indices, material_ids=ids, materials=[white],
                    lights=[g.Light("point", power=100.0, position=(2.0, 3.0, 1.5))],
                    camera=camera)
    # A gather radius below the distance from most visible points to the box's edges: the
    # automatic one (0.51 here, relative to the 12-unit floor) reaches around the edges of
    # the zero-thickness walls to photons stored outside (a kernel effect, not a geometric
    # leak: it lights 168 of the 256 pixels, at most 0.05).
    # Photons alone: first hits on the box's outside are what this checks (light sampling
    # stores none of them).
    settings = g.Settings(width=16, height=16, photons_per_pass=65536, seed=9,
                          initial_radius=0.02, direct_light="photons")
    r = g.Renderer(scene, settings)
    for _ in range(6):
        r.run(1)
        photons = stored_photons(r)
        p = photons[:, :3].astype(np.float64)
        incoming = photons[:, 4:7].astype(np.float64)
        on_inner = np.all((p >= [-0.3 - 1e-5, -0.9 - 1e-5, -0.6 - 1e-5]) &
                          (p <= [0.2 + 1e-5, -0.4 + 1e-5, -0.1 + 1e-5]), axis=1)
        assert not on_inner.any(), p[on_inner][:5]
        on_box = np.abs(np.abs(p).max(axis=1) - 1.0) <= 1e-5
        assert on_box.sum() > 1000
        # Came from outside: a step back along the incoming direction leaves the box.
        back = np.abs(p[on_box] + 1e-3 * incoming[on_box]).max(axis=1)
        assert np.all(back > 1.0), back.min()
    assert r.stats()["photons_emitted"] > 0
    assert np.all(r.film()[..., :3] == 0.0)


def emissive_view(g, positions, indices, camera, size=16, passes=4):
    scene = g.Scene(positions, indices, materials=[emitter(g)], camera=camera)
    r = g.Renderer(scene, g.Settings(width=size, height=size, photons_per_pass=1024, seed=2))
    r.run(passes)
    return r.film()[..., 0]


def fan(center, radius, k):
    """k triangles around a shared centre vertex, counter-clockwise from +z."""
    angles = 2.0 * np.pi * np.arange(k) / k + 0.1
    ring = np.stack([center[0] + radius * np.cos(angles), center[1] + radius * np.sin(angles),
                     np.full(k, center[2])], 1)
    p = np.concatenate([[center], ring]).astype(np.float32)
    t = np.array([[0, 1 + i, 1 + (i + 1) % k] for i in range(k)], np.uint32)
    return p, t


@pytest.mark.parametrize("where", ["vertex", "edge"])
def test_zoomed_to_float_resolution_at_shared_vertex_and_edge_no_holes(glslppm, where):
    """An orthographic camera 32 float ulps wide, centred on the vertex shared by a fan of
    24 triangles or on an edge of a grid: every ray lands within a few ulps of shared
    edges, and every pixel sees the emitter on every pass (L = Le, no hole)."""
    g = glslppm
    if where == "vertex":
        center = np.array([0.3, 0.7, 0.0], np.float32)
        p, t = fan(center, 0.5, 24)
    else:
        p, t = grid(8, -1.0, 1.0)
        center = np.array([0.25, 0.6, 0.0], np.float32)  # on the grid line x = 0.25
    width = 32 * float(np.spacing(np.float32(0.7)))
    camera = g.Camera(look_at(center + [0, 0, 1], center), projection="orthographic",
                      ortho_scale=width)
    film = emissive_view(g, p, t, camera, passes=8)
    assert film.min() == pytest.approx(LE, rel=1e-6) and film.max() == pytest.approx(LE, rel=1e-6)


@pytest.mark.parametrize("degrees", [3.0, 1.0, 0.3])
def test_grazing_view_along_a_seam_has_no_holes(glslppm, degrees):
    """A camera a little above a tessellated emissive floor (64 x 64 quads, 100 units wide),
    looking along the seam x = 0 at a depression of `degrees`: every pixel whose rays all
    hit the floor (computed per pixel corner) shows Le, every pixel whose rays all pass
    above it shows 0."""
    g = glslppm
    half = 50.0
    p, t = grid(64, -half, half)
    p = p[:, [0, 2, 1]].copy()  # the floor y = 0
    t = t[:, ::-1].copy()  # facing +y
    height, size, fov = 0.5, 16, math.radians(20)
    distance = height / math.tan(math.radians(degrees))
    eye = np.array([0.0, height, 40.0])
    target = eye + [0.0, -height, -distance]
    to_world = look_at(eye, target)
    film = emissive_view(g, p, t, g.Camera(to_world, fov_x=fov), size=size)

    # Pixel corner rays (perspective: film half extent tan(fov/2) on the z = -1 plane).
    tan_half = math.tan(fov / 2)
    edges = np.linspace(-1.0, 1.0, size + 1) * tan_half
    hits = np.zeros((size + 1, size + 1), bool)
    misses = np.zeros((size + 1, size + 1), bool)
    for row, fy in enumerate(edges[::-1]):
        for col, fx in enumerate(edges):
            d = to_world[:3, :3].astype(np.float64) @ np.array([fx, fy, -1.0])
            if d[1] < 0:
                hit = eye + d * (-eye[1] / d[1])
                inside = abs(hit[0]) < half and abs(hit[2]) < half
                hits[row, col], misses[row, col] = inside, not inside
            else:
                misses[row, col] = True
    all_hit = hits[:-1, :-1] & hits[1:, :-1] & hits[:-1, 1:] & hits[1:, 1:]
    all_miss = misses[:-1, :-1] & misses[1:, :-1] & misses[:-1, 1:] & misses[1:, 1:]
    assert all_hit.sum() >= size  # the floor fills at least a row of pixels
    assert np.all(film[all_hit] == pytest.approx(LE, rel=1e-6)), film[all_hit].min()
    assert np.all(film[all_miss] == 0.0)


@pytest.mark.parametrize("degrees", [3.0, 0.3, 0.03])
def test_grazing_reflection_off_a_tessellated_mirror_does_not_stick(glslppm, degrees):
    """The same view over a mirror floor (conductor, colour 1) under a uniform sky of
    radiance Le: every pixel sees Le, directly or reflected once. A reflected ray that hit
    the floor again at its own origin (a ray that "sticks") would bounce down and up until
    the depth limit and come back black."""
    g = glslppm
    p, t = grid(64, -50.0, 50.0)
    p = p[:, [0, 2, 1]].copy()
    t = t[:, ::-1].copy()
    height = 0.5
    eye = np.array([0.0, height, 40.0])
    target = eye + [0.0, -height, -height / math.tan(math.radians(degrees))]
    scene = g.Scene(p, t, materials=[g.Material("conductor", color=(1.0, 1.0, 1.0))],
                    environment=(LE, LE, LE),
                    camera=g.Camera(look_at(eye, target), fov_x=math.radians(20)))
    r = g.Renderer(scene, g.Settings(width=16, height=16, photons_per_pass=1024, seed=6))
    r.run(4)
    np.testing.assert_allclose(r.film()[..., :3], LE, rtol=1e-6)
    # Control: with a black mirror the pixels that see it go black, so the view above does
    # look at the floor (at least 4 rows of pixels). (Cutting the bounces cannot: as in
    # Cycles, a mirror shows the sky even with no bounces, docs/bounces.md.)
    scene = g.Scene(p, t, materials=[g.Material("conductor", color=(0.0, 0.0, 0.0))],
                    environment=(LE, LE, LE),
                    camera=g.Camera(look_at(eye, target), fov_x=math.radians(20)))
    r = g.Renderer(scene, g.Settings(width=16, height=16, photons_per_pass=1024, seed=6))
    r.run(1)
    assert (r.film()[..., 0] == 0.0).sum() >= 64


def test_triangles_1e7_of_the_scene_and_spanning_it(glslppm):
    """One emissive triangle (Le 0.25) spanning the whole scene (2 units) behind a 2 x 2
    grid of emissive quads (Le 1) of side 2e-7 at the origin. Zoomed in (orthographic,
    8e-7 wide, 16 pixels of 5e-8), the tiny quads fill exactly pixels 4..11 of both axes
    and the big triangle the rest; zoomed out (2.5 units wide), every pixel inside the big
    triangle shows 0.25 and every pixel outside it 0."""
    g = glslppm
    big = (np.array([[-1, -1, -1], [1, -1, -1], [0, 1, -1]], np.float32),
           np.array([[0, 1, 2]], np.uint32))
    tiny = grid(2, -2e-7, 2e-7)
    positions, indices, ids = merge((*big, 0), (*tiny, 1))
    materials = [emitter(g, 0.25), emitter(g, 1.0)]
    settings = g.Settings(width=16, height=16, photons_per_pass=1024, seed=4)

    def render(ortho_scale):
        camera = g.Camera(look_at((0, 0, 1), (0, 0, 0)), projection="orthographic",
                          ortho_scale=ortho_scale)
        scene = g.Scene(positions, indices, material_ids=ids, materials=materials, camera=camera)
        r = g.Renderer(scene, settings)
        r.run(4)
        return r.film()[..., 0], r.stats()

    film, stats = render(8e-7)
    assert stats["triangles"] == 9 and stats["degenerate_dropped"] == 0
    expected = np.full((16, 16), 0.25)
    expected[4:12, 4:12] = 1.0
    np.testing.assert_allclose(film, expected, rtol=1e-6)

    film, _ = render(2.5)
    # Pixel corners in world units; a pixel is inside the big triangle when all 4 are.
    edges = np.linspace(-1.25, 1.25, 17)
    x, y = np.meshgrid(edges, edges[::-1])

    def inside(px, py):
        # Half-planes of (-1,-1), (1,-1), (0,1): y >= -1, y <= 1 - 2|x|.
        return (py >= -1) & (py <= 1 - 2 * np.abs(px))

    corner_in = inside(x, y)
    all_in = corner_in[:-1, :-1] & corner_in[1:, :-1] & corner_in[:-1, 1:] & corner_in[1:, 1:]
    any_in = corner_in[:-1, :-1] | corner_in[1:, :-1] | corner_in[:-1, 1:] | corner_in[1:, 1:]
    assert all_in.sum() >= 40
    np.testing.assert_allclose(film[all_in], 0.25, rtol=1e-6)
    assert np.all(film[~any_in] == 0.0)


def test_degenerate_triangles_are_dropped_and_counted(glslppm):
    """Collinear, coincident and repeated-index triangles, and a sliver whose edges meet at
    a sine of 1e-12, are dropped and counted; a thin but real triangle (sine 1e-5) and the
    emissive quad are kept, and the quad still renders Le in every pixel."""
    g = glslppm
    qp, qt = quad((-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0))
    extra = np.array([[0, 0, 0.5], [0.5, 0, 0.5], [1, 0, 0.5],      # collinear
                      [0.5, 0.5, 0.5],                                # a lone point
                      [0, 0.2, 0.5], [1, 0.2 + 1e-12, 0.5], [2, 0.2, 0.5],  # sine ~1e-12
                      [0, 0.4, 0.5], [1, 0.4 + 1e-5, 0.5], [2, 0.4, 0.5]], np.float32)
    extra[:, 0] += 1.0  # out of the camera's view, in front of the quad
    p = np.concatenate([qp, extra]).astype(np.float32)
    t = np.concatenate([qt, np.array([
        [4, 5, 6],     # collinear
        [7, 7, 7],     # all three the same vertex
        [4, 4, 5],     # two the same index
        [4, 6, 6],     # two the same index again
        [8, 9, 10],    # sliver below the relative threshold (rounds to collinear)
        [11, 12, 13],  # thin but real: kept
    ], np.uint32)]).astype(np.uint32)
    camera = g.Camera(look_at((0, 0, 2), (0, 0, 0)), projection="orthographic", ortho_scale=1.5)
    scene = g.Scene(p, t, materials=[emitter(g)], camera=camera)
    r = g.Renderer(scene, g.Settings(width=16, height=16, photons_per_pass=1024, seed=1))
    r.run(2)
    stats = r.stats()
    assert (stats["triangles"], stats["degenerate_dropped"]) == (3, 5)
    np.testing.assert_allclose(r.film()[..., 0], LE, rtol=1e-6)


def bits(pattern):
    return np.array([pattern], np.uint32).view(np.float32)[0]


@pytest.mark.parametrize("pattern", [0x7F800001, 0x7FBFFFFF, 0xFFC00000, 0xFFFFFFFF, 0xFF800000])
def test_every_non_finite_bit_pattern_is_named(glslppm, pattern):
    """Signalling NaNs, negative NaNs, NaN with every payload bit set and -Inf, in the first
    column of the last vertex (test_scene_validation.py tries quiet NaN and +-Inf)."""
    p, t = quad((0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0))
    p[3, 0] = bits(pattern)
    with pytest.raises(ValueError, match=r"positions\[3\]: coordinate is NaN or Inf"):
        glslppm.Scene(p, t)


def test_largest_index_and_material_id_are_named(glslppm):
    """Index 2^32 - 1 (a -1 cast to uint32) and material id 2^32 - 1."""
    p, t = quad((0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0))
    t[1, 2] = 0xFFFFFFFF
    message = r"indices\[1\]: vertex index 4294967295 is out of range \(4 vertices\)"
    with pytest.raises(ValueError, match=message):
        glslppm.Scene(p, t)
    p, t = quad((0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0))
    with pytest.raises(ValueError, match=r"material_ids\[1\]: material 4294967295 does not exist"):
        glslppm.Scene(p, t, material_ids=np.array([0, 0xFFFFFFFF], np.uint32))


def test_denormal_and_negative_zero_coordinates_are_accepted(glslppm):
    """Finite values at the bottom of the float range are valid input: -0.0 and denormals
    pass validation. A scene of side 1e-40 is far below what 32-bit floats can render, so
    the renderer refuses it with a message that says how big it is and what to do."""
    g = glslppm
    p, t = quad((0, 0, 0), (1e-40, 0, 0), (1e-40, 1e-40, 0), (0, 1e-40, 0))
    p[0, 2] = -0.0
    assert 0.0 < p[1, 0] < np.finfo(np.float32).tiny  # really a denormal
    scene = g.Scene(p, t, lights=[g.Light("point", power=1.0, position=(0.0, 0.0, 1e-39))])
    assert scene.triangle_count == 2
    with pytest.raises(ValueError, match=r"units across, outside the 1e-14 to 1e11.*scale it"):
        g.Renderer(scene, g.Settings(width=8, height=8, photons_per_pass=256))


def lit_quad_ratio(g, size):
    """A point light at height `size` over a diffuse quad of half-width `size`, seen by an
    orthographic camera: the image mean over the closed form at the foot of the light,
    a I / (pi size^2). Scale-free, so the same ratio at every size."""
    p, t = quad((-size, -size, 0), (size, -size, 0), (size, size, 0), (-size, size, 0))
    camera = g.Camera(look_at((0, 0, 2 * size), (0, 0, 0)), projection="orthographic",
                      ortho_scale=size)
    scene = g.Scene(p, t, materials=[g.Material("diffuse", color=(0.5,) * 3)],
                    lights=[g.Light("point", power=1.0, position=(0.0, 0.0, size))],
                    camera=camera)
    r = g.Renderer(scene, g.Settings(width=8, height=8, photons_per_pass=4096, seed=1))
    r.run(4)
    film = r.film()[..., 0].astype(np.float64)
    return film.mean() / (0.5 / (4.0 * np.pi) / (np.pi * size * size))


@pytest.mark.parametrize("size", [1e-25, 1e-18, 1e15])
def test_scene_beyond_float_range_is_rejected_or_renders(glslppm, size):
    """Far outside the design's 1e-3..1e5 units, a scene either gets an error that says so
    or renders what it renders at size 1 (same photons, same seed: within 1e-3). Measured:
    the same ratio from 1e-15 to 1e10; beyond, it rendered black or NaN until the renderer
    refused scenes outside 1e-14..1e11 units across."""
    reference = lit_quad_ratio(glslppm, 1.0)
    try:
        ratio = lit_quad_ratio(glslppm, size)
    except ValueError as e:
        assert "size" in str(e) or "scale" in str(e), str(e)
        return
    assert abs(ratio / reference - 1.0) < 1e-3, (ratio, reference)
