"""Scenes several test files share, built from numpy arrays as the built-in ones are in C++
(native/procedural/): the Cornell box replica, a closed box furnace, a lamp over a floor, a
glass ball focusing a beam onto a floor (with each pixel's floor area and the pixel a
point projects into), an axis-aligned box, an instanced scene (mirrored
and scaled instances of a ball and a cube), Blender's equirectangular texel directions, and
a render helper that returns film, stats and photons. Test files import from here, never
from each other."""
import math
from collections import namedtuple

import numpy as np

from conftest import look_at, merge, quad, sphere


def shape_quad(a, b, c, d):
    """native/procedural/shapes.cpp make_quad: four corners, the face normal at each."""
    a, b, c, d = (np.array(v, np.float32) for v in (a, b, c, d))
    n = np.cross(b - a, c - a)
    n = (n / np.linalg.norm(n)).astype(np.float32)
    return np.array([a, b, c, d], np.float32), np.array([n] * 4, np.float32), \
        np.array([[0, 1, 2], [0, 2, 3]], np.uint32)


def join_shapes(parts):
    """((positions, normals, triangles), material id) parts as one mesh's arrays:
    (positions, normals, triangles, material ids), triangles re-indexed."""
    positions, normals, triangles, ids = [], [], [], []
    base = 0
    for (p, n, t), m in parts:
        positions.append(p)
        normals.append(n)
        triangles.append(t + base)
        ids.append(np.full(len(t), m, np.uint32))
        base += len(p)
    return (np.concatenate(positions), np.concatenate(normals), np.concatenate(triangles),
            np.concatenate(ids))


def shape_sphere(center, radius, rings, segments):
    """native/procedural/shapes.cpp make_sphere, in float32 as the C++ computes it."""
    pi = np.float32(3.14159265358979)
    positions, normals = [], []
    for i in range(rings + 1):
        theta = np.float32(pi * np.float32(i) / np.float32(rings))
        for j in range(segments + 1):
            phi = np.float32(np.float32(2.0) * pi * np.float32(j) / np.float32(segments))
            n = np.array([np.sin(theta) * np.cos(phi), np.cos(theta),
                          np.sin(theta) * np.sin(phi)], np.float32)
            positions.append(np.array(center, np.float32) + np.float32(radius) * n)
            normals.append(n)
    row = segments + 1
    triangles = []
    for i in range(rings):
        for j in range(segments):
            a = i * row + j
            b = a + row
            if i != 0:
                triangles.append([a, a + 1, b])
            if i != rings - 1:
                triangles.append([a + 1, b + 1, b])
    return np.array(positions, np.float32), np.array(normals, np.float32), \
        np.array(triangles, np.uint32)


def cornell_box(g, scale=1.0, light=17.0, rings=16):
    """native/procedural/cornell_box.cpp rebuilt from arrays, so that its positions and camera
    can be scaled and its light changed (test_replica_is_the_builtin_cornell_box)."""
    parts = [
        (shape_quad((-1, 0, -1), (-1, 0, 1), (1, 0, 1), (1, 0, -1)), 0),  # floor
        (shape_quad((-1, 2, -1), (1, 2, -1), (1, 2, 1), (-1, 2, 1)), 0),  # ceiling
        (shape_quad((-1, 0, -1), (1, 0, -1), (1, 2, -1), (-1, 2, -1)), 0),  # back
        (shape_quad((-1, 0, -1), (-1, 2, -1), (-1, 2, 1), (-1, 0, 1)), 1),  # left
        (shape_quad((1, 0, -1), (1, 0, 1), (1, 2, 1), (1, 2, -1)), 2),  # right
        (shape_quad((-0.3, 1.98, -0.3), (0.3, 1.98, -0.3), (0.3, 1.98, 0.3),
                    (-0.3, 1.98, 0.3)), 3),  # light
        (shape_sphere((-0.45, 0.38, -0.35), 0.38, rings, 2 * rings), 4),  # mirror
        (shape_sphere((0.45, 0.38, 0.3), 0.38, rings, 2 * rings), 5),  # glass
    ]
    positions, normals, triangles, ids = join_shapes(parts)
    materials = [
        g.Material("diffuse", color=(0.75, 0.75, 0.75)),
        g.Material("diffuse", color=(0.75, 0.25, 0.25)),
        g.Material("diffuse", color=(0.25, 0.75, 0.25)),
        g.Material("diffuse", color=(0, 0, 0), emission=(light, light, light),
                   emission_two_sided=False),
        g.Material("conductor", color=(0.95, 0.95, 0.95)),
        g.Material("dielectric", color=(1, 1, 1), ior=1.5),
    ]
    camera = np.eye(4, dtype=np.float32)
    camera[:3, 3] = np.array([0, 1, 4], np.float32) * np.float32(scale)
    return g.Scene((positions * np.float32(scale)).astype(np.float32), triangles,
                   normals=normals, material_ids=ids, materials=materials,
                   camera=g.Camera(camera, fov_x=2.0 * math.atan(1.15 / 3.0)))


