"""Plain data the exporter produces: numpy buffers and small records whose fields
are the keyword arguments of the native module's constructors (``engine/native_scene.py``
turns them into ``_glslppm`` objects). Keeping export free of the native module lets
it be tested, and timed, on its own.
"""

from dataclasses import dataclass, field

import numpy as np


@dataclass
class MaterialData:
    """``_glslppm.Material``: kind is "diffuse", "conductor", "dielectric", "plastic",
    "translucent", "transparent" or "mix"; emission is radiance (colour × strength).
    A Blender material becomes a list of these, its root first, whose mix_a / mix_b
    index that list (``SceneBuilder.material_id`` rebases them into the scene's table)."""
    kind: str = "diffuse"
    color: tuple = (0.8, 0.8, 0.8)
    ior: float = 1.5
    emission: tuple = (0.0, 0.0, 0.0)
    color_texture: int = -1          # index into SceneData.textures; colour x texel(uv)
    visible_to_camera: bool = True   # False: camera rays pass through
    casts_shadow: bool = True        # False: photons pass through (lighting it on the way)
    roughness: float = 0.0           # Blender's roughness (GGX alpha = roughness^2)
    roughness_texture: int = -1      # roughness x the texture's channel
    roughness_channel: str = "luminance"
    multiscatter: bool = True        # Blender's "Multiscatter GGX"; False: "GGX"
    schlick: bool = False            # conductor: Schlick Fresnel from the colour
    f82_tint: tuple = (1.0, 1.0, 1.0)  # Schlick conductor: Blender 4.x's F82 tint
    tint_reflection: bool = False    # dielectric: the colour tints reflection too
    mix_a: int = -1                  # mix: the material picked with probability 1 - factor
    mix_b: int = -1                  # mix: the one picked with probability factor
    mix_factor: float = 0.5
    mix_texture: int = -1            # factor x the texture's channel
    mix_channel: str = "luminance"
    mix_mode: str = "constant"       # "constant", "fresnel" / "layer_fresnel" (IOR mix_ior),
                                     # "facing" (blend)
    mix_ior: float = 1.5
    normal_texture: int = -1         # tangent-space Normal Map image (the whole material's)
    normal_strength: float = 1.0     # the Normal Map node's Strength
    bump_texture: int = -1           # Bump node's Height image (luminance); not with a normal map
    bump_strength: float = 1.0
    bump_distance: float = 1.0       # negative: Invert
    emission_texture: int = -1       # emission x texel (the whole material's)
    # The mesh colour attribute the colour is multiplied by ("" the mesh's default one), or
    # None; the module's Material takes only whether there is one (engine/native_scene.py).
    vertex_color: object = None
    absorption: tuple = (0.0, 0.0, 0.0)  # sigma_a per world unit inside (the whole material's)
    light_group: int = -1            # index into SceneData.light_groups (its object's), -1 none
    light_link_set: int = 0          # its object's link set (export/light_linking.py)
    light_link_row: int = 0          # its object's row of SceneData.light_link_receives

    def textured(self):
        return max(self.color_texture, self.roughness_texture, self.mix_texture,
                   self.normal_texture, self.bump_texture, self.emission_texture) >= 0


@dataclass
class TextureData:
    """``_glslppm.Texture``: pixels (H, W, 4), row 0 the bottom row as in Blender's
    image.pixels; uint8 holds sRGB-encoded values, float32 linear ones."""
    pixels: np.ndarray
    wrap: str = "repeat"             # "repeat", "clip", "extend" or "mirror"
    name: str = "image"
    # Looked up at (a u + b v + c, d u + e v + f) for mesh uv (u, v): ((a, b, c), (d, e, f))
    uv_map: tuple = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0))
    # Or, where given, at (a x + b y + c z + d, e x + f y + g z + h) for the world position
    # (Generated and Object coordinates): ((a, b, c, d), (e, f, g, h)); uv_map unused.
    position_map: tuple = None
    interpolation: str = "linear"    # "linear" or "closest" (export/image.py)


