"""Light converters, one per Blender light type (``LIGHT_CONVERTERS``), in Blender's
units: point and spot power is light.energy in W, sun strength in W/m², area power W.

Point and spot lights keep their radius (shadow_soft_size: a sphere light), the sun its
angular diameter. Spot lights under Blender 3.x also fall off with the cosine to the
axis (Cycles 3.x's spot_attenuation, dropped in 4.0): spot_cosine.

Area lights are native lights of any shape: the renderer gets the object's matrix and
the sizes and emits radiance L = P / (π A) along local -Z (Cycles 4.x: ``eval_fac =
M_1_PI_F * invarea``). Cycles 3.x used ``eval_fac = 0.25f * invarea``, L = P / (4 A),
so there the power passed is P π / 4. invarea is 1 / area unless the light's Normalize
option (4.x) is off, where L = P / π whatever the size: the power passed is then P A.
"""

import math

import numpy as np

from ..compat import BLENDER_4, node_tree
from .node_inputs import linked_node as _linked_node, socket_color, socket_value
from .scene_data import LightData


# Cycles' area light radiance per W/m² relative to 1/π: 1 from Blender 4.0, π/4 before.
AREA_POWER_FACTOR = 1.0 if BLENDER_4 else math.pi / 4.0

AREA_SHAPES = {'SQUARE': "square", 'RECTANGLE': "rectangle", 'DISK': "disk",
               'ELLIPSE': "ellipse"}


def convert_light(light, matrix, builder, visible_to_camera=True):
    """Adds one light instance (its datablock and object-to-world matrix) to builder;
    visible_to_camera is the object's camera ray visibility (area lights)."""
    converter = LIGHT_CONVERTERS.get(light.type)
    if converter is None:
        builder.warn(f"light '{light.name}': {light.type.lower()} lights are not supported")
        return
    matrix = np.asarray(matrix, dtype=np.float64)
    problem = _non_finite_setting(light, matrix)
    if problem is not None:
        # Cycles leaves such a light dark; an inf or NaN would otherwise fill the image.
        builder.warn(f"light '{light.name}': {problem}; the light is off")
        return
    strength, color = light_node_emission(light, builder.warn)
    if light.energy * strength < 0.0:
        # Cycles subtracts a negative light's light (a -50 W point light under a 100 W one
        # halves it); photons of negative flux are not modelled here.
        energy_name = "strength" if light.type == 'SUN' else "power"
        builder.warn(f"light '{light.name}': negative {energy_name} "
                     f"{light.energy * strength:g} is not supported (Cycles subtracts its "
                     "light); the light is off")
        return
    if light.energy <= 0.0 or strength <= 0.0 or max(color) <= 0.0:
        return
    scaled = _NodeScaledLight(light, strength, color)
    with np.errstate(over='ignore'):
        overflows = not np.isfinite(np.float32(scaled.energy) * np.float32(max(scaled.color)))
    if overflows:
        builder.warn(f"light '{light.name}': power {scaled.energy:g} x colour overflows "
                     "single precision; the light is off")
        return
    converter(scaled, matrix, builder, visible_to_camera)


def _non_finite_setting(light, matrix):
    """'power is inf' (the first setting that is not a finite number), or None."""
    energy_name = "strength" if light.type == 'SUN' else "power"
    settings = [(energy_name, light.energy), ("radius", light.shadow_soft_size)]
    settings += [(f"colour {'RGB'[i]}", c) for i, c in enumerate(light.color)]
    if light.type == 'SPOT':
        settings += [("spot size", light.spot_size), ("spot blend", light.spot_blend)]
    elif light.type == 'SUN':
        settings += [("angle", light.angle)]
    elif light.type == 'AREA':
        settings += [("size", light.size), ("size Y", light.size_y)]
    for name, value in settings:
        if not math.isfinite(value):
            return f"{name} is {value}"
    if not np.isfinite(matrix).all():
        return "its object's transform is not finite"
    return None