def inward_box(h=1.0):
    """A closed cube of half size h, every face facing the inside."""
    faces = [
        quad((-h, -h, -h), (-h, -h, h), (h, -h, h), (h, -h, -h)),
        quad((-h, h, -h), (h, h, -h), (h, h, h), (-h, h, h)),
        quad((-h, -h, -h), (h, -h, -h), (h, h, -h), (-h, h, -h)),
        quad((-h, -h, h), (-h, h, h), (h, h, h), (h, -h, h)),
        quad((-h, -h, -h), (-h, h, -h), (-h, h, h), (-h, -h, h)),
        quad((h, -h, -h), (h, -h, h), (h, h, h), (h, h, -h)),
    ]
    return merge(*[(p, t, 0) for p, t in faces])[:2]


def box_furnace(g, albedo=0.5, emission=1.0):
    """Inside a closed box whose walls all emit Le and reflect albedo a, with direct light
    only (max_bounces=0, as Cycles counts bounces: docs/bounces.md) L = Le + a Le exactly:
    the irradiance is pi Le everywhere in a closed enclosure. The camera sees only the middle of one face (farther than any radius from an
    edge), where the photon density is uniform, so the kernel adds no bias and every path
    ends after one bounce: photons_emitted = passes * photons_per_pass exactly."""
    p, t = inward_box()
    material = g.Material("diffuse", color=(albedo,) * 3, emission=(emission,) * 3)
    camera = g.Camera(look_at((0, 0, 0), (0, 0, -1)), fov_x=math.radians(30))
    return g.Scene(p, t, materials=[material], camera=camera)


def lamp_over_floor(g, scale):
    """A point light 0.01 above a 2000 x 2000 floor, the camera 1 above looking down: the
    photons crowd under the lamp, so the radii shrink to the floor within a few passes."""
    half = np.float32(1000.0 * scale)
    p, t = quad((-half, 0, -half), (-half, 0, half), (half, 0, half), (half, 0, -half))
    return g.Scene(p, t, materials=[g.Material("diffuse", color=(0.5, 0.5, 0.5))],
                   lights=[g.Light("point", power=1.0, position=(0, 0.01 * scale, 0))],
                   camera=g.Camera(look_at((0, scale, 0), (0, 0, 0), up=(0, 0, -1)),
                                   fov_x=math.radians(10)))


GlassBall = namedtuple("GlassBall", "scene to_world fov_x centre radius albedo")


def glass_ball_beam(g, albedo=0.8, ior=1.5, rings=64):
    """A glass ball of radius 0.5 resting on a white floor (albedo) beside a blue-grey wall,
    lit by a narrow spot beam from (-2.5, 2.5, 0) through the ball's centre, which the ball
    focuses near the floor into a small caustic; the camera looks down at it from
    (0.6, 2.2, 3.4). Returns the scene with what the caustic-flux tests need to find each
    pixel's floor area (camera, ball, albedo)."""
    centre, radius = (0.0, 0.5, 0.0), 0.5
    floor = quad((-3, 0, -2), (-3, 0, 3), (3, 0, 3), (3, 0, -2))
    wall = quad((-3, 0, -2), (3, 0, -2), (3, 3, -2), (-3, 3, -2))
    ball_p, ball_t, ball_n = sphere(centre, radius, rings, 2 * rings)
    positions, indices, ids = merge((*floor, 0), (*wall, 1), (ball_p, ball_t, 2))
    normals = np.concatenate([np.tile([0.0, 1.0, 0.0], (4, 1)), np.tile([0.0, 0.0, 1.0], (4, 1)),
                              ball_n]).astype(np.float32)
    materials = [g.Material("diffuse", color=(albedo,) * 3),
                 g.Material("diffuse", color=(0.6, 0.6, 0.7)),
                 g.Material("dielectric", color=(1.0, 1.0, 1.0), ior=ior)]
    source = np.array([-2.5, 2.5, 0.0])
    axis = (np.array(centre) - source) / np.linalg.norm(np.array(centre) - source)
    light = g.Light("spot", power=1000.0, position=tuple(source), direction=tuple(axis),
                    spot_size=0.002, spot_blend=0.0, radius=0.6)
    to_world = look_at((0.6, 2.2, 3.4), (0.25, 0.3, 0.0))
    fov_x = 0.8
    scene = g.Scene(positions, indices, normals=normals, material_ids=ids, materials=materials,
                    lights=[light], camera=g.Camera(to_world, fov_x=fov_x))
    return GlassBall(scene, to_world, fov_x, centre, radius, albedo)


