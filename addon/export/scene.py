"""Exports an evaluated depsgraph into SceneData: walks ``object_instances`` once and
hands each instance to the converter for its kind (mesh, light), then adds the
camera and the world.

Mesh data is read once per evaluated object and placed once per instance, so a
thousand instances of one mesh cost one read and a thousand numpy transforms.
"""

import time

import numpy as np

from .camera import convert_camera
from .image import TextureTable
from .light import convert_light
from .material import DEFAULT_MATERIAL, convert_material, volume_only
from .mesh import face_normals, mesh_geometry, transform_geometry
from .scene_data import SceneData
from .world import convert_world

GEOMETRY_TYPES = {'MESH', 'CURVE', 'SURFACE', 'FONT', 'META'}


class ExportError(Exception):
    """The scene cannot be rendered; the message says why and what to do."""


class SceneBuilder:
    """Collects world-space triangles, the material table, lights and warnings."""

    def __init__(self):
        self._positions = []
        self._normals = []
        self._uvs = []
        self._material_ids = []
        self._material_index = {}
        self.materials = []
        self.lights = []
        self.warnings = []
        self._warned = set()
        self.dropped_triangles = 0
        self.textures = TextureTable(self.warn)

    def warn(self, message):
        """Keeps each distinct warning once (one per material, not per instance)."""
        if message not in self._warned:
            self._warned.add(message)
            self.warnings.append(message)

    def material_id(self, key, make):
        """Index of a material in the table, converting it the first time it is seen."""
        index = self._material_index.get(key)
        if index is None:
            index = len(self.materials)
            self.materials.append(make())
            self._material_index[key] = index
        return index

    def add_light(self, light):
        self.lights.append(light)

    def add_triangles(self, positions, material_ids, normals=None, uvs=None, source="mesh"):
        """World-space corners (3T, 3); material_ids is one index or a (T,) array.
        Triangles with a non-finite corner are dropped here with a warning."""
        count = len(positions) // 3
        if count == 0:
            return
        material_ids = np.broadcast_to(np.asarray(material_ids, dtype=np.uint32), (count,))
        finite = np.isfinite(positions.reshape(count, 9)).all(axis=1)
        if not finite.all():
            dropped = int(count - finite.sum())
            self.dropped_triangles += dropped
            self.warn(f"{source}: dropped {dropped} triangle(s) with NaN or infinite vertices")
            keep = np.repeat(finite, 3)
            positions = positions[keep]
            normals = None if normals is None else normals[keep]
            uvs = None if uvs is None else uvs[keep]
            material_ids = material_ids[finite]
        if normals is not None:
            bad = ~np.isfinite(normals).all(axis=1)
            if bad.any():
                normals = normals.copy()
                normals[bad] = face_normals(positions)[bad]
        self._positions.append(positions)
        self._normals.append(normals)
        self._uvs.append(uvs)
        self._material_ids.append(np.ascontiguousarray(material_ids))

    def geometry(self):
        """(positions, indices, normals or None, uvs or None, material_ids), concatenated.
        Normals (and UVs) are exported for every triangle when any mesh has them."""
        if not self._positions:
            empty = np.zeros((0, 3), dtype=np.float32)
            return (empty, np.zeros((0, 3), dtype=np.uint32), None, None,
                    np.zeros(0, dtype=np.uint32))
        positions = _concatenate(self._positions, np.float32)
        count = len(positions) // 3
        indices = np.arange(3 * count, dtype=np.uint32).reshape(count, 3)
        normals = None
        if any(n is not None for n in self._normals):
            normals = _concatenate(
                [n if n is not None else face_normals(p)
                 for p, n in zip(self._positions, self._normals)], np.float32)
        uvs = None
        if any(u is not None for u in self._uvs):
            uvs = _concatenate(
                [u if u is not None else np.zeros((len(p), 2), np.float32)
                 for p, u in zip(self._positions, self._uvs)], np.float32)
        material_ids = _concatenate(self._material_ids, np.uint32)
        return positions, indices, normals, uvs, material_ids


def _concatenate(arrays, dtype):
    if len(arrays) == 1:
        return np.ascontiguousarray(arrays[0], dtype=dtype)
    return np.ascontiguousarray(np.concatenate(arrays), dtype=dtype)


