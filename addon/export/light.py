"""Light converters, one per Blender light type (``LIGHT_CONVERTERS``), in Blender's
units: point and spot power is light.energy in W, sun strength in W/m².

Area lights become emissive geometry: a one-sided quad or disk facing the light's
-Z. Its radiance follows the running Blender's Cycles, whose convention changed in
4.0: L = P / (π A) from 4.0 on (``eval_fac = M_1_PI_F * invarea``; the emitted power
is P) and L = P / (4 A) before (``eval_fac = 0.25f * invarea``; measured here: the
same Cornell box is 4/π brighter in Cycles 4.3 than in 3.4). invarea is 1 / area
unless the light's Normalize option (4.x) is off.
"""

import math

import bpy
import numpy as np

from .scene_data import LightData, MaterialData

# Radiance per watt and unit area of an area light: 1/π (Blender 4.0+) or 1/4 (3.x).
AREA_RADIANCE_PER_WATT = 1.0 / math.pi if bpy.app.version >= (4, 0, 0) else 0.25

# Triangles in the fan of a disk or ellipse area light.
DISK_SEGMENTS = 64


def convert_light(light, matrix, builder):
    """Adds one light instance (its datablock and object-to-world matrix) to builder."""
    converter = LIGHT_CONVERTERS.get(light.type)
    if converter is None:
        builder.warn(f"light '{light.name}': {light.type.lower()} lights are not supported")
        return
    if light.energy <= 0.0:
        return
    converter(light, np.asarray(matrix, dtype=np.float64), builder)


def _color(light):
    return tuple(max(0.0, float(c)) for c in light.color)


def _position(matrix):
    return tuple(float(x) for x in matrix[:3, 3])


def _direction(matrix):
    """Where the light travels: its local -Z axis in world space."""
    axis = -matrix[:3, 2]
    length = np.linalg.norm(axis)
    return tuple(float(x) for x in (axis / length if length > 0.0 else (0.0, 0.0, -1.0)))


def _point(light, matrix, builder):
    builder.add_light(LightData(
        "point", _color(light), float(light.energy), position=_position(matrix),
        direction=_direction(matrix), radius=float(light.shadow_soft_size)))


def _spot(light, matrix, builder):
    builder.add_light(LightData(
        "spot", _color(light), float(light.energy), position=_position(matrix),
        direction=_direction(matrix), spot_size=float(light.spot_size),
        spot_blend=float(light.spot_blend), radius=float(light.shadow_soft_size)))


def _sun(light, matrix, builder):
    builder.add_light(LightData(
        "sun", _color(light), float(light.energy), position=_position(matrix),
        direction=_direction(matrix), angle=float(light.angle)))


def _area(light, matrix, builder):
    corners = area_light_corners(light)
    world = corners @ matrix[:3, :3].T + matrix[:3, 3]
    if np.linalg.det(matrix[:3, :3]) < 0.0:
        world = world[:, (0, 2, 1)]  # a mirrored light still emits along its -Z
    edges = np.cross(world[:, 1] - world[:, 0], world[:, 2] - world[:, 0])
    area = 0.5 * float(np.linalg.norm(edges, axis=1).sum())
    if area <= 0.0:
        builder.warn(f"light '{light.name}': area light of zero size ignored")
        return
    spread = getattr(light, "spread", math.pi)
    if spread < math.pi - 1e-3:
        builder.warn(f"light '{light.name}': area light spread is not supported; "
                     "emitting into the full hemisphere")
    normalize = getattr(light, "normalize", True)
    scale = float(light.energy) * AREA_RADIANCE_PER_WATT / (area if normalize else 1.0)
    radiance = tuple(c * scale for c in _color(light))
    material = builder.material_id(
        ("area light", light.name_full, radiance),
        lambda: MaterialData("diffuse", (0.0, 0.0, 0.0), 1.5, radiance))
    builder.add_triangles(world.reshape(-1, 3).astype(np.float32), material,
                          source=f"light '{light.name}'")


def area_light_corners(light):
    """Local-space triangles (T, 3, 3) of an area light in its z = 0 plane, wound
    counter-clockwise seen from -Z so the geometric normal is the light's -Z."""
    size_x = float(light.size)
    size_y = float(light.size_y) if light.shape in ('RECTANGLE', 'ELLIPSE') else size_x
    hx, hy = 0.5 * size_x, 0.5 * size_y
    if light.shape in ('DISK', 'ELLIPSE'):
        angles = np.linspace(0.0, 2.0 * math.pi, DISK_SEGMENTS + 1)
        rim = np.stack([hx * np.cos(angles), hy * np.sin(angles), np.zeros_like(angles)], 1)
        center = np.zeros((DISK_SEGMENTS, 3))
        # Counter-clockwise seen from +Z is clockwise seen from -Z: reverse the rim order.
        return np.stack([center, rim[1:], rim[:-1]], axis=1)
    a, b, c, d = ((-hx, -hy, 0.0), (hx, -hy, 0.0), (hx, hy, 0.0), (-hx, hy, 0.0))
    return np.array([[a, c, b], [a, d, c]], dtype=np.float64)


LIGHT_CONVERTERS = {
    'POINT': _point,
    'SPOT': _spot,
    'SUN': _sun,
    'AREA': _area,
}