def floor_footprints(to_world, fov_x, size, ball_centre, ball_radius):
    """For a square perspective image of the floor y = 0: each pixel's area on the floor (its
    four corner rays' quadrilateral: a plane maps the pixel square projectively, so the
    quadrilateral is exact) and whether its rays see the floor directly (centre ray clear of
    the ball by a margin, the floor in front of the camera)."""
    rotation, eye = to_world[:3, :3].astype(np.float64), to_world[:3, 3].astype(np.float64)
    tan_half = math.tan(0.5 * fov_x)

    def rays(cols, rows):
        film = np.stack([(2.0 * cols / size - 1.0) * tan_half, (1.0 - 2.0 * rows / size) * tan_half,
                         -np.ones_like(cols)], axis=-1)
        d = film @ rotation.T
        return d / np.linalg.norm(d, axis=-1, keepdims=True)

    corner = np.arange(size + 1.0)
    d = rays(*np.meshgrid(corner, corner))
    hit = eye - (eye[1] / d[..., 1])[..., None] * d
    x, z = hit[..., 0], hit[..., 2]
    # Shoelace over each pixel's corners in order around it.
    corners = [(x[:-1, :-1], z[:-1, :-1]), (x[:-1, 1:], z[:-1, 1:]),
               (x[1:, 1:], z[1:, 1:]), (x[1:, :-1], z[1:, :-1])]
    twice = sum(xa * zb - xb * za for (xa, za), (xb, zb) in zip(corners, corners[1:] + corners[:1]))
    area = 0.5 * np.abs(twice)
    centre = np.arange(size) + 0.5
    d = rays(*np.meshgrid(centre, centre))
    oc = eye - np.asarray(ball_centre)
    b = d @ oc
    disc = b * b - (oc @ oc - (1.04 * ball_radius) ** 2)
    clear = (disc < 0.0) | (-b - np.sqrt(np.maximum(disc, 0.0)) < 0.0)
    visible = (d[..., 1] < 0.0) & clear
    return area, visible


def pixel_of(points, to_world, fov_x, size):
    """The pixel (row * size + col) a world point projects into; -1 outside the image."""
    rotation, eye = to_world[:3, :3].astype(np.float64), to_world[:3, 3].astype(np.float64)
    q = (points - eye) @ rotation
    tan_half = math.tan(0.5 * fov_x)
    with np.errstate(divide="ignore", invalid="ignore"):
        col = np.floor((q[:, 0] / -q[:, 2] / tan_half + 1.0) * 0.5 * size)
        row = np.floor((1.0 - q[:, 1] / -q[:, 2] / tan_half) * 0.5 * size)
    ok = (q[:, 2] < 0.0) & (col >= 0) & (col < size) & (row >= 0) & (row < size)
    return np.where(ok, row * size + col, -1).astype(np.int64)


def grow(mask, pixels):
    """The mask grown by `pixels` (4-neighbour steps)."""
    for _ in range(pixels):
        p = np.pad(mask, 1)
        mask = mask | p[:-2, 1:-1] | p[2:, 1:-1] | p[1:-1, :-2] | p[1:-1, 2:]
    return mask


def render(g, scene, passes, **settings):
    r = g.Renderer(scene, g.Settings(**settings))
    r.run(passes)
    film, stats, photons = r.film()[..., :3].astype(np.float64), r.stats(), r.photons()
    r.close()
    return film, stats, photons