def export_scene(depsgraph, camera_object, width, height, test_break=None, frame=None):
    """SceneData for an evaluated depsgraph; raises ExportError for a scene that
    cannot render (no camera). test_break() returning True stops early (None).
    frame (a RenderFrame) gives the pixels' shape and the render region."""
    start = time.perf_counter()
    scene = depsgraph.scene
    if camera_object is None:
        raise ExportError("the scene has no camera: add one, or set the scene's "
                          "active camera")
    builder = SceneBuilder()
    geometry_cache = {}
    instance_count = 0
    for instance in depsgraph.object_instances:
        if test_break is not None and instance_count % 256 == 0 and test_break():
            return None
        instance_count += 1
        obj = instance.object
        if obj.type == 'LIGHT':
            convert_light(obj.data, instance.matrix_world, builder,
                          getattr(obj, "visible_camera", True))
        elif obj.type in GEOMETRY_TYPES and instance.show_self:
            _export_object_instance(obj, np.array(instance.matrix_world), builder,
                                    geometry_cache)
    positions, indices, normals, uvs, material_ids = builder.geometry()
    camera = convert_camera(camera_object.evaluated_get(depsgraph), width, height,
                            builder.warn, frame)
    environment, environment_texture, environment_to_world = convert_world(
        scene.world, builder.warn, builder.textures)
    if scene.render.use_motion_blur:
        builder.warn("motion blur is not supported; the frame renders at one instant "
                     "(Output > Motion Blur)")
    return SceneData(
        positions=positions, indices=indices, normals=normals, uvs=uvs,
        material_ids=material_ids, materials=builder.materials or [DEFAULT_MATERIAL],
        lights=builder.lights, camera=camera, environment=environment,
        width=width, height=height, textures=builder.textures.textures,
        environment_texture=environment_texture,
        environment_to_world=environment_to_world,
        warnings=builder.warnings,
        stats={"seconds": time.perf_counter() - start, "instances": instance_count,
               "triangles": len(indices), "meshes": len(geometry_cache),
               "dropped_triangles": builder.dropped_triangles})


def _export_object_instance(obj, matrix, builder, geometry_cache):
    key = (obj.name_full, obj.data.name_full if obj.data is not None else "")
    cached = geometry_cache.get(key)
    if cached is None:
        cached = geometry_cache[key] = _read_object(obj, builder)
    geometry, slot_materials = cached
    if geometry is None:
        return
    world = transform_geometry(geometry, matrix)
    slots = np.clip(geometry.slot_indices, 0, len(slot_materials) - 1)
    builder.add_triangles(world.positions, slot_materials[slots], world.normals, world.uvs,
                          source=f"object '{obj.name}'")


def _read_object(obj, builder):
    """(object-space MeshGeometry or None, material table index per slot). UVs are read
    only when one of the object's materials has a texture."""
    slot_materials = np.array(
        [builder.material_id(_material_key(slot.material),
                             lambda slot=slot: convert_material(slot.material, builder.warn,
                                                                builder.textures))
         for slot in obj.material_slots] or
        [builder.material_id(None, lambda: DEFAULT_MATERIAL)], dtype=np.uint32)
    need_uvs = any(builder.materials[i].color_texture >= 0 for i in slot_materials)
    volumes = [slot.material for slot in obj.material_slots if volume_only(slot.material)]
    if volumes and len(volumes) == len(obj.material_slots):
        builder.warn(f"object '{obj.name}': its material '{volumes[0].name}' has only a "
                     "Volume output; volumes are not supported, so the object is left out")
        return None, None
    try:
        mesh = obj.to_mesh()
    except RuntimeError as error:
        builder.warn(f"object '{obj.name}' could not be converted to a mesh: {error}")
        return None, None
    try:
        geometry = mesh_geometry(mesh, need_uvs) if mesh is not None else None
    finally:
        obj.to_mesh_clear()
    if volumes and geometry is not None:
        builder.warn(f"object '{obj.name}': the faces with material '{volumes[0].name}' "
                     "(only a Volume output) are left out; volumes are not supported")
        volume_slots = np.array([volume_only(slot.material) for slot in obj.material_slots])
        keep = ~volume_slots[np.clip(geometry.slot_indices, 0, len(volume_slots) - 1)]
        geometry = geometry.subset(keep)
    if need_uvs and geometry is not None and geometry.uvs is None:
        builder.warn(f"object '{obj.name}' has a textured material but no UV map; "
                     "its texture is sampled at UV (0, 0)")
    return geometry, slot_materials


def _material_key(material):
    return None if material is None else material.name_full