def light_node_emission(light, warn):
    """(strength, rgb) of the Emission node feeding the light's node tree output, which
    Cycles multiplies into the light's power and colour: (1, white) without nodes."""
    white = (1.0, 1.0, 1.0)
    tree = node_tree(light)
    if tree is None:
        return 1.0, white

    def light_warn(message):
        warn(f"light '{light.name}': {message}")

    if any(node.type == 'TEX_IES' and not node.mute for node in tree.nodes):
        light_warn("IES textures are not supported; the light emits evenly")
    output = next((node for node in tree.nodes
                   if node.type == 'OUTPUT_LIGHT' and node.is_active_output), None)
    if output is None:
        output = next((node for node in tree.nodes if node.type == 'OUTPUT_LIGHT'), None)
    node = _linked_node(output.inputs["Surface"]) if output is not None else None
    if node is None:
        return 1.0, white
    if node.type != 'EMISSION':
        light_warn(f"the {node.bl_label or node.type} node on the Light Output is not "
                   "supported; the light emits as if it had no nodes")
        return 1.0, white
    # Numbers that are not finite read as 0 (with a warning), which turns the light off.
    strength = socket_value(node.inputs["Strength"], light_warn)
    color = socket_color(node.inputs["Color"], light_warn, clamp=False)
    return strength, tuple(max(0.0, c) for c in color)


class _NodeScaledLight:
    """A light datablock seen through its node tree: energy times the Emission node's
    strength, colour times its colour; everything else as the datablock has it."""

    def __init__(self, light, strength, color):
        self._light = light
        self.energy = float(light.energy) * strength
        self.color = tuple(float(c) * k for c, k in zip(light.color, color))

    def __getattr__(self, name):
        return getattr(self._light, name)


def _color(light):
    return tuple(max(0.0, float(c)) for c in light.color)


def _position(matrix):
    return tuple(float(x) for x in matrix[:3, 3])


def _direction(matrix):
    """Where the light travels: its local -Z axis in world space."""
    axis = -matrix[:3, 2]
    length = np.linalg.norm(axis)
    return tuple(float(x) for x in (axis / length if length > 0.0 else (0.0, 0.0, -1.0)))


def _point(light, matrix, builder, visible):
    builder.add_light(LightData(
        "point", _color(light), float(light.energy), position=_position(matrix),
        direction=_direction(matrix), radius=float(light.shadow_soft_size),
        facing_disc=_facing_disc(light)))


def _facing_disc(light):
    """Whether Cycles lights this point or spot light of a radius from a disc facing the lit
    point (3.x always; 4.x and later while Soft Falloff is on, its default) rather than the
    sphere (Cycles' is_sphere: Soft Falloff off)."""
    return not BLENDER_4 or bool(getattr(light, "use_soft_falloff", True))


def _spot(light, matrix, builder, visible):
    builder.add_light(LightData(
        "spot", _color(light), float(light.energy), position=_position(matrix),
        direction=_direction(matrix), spot_size=float(light.spot_size),
        spot_blend=float(light.spot_blend), radius=float(light.shadow_soft_size),
        spot_cosine=not BLENDER_4, facing_disc=_facing_disc(light)))


def _sun(light, matrix, builder, visible):
    angle = min(float(light.angle), math.radians(179.0))
    builder.add_light(LightData(
        "sun", _color(light), float(light.energy), position=_position(matrix),
        direction=_direction(matrix), angle=angle))


def _area(light, matrix, builder, visible):
    shape = AREA_SHAPES.get(light.shape)
    if shape is None:
        builder.warn(f"light '{light.name}': {light.shape.lower()} area lights are not "
                     "supported")
        return
    size_x = float(light.size)
    size_y = float(light.size_y) if shape in ("rectangle", "ellipse") else size_x
    if not (size_x > 0.0 and size_y > 0.0) or abs(np.linalg.det(matrix[:3, :3])) == 0.0:
        builder.warn(f"light '{light.name}': area light of zero size ignored")
        return
    spread = getattr(light, "spread", math.pi)
    if spread < math.pi - 1e-3:
        builder.warn(f"light '{light.name}': area light spread is not supported; "
                     "emitting into the full hemisphere")
    power = float(light.energy) * AREA_POWER_FACTOR
    if not getattr(light, "normalize", True):
        power *= _world_area(shape, size_x, size_y, matrix)
    builder.add_light(LightData(
        "area", _color(light), power, position=_position(matrix),
        direction=_direction(matrix), to_world=matrix.astype(np.float32), shape=shape,
        size_x=size_x, size_y=size_y, visible_to_camera=visible))


def _world_area(shape, size_x, size_y, matrix):
    """The light's area after the object's transform (its local XY plane scaled)."""
    axes = np.cross(matrix[:3, 0], matrix[:3, 1])
    local = size_x * size_y * (math.pi / 4.0 if shape in ("disk", "ellipse") else 1.0)
    return local * float(np.linalg.norm(axes))


LIGHT_CONVERTERS = {
    'POINT': _point,
    'SPOT': _spot,
    'SUN': _sun,
    'AREA': _area,
}
