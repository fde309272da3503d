"""Closed forms and reference scenes that several test files check the renderer against:
a spot light's irradiance, an area light's by brute-force integration, a disk light's in
closed form, the closed diffuse furnace, and a dielectric's Fresnel reflectance."""
import math

import numpy as np

from conftest import look_at, sphere


def fresnel_dielectric(cos_i, eta):
    """Unpolarised Fresnel reflectance (Born and Wolf 1999, section 1.5.3) and the cosine of
    the refracted ray; eta = n_incident / n_transmitted; 1 under total internal reflection.
    Scalars or numpy arrays."""
    cos_i = np.asarray(cos_i, dtype=np.float64)
    sin2_t = eta * eta * np.maximum(0.0, 1.0 - cos_i * cos_i)
    cos_t = np.sqrt(np.maximum(0.0, 1.0 - sin2_t))
    rs = (eta * cos_i - cos_t) / (eta * cos_i + cos_t)
    rp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t)
    return np.where(sin2_t >= 1.0, 1.0, 0.5 * (rs * rs + rp * rp)), cos_t


def spot_expected(x, y, h, power, size, blend, cosine):
    """Blender's spot: I = P / 4 pi inside the cone, times smoothstep over the blend width
    (1 - cos(size / 2)) * blend below the cone's edge (Cycles' spot_attenuation)."""
    d2 = x * x + y * y + h * h
    cos_t = h / np.sqrt(d2)
    cos_half = math.cos(size / 2)
    smooth = (1 - cos_half) * blend
    s = np.clip((cos_t - cos_half) / smooth, 0.0, 1.0)
    attenuation = np.where(cos_t > cos_half, s * s * (3 - 2 * s), 0.0)
    if cosine:
        attenuation = attenuation * cos_t
    return power / (4 * math.pi) * attenuation * cos_t / d2


def area_irradiance_brute_force(to_world, shape, sx, sy, radiance, points, n=400):
    """E at plane points below a downward-facing light: sum of L cos cos' / d^2 dA over a
    fine grid on the shape (the 64-gon's area for disks and ellipses is within 0.2%)."""
    a, b = sx / 2, (sx if shape in ("square", "disk") else sy) / 2
    u = (np.arange(n) + 0.5) / n * 2 - 1
    uu, vv = np.meshgrid(u * a, u * b)
    keep = np.ones_like(uu, dtype=bool)
    if shape in ("disk", "ellipse"):
        keep = (uu / a) ** 2 + (vv / b) ** 2 <= 1.0
    da = (2 * a / n) * (2 * b / n)
    q = np.stack([uu[keep], vv[keep], np.zeros(keep.sum())], axis=1) + to_world[:3, 3]
    out = []
    for p in points:
        d = q - p
        d2 = (d * d).sum(1)
        cos = d[:, 2] / np.sqrt(d2)  # both normals are vertical
        out.append(radiance * (cos * cos / d2).sum() * da)
    return np.array(out)


def disk_irradiance(radiance, b, h, r):
    """Irradiance at distance r from the axis of a disk light of radius b and radiance L,
    on a plane parallel to it at height h (the standard disk-to-point form factor):
    E = pi L / 2 (1 - (h^2 + r^2 - b^2) / sqrt((h^2 + r^2 + b^2)^2 - 4 r^2 b^2)), which on the
    axis is pi L b^2 / (h^2 + b^2)."""
    s = h * h + r * r
    root = np.sqrt((s + b * b) ** 2 - 4 * r * r * b * b)
    return 0.5 * math.pi * radiance * (1.0 - (s - b * b) / root)


def furnace_scene(g, albedo, emission, rings=24, inward=True, materials=None):
    """A closed sphere of radius 1 seen from its centre; `materials` replaces its one
    diffuse material of that albedo and emission (the first is the triangles')."""
    p, t, n = sphere((0.0, 0.0, 0.0), 1.0, rings, 2 * rings, inward=inward)
    if materials is None:
        materials = [g.Material("diffuse", color=(albedo,) * 3, emission=(emission,) * 3)]
    camera = g.Camera(look_at((0, 0, 0), (0, 0, -1)), fov_x=math.radians(90))
    return g.Scene(p, t, normals=n, materials=materials, camera=camera)