@dataclass
class LightData:
    """``_glslppm.Light`` in Blender's units: power is light.energy (W; W/m² for sun),
    direction is where the light travels (the light's local -Z in world space).
    Area lights: to_world is the object's matrix_world (float32 4x4), the shape lies in
    its local XY plane with full extents size_x, size_y, emitting along local -Z."""
    kind: str
    color: tuple
    power: float
    position: tuple = (0.0, 0.0, 0.0)
    direction: tuple = (0.0, 0.0, -1.0)
    spot_size: float = 0.0
    spot_blend: float = 0.0
    radius: float = 0.0
    angle: float = 0.0
    spot_cosine: bool = False
    facing_disc: bool = False        # point/spot: Cycles' disc facing the lit point (Soft Falloff)
    to_world: object = None          # float32 (4, 4) or None
    shape: str = "square"
    size_x: float = 1.0
    size_y: float = 1.0
    visible_to_camera: bool = True
    light_group: int = -1            # index into SceneData.light_groups, -1 none
    light_link_set: int = 0          # its object's link set (export/light_linking.py)


@dataclass
class CameraData:
    """``_glslppm.Camera``: to_world is the camera's matrix_world without scale (looks
    down local -Z, +Y up); fov_x the full horizontal angle; shift and ortho_scale
    relative to the larger image dimension whatever the sensor fit."""
    to_world: np.ndarray
    fov_x: float
    shift_x: float = 0.0
    shift_y: float = 0.0
    projection: str = "perspective"
    ortho_scale: float = 1.0
    aperture_radius: float = 0.0
    focus_distance: float = 10.0
    pixel_aspect: float = 1.0        # a pixel's height over its width
    region: object = None            # (column, row from the top, full width, full height)


@dataclass
class SceneData:
    """World-space triangles (three corners per triangle, unshared) and the rest of
    the scene, ready for ``_glslppm.Scene``."""
    positions: np.ndarray            # float32 (V, 3)
    indices: np.ndarray              # uint32 (T, 3)
    normals: object                  # float32 (V, 3) or None
    uvs: object                      # float32 (V, 2) or None
    material_ids: np.ndarray         # uint32 (T,)
    materials: list
    lights: list
    camera: CameraData
    environment: tuple
    width: int
    height: int
    textures: list = field(default_factory=list)   # TextureData
    environment_texture: int = -1    # index into textures: environment x map(direction)
    environment_to_world: object = None  # float32 (4, 4) rotation of the map, or None
    warnings: list = field(default_factory=list)
    stats: dict = field(default_factory=dict)
    # Instanced geometry (geometry nodes, particles, collection instances): each mesh once in
    # object space (dicts of positions, indices, normals, uvs, material_ids as above), placed
    # by (N, 4, 4) float32 matrices and (N,) uint32 mesh indices.
    instance_meshes: list = field(default_factory=list)
    instances: object = None
    instance_mesh: object = None
    # The material table's roots in order, as ((material name or None, object visibility),
    # root index): what export_tables replays after a material, light or world edit.
    material_keys: list = field(default_factory=list)
    tangents: object = None          # float32 (V, 4) or None: normal maps' tangent frames
    colors: object = None            # float32 (V, 3) or None: linear vertex colours
    # The view layer's Light Groups (docs/light_groups.md): their names in order, and the
    # world's (an index, -1 none); lights and materials carry their own.
    light_groups: list = field(default_factory=list)
    world_light_group: int = -1
    # Light and shadow linking (export/light_linking.py): per row, the masks of the link
    # sets that reach it and that it shadows; empty: no links.
    light_link_receives: list = field(default_factory=list)
    shadow_link_blocks: list = field(default_factory=list)
    # Motion blur (export/motion.py): the module's Scene.set_motion arguments, or None.
    motion: dict = None

    @property
    def triangle_count(self):
        return len(self.indices)

    @property
    def instance_count(self):
        return 0 if self.instance_mesh is None else len(self.instance_mesh)

    def has_surfaces(self):
        """True when a camera ray can hit something: triangles or an area light."""
        return (self.triangle_count > 0 or self.instance_count > 0 or
                any(light.kind == "area" for light in self.lights))

    def emits_light(self):
        """True when something in the scene can light it."""
        if self.lights or max(self.environment) > 0.0:
            return True
        emissive = np.array([max(m.emission) > 0.0 for m in self.materials], dtype=bool)
        if len(self.material_ids) and emissive[self.material_ids].any():
            return True
        return any(len(m["material_ids"]) and emissive[m["material_ids"]].any()
                   for m in self.instance_meshes)