def block_means(image, size=4):
    h, w = image.shape[:2]
    return image.reshape(h // size, size, w // size, size, -1).mean(axis=(1, 3, 4))


def direction_of_texel(x, y, width, height):
    """The direction of a texel's centre in Blender's (Cycles') equirectangular mapping, Z up:
    +X at u = 0.5, +Y at u = 0.25 (checked against Cycles by tests/blender/test_cycles.py)."""
    u, v = (x + 0.5) / width, (y + 0.5) / height
    phi, elevation = (0.5 - u) * 2 * math.pi, (v - 0.5) * math.pi   # u = 0.5 - atan2(y, x) / 2pi
    return np.array([math.cos(elevation) * math.cos(phi), math.cos(elevation) * math.sin(phi),
                     math.sin(elevation)])


def axis_box(lo, hi):
    """An axis-aligned box, outward-facing."""
    (x0, y0, z0), (x1, y1, z1) = lo, hi
    faces = [
        quad((x0, y0, z0), (x1, y0, z0), (x1, y0, z1), (x0, y0, z1)),  # -y
        quad((x0, y1, z0), (x0, y1, z1), (x1, y1, z1), (x1, y1, z0)),  # +y
        quad((x0, y0, z0), (x0, y1, z0), (x1, y1, z0), (x1, y0, z0)),  # -z
        quad((x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)),  # +z
        quad((x0, y0, z0), (x0, y0, z1), (x0, y1, z1), (x0, y1, z0)),  # -x
        quad((x1, y0, z0), (x1, y1, z0), (x1, y1, z1), (x1, y0, z1)),  # +x
    ]
    return merge(*[(p, t, 0) for p, t in faces])[:2]


def rotation(axis, angle):
    axis = np.asarray(axis, np.float64) / np.linalg.norm(axis)
    x, y, z = axis
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c + x * x * (1 - c), x * y * (1 - c) - z * s, x * z * (1 - c) + y * s],
                     [y * x * (1 - c) + z * s, c + y * y * (1 - c), y * z * (1 - c) - x * s],
                     [z * x * (1 - c) - y * s, z * y * (1 - c) + x * s, c + z * z * (1 - c)]])


def placement(axis, angle, scale, translation):
    m = np.eye(4)
    m[:3, :3] = rotation(axis, angle) @ np.diag(scale)
    m[:3, 3] = translation
    return m


def unit_cube():
    """A unit cube without normals (flat shaded), 12 triangles."""
    c = [(x, y, z) for x in (-.5, .5) for y in (-.5, .5) for z in (-.5, .5)]
    faces = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    tris = [[a, b, c_] for a, b, c_, d in faces] + [[a, c_, d] for a, b, c_, d in faces]
    return {"positions": np.array(c, np.float32), "indices": np.array(tris, np.uint32)}


def ball():
    p, t, n = sphere((0, 0, 0), 0.5, 12, 24)
    return {"positions": p, "indices": t, "normals": n,
            "material_ids": np.zeros(len(t), np.uint32)}


def instanced_scene(g, offset=(0.0, 0.0, 0.0)):
    """A floor and a wall placed once; a ball and a box placed eight times under rotations,
    non-uniform scales, mirrors (negative determinants) and materials chosen by offset:
    diffuse red, mirror, glass, diffuse green. `offset` moves everything (camera and light
    too)."""
    o = np.asarray(offset, np.float64)
    fp, ft = quad((-3, 0, -3), (-3, 0, 3), (3, 0, 3), (3, 0, -3))
    wp, wt = quad((-3, 0, -2), (3, 0, -2), (3, 4, -2), (-3, 4, -2))
    positions = (np.concatenate([fp, wp]) + o).astype(np.float32)
    indices = np.concatenate([ft, wt + 4]).astype(np.uint32)
    ids = np.array([0, 0, 1, 1], np.uint32)
    materials = [g.Material("diffuse", color=(.8, .8, .8)),
                 g.Material("diffuse", color=(.6, .6, .7)),
                 g.Material("diffuse", color=(.8, .2, .2)),
                 g.Material("conductor", color=(.9, .9, .9)),
                 g.Material("dielectric", ior=1.5),
                 g.Material("diffuse", color=(.2, .8, .2))]
    rng = np.random.default_rng(5)
    matrices, meshes, offsets = [], [], []
    for k in range(8):
        scale = rng.uniform(0.4, 1.0, 3)
        if k % 2:
            scale[k // 2 % 3] *= -1.0  # a mirror
        t = (rng.uniform(-2, 2), rng.uniform(0.4, 1.2), rng.uniform(-1.5, 1.5))
        matrices.append(placement(rng.normal(size=3), rng.uniform(0, 6.28), scale, t + o))
        meshes.append(k % 2)
        offsets.append(2 + k // 2 % 4)  # each material on one mirrored instance
    camera = g.Camera(to_world=look_at(o + (0, 2.5, 6), o + (0, 0.7, 0)), fov_x=0.9)
    light = g.Light("point", power=400.0, position=tuple(o + (1.0, 3.5, 2.0)))
    return dict(positions=positions, indices=indices, material_ids=ids, materials=materials,
                lights=[light], camera=camera,
                instance_meshes=[ball(), unit_cube()],
                instances=np.array(matrices, np.float32),
                instance_mesh=np.array(meshes, np.uint32),
                instance_material_offset=np.array(offsets, np.uint32))
