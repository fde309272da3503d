"""Exports an evaluated depsgraph into SceneData: walks ``object_instances`` once and
hands each instance to the converter for its kind (mesh, light), then adds the
camera and the world.

Mesh data is read once per evaluated object. Objects placed as themselves become
world-space triangles; instances (geometry nodes, particles, collection instances) are
exported by mesh: each mesh once in object space, and a row of the instance table (its
matrix and mesh) per instance, so ten thousand instances cost one read and ten thousand
matrices. The renderer traces them through a two-level MTBVH or flattens them.
"""

import math
import time
from dataclasses import replace

import numpy as np

from .camera import _without_scale, convert_camera, horizontal_fov
from .curves import TriangleBudget, curves_object, hair_systems, point_cloud
from .image import TextureTable
from .light import convert_light
from .light_groups import group_indices, group_of
from .light_linking import LightLinks
from .material import DEFAULT_MATERIAL, convert_material, volume_only
from .mesh import face_normals, mesh_geometry, transform_geometry
from .motion import (instance_key, light_steps, object_deformation, object_steps,
                     sample_motion, unsupported_motion_warnings, vertices_move)
from .scene_data import SceneData
from .texture_mapping import object_spaces, reads_object_coordinates
from .visibility import object_visibility
from .world import convert_world

# Geometry is read from objects whose data is a mesh, as Cycles does (object_is_geometry in
# its blender/object.cpp): since Blender 3.0 a curve, surface, text or metaball object is
# listed itself (its data a Curve or MetaBall) and then its evaluated mesh as an instance of
# it, so reading both drew it twice.
GEOMETRY_TYPES = {'MESH'}


class ExportError(Exception):
    """The scene cannot be rendered; the message says why and what to do."""


class _Cancelled(Exception):
    """The user cancelled during export (raised between steps, caught by export_scene)."""


class CancelPoll:
    """Asks test_break() at most every POLL_SECONDS, between the steps of export: a large
    mesh's steps take tenths of a second each, a thousand instances' much less."""
    POLL_SECONDS = 0.02

    def __init__(self, test_break):
        self._test_break = test_break
        self._last = time.perf_counter()

    def __call__(self):
        if self._test_break is None:
            return
        now = time.perf_counter()
        if now - self._last < self.POLL_SECONDS:
            return
        self._last = now
        if self._test_break():
            raise _Cancelled()


class SceneBuilder:
    """Collects world-space triangles, the material table, lights and warnings."""

    def __init__(self):
        self._positions = []
        self._normals = []
        self._uvs = []
        self._tangents = []
        self._colors = []
        self._material_ids = []
        self._material_index = {}
        self._material_size = {}
        # Each material root's (key, index), in table order: a material, light or world edit
        # replays them (export_tables) instead of reading the meshes again.
        self.material_keys = []
        self.materials = []
        self.lights = []
        self.warnings = []
        self._warned = set()
        self.dropped_triangles = 0
        self.textures = TextureTable(self.warn)
        self.check_cancel = CancelPoll(None)
        self.instance_meshes = []
        self.light_group_indices = {}  # the view layer's light groups (export/light_groups.py)
        self.light_links = LightLinks((), self.warn)  # export/light_linking.py
        self._instance_mesh_index = {}
        self._instance_matrices = []
        self._instance_mesh_ids = []

    def warn(self, message):
        """Keeps each distinct warning once (one per material, not per instance)."""
        if message not in self._warned:
            self._warned.add(message)
            self.warnings.append(message)

    def material_id(self, key, make):
        """Index of a material's root in the table, converting it the first time it is
        seen. make() returns the material's entries, root first, their mix indices
        relative to that list; they are appended with the indices rebased."""
        index = self._material_index.get(key)
        if index is None:
            index = len(self.materials)
            entries = make()
            self.materials.extend(
                replace(m, mix_a=m.mix_a + index, mix_b=m.mix_b + index)
                if m.kind == "mix" else m for m in entries)
            self._material_index[key] = index
            self._material_size[index] = len(entries)
            self.material_keys.append((key, index))
        return index

    def material_entries(self, index):
        """The entries of the material rooted at index: the root and its mixed parts."""
        return self.materials[index:index + self._material_size[index]]

    def material_textured(self, index):
        """True when the material rooted at index (or one of its mixed parts) reads a
        texture."""
        return any(m.textured() for m in self.material_entries(index))

    def material_reads_uvs(self, index):
        """True when the material rooted at index (or one of its mixed parts) has a texture
        looked up at the mesh's uvs (not at Generated or Object coordinates)."""
        return any(k >= 0 and self.textures.textures[k].position_map is None
                   for m in self.material_entries(index)
                   for k in (m.color_texture, m.roughness_texture, m.mix_texture,
                             m.normal_texture, m.bump_texture, m.emission_texture))

    def material_normal_mapped(self, index):
        """True when the material rooted at index has a normal map (its mesh needs
        tangents)."""
        return self.materials[index].normal_texture >= 0

    def material_vertex_colors(self, index):
        """The colour attributes the material rooted at index (or its mixed parts) multiplies
        in, as a set of names ("" the mesh's default)."""
        return {m.vertex_color for m in self.material_entries(index)
                if m.vertex_color is not None}

    def add_light(self, light):
        self.lights.append(light)

    def add_triangles(self, positions, material_ids, normals=None, uvs=None, source="mesh",
                      tangents=None, colors=None):
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
            tangents = None if tangents is None else tangents[keep]
            colors = None if colors is None else colors[keep]
            material_ids = material_ids[finite]
        if normals is not None:
            bad = ~np.isfinite(normals).all(axis=1)
            if bad.any():
                normals = normals.copy()
                normals[bad] = face_normals(positions)[bad]
        self._positions.append(positions)
        self._normals.append(normals)
        self._uvs.append(uvs)
        self._tangents.append(tangents)
        self._colors.append(colors)
        self._material_ids.append(np.ascontiguousarray(material_ids))

    def add_instance(self, key, matrix, make_mesh):
        """One instance of the mesh cached under key, converted by make_mesh() (a dict of
        object-space arrays, or None when it has no triangles) the first time."""
        index = self._instance_mesh_index.get(key)
        if index is None:
            mesh = make_mesh()
            index = self._instance_mesh_index[key] = -1 if mesh is None else len(
                self.instance_meshes)
            if mesh is not None:
                self.instance_meshes.append(mesh)
        if index >= 0:
            self._instance_matrices.append(matrix)
            self._instance_mesh_ids.append(index)
            return len(self._instance_mesh_ids) - 1  # the row in the instance table
        return None

    def instance_mesh_of(self, row):
        """The instance mesh index of an instance table row."""
        return self._instance_mesh_ids[row]

    def instance_table(self):
        """((N, 4, 4) float32 matrices, (N,) uint32 mesh indices), or (None, None)."""
        if not self._instance_mesh_ids:
            return None, None
        return (np.ascontiguousarray(self._instance_matrices, dtype=np.float32),
                np.array(self._instance_mesh_ids, dtype=np.uint32))

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

    def tangents(self):
        """(V, 4) float32 tangents when a normal-mapped mesh has them, else None; the
        other meshes' corners get (1, 0, 0, 1), which no normal map reads."""
        if all(t is None for t in self._tangents):
            return None
        return _concatenate(
            [t if t is not None else np.tile(np.float32([1, 0, 0, 1]), (len(p), 1))
             for p, t in zip(self._positions, self._tangents)], np.float32)

    def colors(self):
        """(V, 3) float32 linear vertex colours when a mesh has them, else None; the other
        meshes' corners are white, which only materials without vertex colours see."""
        if all(c is None for c in self._colors):
            return None
        return _concatenate(
            [c if c is not None else np.ones((len(p), 3), np.float32)
             for p, c in zip(self._positions, self._colors)], np.float32)


def _concatenate(arrays, dtype):
    if len(arrays) == 1:
        return np.ascontiguousarray(arrays[0], dtype=dtype)
    return np.ascontiguousarray(np.concatenate(arrays), dtype=dtype)


def export_scene(depsgraph, camera_object, width, height, test_break=None, frame=None,
                 camera=None, engine=None):
    """SceneData for an evaluated depsgraph; raises ExportError for a scene that
    cannot render (no camera). test_break() returning True stops early (None).
    frame (a RenderFrame) gives the pixels' shape and the render region. camera (a
    CameraData: the 3D view's, for the rendered viewport) replaces camera_object's.
    engine (a final render's RenderEngine): with Blender's motion blur on, the objects and
    the camera are sampled at the motion steps (export/motion.py); none in the viewport."""
    start = time.perf_counter()
    scene = depsgraph.scene
    if camera_object is None and camera is None:
        raise ExportError("the scene has no camera: add one, or set the scene's "
                          "active camera")
    builder = SceneBuilder()
    builder.check_cancel = CancelPoll(test_break)
    motion = None
    if engine is not None and camera is None:
        size = frame.film_size if frame is not None else (width, height)
        motion = sample_motion(engine, depsgraph, camera_object,
                               lambda cam: horizontal_fov(cam.data, *size), GEOMETRY_TYPES)
    try:
        return _export(depsgraph, scene, camera_object, width, height, frame, builder, start,
                       camera, motion)
    except _Cancelled:
        return None


def _export(depsgraph, scene, camera_object, width, height, frame, builder, start, camera,
            motion=None):
    geometry_cache = {}
    builder.light_group_indices = group_indices(depsgraph.view_layer)
    builder.light_links = LightLinks(depsgraph.objects, builder.warn)
    moving = []  # (instance table row, times, matrices) of objects that move in the shutter
    deforming = []  # (instance mesh, times, positions, normals) of meshes that deform in it
    moving_lights = []  # (light table row, times, matrices) of lamps that move in it
    instance_count = 0
    budget = TriangleBudget(getattr(scene.glslppm, "curve_triangle_limit", 4_000_000),
                            builder.warn)
    for instance in depsgraph.object_instances:
        builder.check_cancel()
        instance_count += 1
        obj = instance.object
        if obj.type == 'LIGHT':
            first = len(builder.lights)
            convert_light(obj.data, instance.matrix_world, builder,
                          getattr(obj, "visible_camera", True))
            group = group_of(obj, builder.light_group_indices)
            link_set = builder.light_links.link_set(obj)
            builder.lights[first:] = [
                replace(light, light_group=group, light_link_set=link_set)
                for light in builder.lights[first:]]
            steps = None
            if motion is not None and len(builder.lights) == first + 1:
                steps = light_steps(motion, instance_key(instance))
            if steps is not None:
                moving_lights.append((first, *steps))
            continue
        if obj.type in GEOMETRY_TYPES and instance.show_self:
            key = instance_key(instance)
            steps = object_steps(motion, key) if motion else None
            deforms = motion is not None and vertices_move(motion, key)
            if instance.is_instance or steps is not None or deforms:
                # A moving or deforming object is an instance: the module moves it per pass.
                row = _export_instance(obj, np.array(instance.matrix_world, dtype=np.float32),
                                       builder, geometry_cache)
                if steps is not None and row is not None:
                    moving.append((row, *steps))
                if deforms and row is not None:
                    mesh = builder.instance_mesh_of(row)
                    d = object_deformation(motion, key, builder.instance_meshes[mesh], obj.name)
                    if d is not None and len(d) == 1:
                        builder.warn(d[0])
                    elif d is not None:
                        deforming.append((mesh, *d))
            else:
                _export_object_instance(obj, np.array(instance.matrix_world), builder,
                                        geometry_cache)
        if obj.type == 'CURVES' and instance.show_self:
            _add_strands(obj, builder, [(0, curves_object(
                obj, instance.matrix_world, budget, builder.warn))])
        elif obj.type == 'POINTCLOUD' and instance.show_self:
            _add_strands(obj, builder, [(0, point_cloud(
                obj, instance.matrix_world, budget, builder.warn))])
        if obj.type == 'MESH' and not instance.is_instance and len(obj.particle_systems):
            _add_strands(obj, builder, hair_systems(obj, depsgraph.mode, budget,
                                                    builder.warn))
    builder.check_cancel()
    positions, indices, normals, uvs, material_ids = builder.geometry()
    instance_matrices, instance_mesh = builder.instance_table()
    builder.check_cancel()
    if camera is None:
        camera = convert_camera(camera_object.evaluated_get(depsgraph), width, height,
                                builder.warn, frame)
    first_world_light = len(builder.lights)
    environment, environment_texture, environment_to_world = _add_world(
        scene, camera, width, height, builder)
    world_group = group_of(scene.world, builder.light_group_indices)
    builder.lights[first_world_light:] = [replace(light, light_group=world_group)
                                          for light in builder.lights[first_world_light:]]
    if motion is not None:
        for warning in unsupported_motion_warnings(scene):
            builder.warn(warning)
    return SceneData(
        positions=positions, indices=indices, normals=normals, uvs=uvs,
        tangents=builder.tangents(), colors=builder.colors(),
        material_ids=material_ids, materials=builder.materials or [DEFAULT_MATERIAL],
        lights=builder.lights, camera=camera, environment=environment,
        width=width, height=height, textures=builder.textures.textures,
        environment_texture=environment_texture,
        environment_to_world=environment_to_world,
        warnings=builder.warnings,
        instance_meshes=builder.instance_meshes, instances=instance_matrices,
        instance_mesh=instance_mesh, material_keys=builder.material_keys,
        light_groups=list(builder.light_group_indices),
        world_light_group=world_group,
        light_link_receives=builder.light_links.tables()[0],
        shadow_link_blocks=builder.light_links.tables()[1],
        motion=_motion_arguments(motion, moving, deforming, moving_lights),
        stats={"seconds": time.perf_counter() - start, "instances": instance_count,
               "triangles": len(indices), "meshes": len(geometry_cache),
               "instance_table": 0 if instance_mesh is None else len(instance_mesh),
               "instance_meshes": len(builder.instance_meshes),
               "dropped_triangles": builder.dropped_triangles})


def _motion_arguments(motion, moving, deforming=(), lights=()):
    """Scene.set_motion's arguments: the moving objects' rows and steps, the deforming
    meshes' vertices at their steps, the moving lamps' rows and steps, and the camera's
    steps where it moves or zooms; None when nothing moves."""
    if motion is None:
        return None
    arguments = {"shutter_open": motion.shutter_open, "shutter_length": motion.shutter_length,
                 "instances": moving, "meshes": list(deforming), "lights": list(lights)}
    cameras = motion.camera
    camera_moves = cameras and (any(not np.array_equal(m, cameras[0]) for m in cameras) or
                                len(set(motion.camera_fov_x)) > 1)
    if camera_moves:
        arguments.update(camera_times=motion.times,
                         camera_to_world=np.ascontiguousarray(
                             [_without_scale(m) for m in cameras], dtype=np.float32),
                         camera_fov_x=motion.camera_fov_x)
    if not (camera_moves or moving or deforming or lights):
        return None
    if motion.shutter_curve:
        arguments["shutter_curve"] = motion.shutter_curve
    return arguments


def _add_world(scene, camera, width, height, builder):
    """The world's (environment, texture index, rotation); a Sky Texture's sun joins the
    lights."""
    world_lights = []
    environment, environment_texture, environment_to_world = convert_world(
        scene.world, builder.warn, builder.textures, world_lights.append)
    for light in world_lights:
        builder.add_light(light)
        if _in_view(camera, width, height, -np.asarray(light.direction)):
            builder.warn(f"world '{scene.world.name}': the Sky Texture's sun disc is in "
                         "view but not drawn; it lights the scene as a sun light")
    return environment, environment_texture, environment_to_world


def export_tables(depsgraph, previous):
    """previous (SceneData) with the materials, lights and world of depsgraph, its
    geometry (triangles, instances, their material ids) kept as it is: what a material,
    light or world edit needs, with no mesh read again. None when the edit reaches the
    geometry's side of the table, and the whole scene must be exported: a material that is
    gone, one whose node tree now has another number of entries (its mixed parts), or one
    that starts or stops reading a texture or a normal map (the meshes' uvs and tangents
    are read only for those)."""
    if previous.light_link_receives:  # links ride on lights and materials: export it all
        return None
    start = time.perf_counter()
    builder = SceneBuilder()
    materials = {m.name_full: m for m in depsgraph.ids if isinstance(m, _material_type())}
    for key, index in previous.material_keys:
        if len(key) > 2:  # converted for one object (Generated or Object coordinates)
            return None
        name, visibility = key
        material = None
        if name is not None:
            material = materials.get(name)
            if material is None:
                return None
        if builder.material_id(key, lambda: _flagged(
                convert_material(material, builder.warn, builder.textures)
                if material is not None else [DEFAULT_MATERIAL], visibility)) != index:
            return None
    if len(builder.materials or [DEFAULT_MATERIAL]) != len(previous.materials):
        return None
    for _, index in previous.material_keys:
        entries = builder.material_entries(index)
        if builder.material_textured(index) != any(
                m.textured() for m in previous.materials[index:index + len(entries)]):
            return None
        # A normal map needs its meshes' tangents, read only for normal-mapped materials;
        # vertex colours are read only for the attributes materials name.
        if (builder.material_normal_mapped(index) !=
                (previous.materials[index].normal_texture >= 0)):
            return None
        if builder.material_vertex_colors(index) != {
                m.vertex_color for m in previous.materials[index:index + len(entries)]
                if m.vertex_color is not None}:
            return None
    for instance in depsgraph.object_instances:
        if instance.object.type == 'LIGHT':
            obj = instance.object
            convert_light(obj.data, instance.matrix_world, builder,
                          getattr(obj, "visible_camera", True))
    camera = previous.camera
    environment, environment_texture, environment_to_world = _add_world(
        depsgraph.scene, camera, previous.width, previous.height, builder)
    return replace(
        previous, materials=builder.materials or [DEFAULT_MATERIAL], lights=builder.lights,
        environment=environment, environment_texture=environment_texture,
        environment_to_world=environment_to_world, textures=builder.textures.textures,
        warnings=builder.warnings, material_keys=builder.material_keys,
        stats=dict(previous.stats, seconds=time.perf_counter() - start, tables_only=True))


def _material_type():
    import bpy
    return bpy.types.Material


def _in_view(camera, width, height, direction):
    """True when a world direction lies within a perspective camera's frame."""
    if camera.projection != "perspective":
        return False
    local = np.asarray(camera.to_world, dtype=np.float64)[:3, :3].T @ direction
    if local[2] >= 0.0:
        return False
    half_x = math.tan(0.5 * camera.fov_x)
    half_y = half_x * height * camera.pixel_aspect / width
    return abs(local[0] / -local[2]) <= half_x and abs(local[1] / -local[2]) <= half_y


def _export_object_instance(obj, matrix, builder, geometry_cache):
    key = (obj.name_full, obj.data.name_full if obj.data is not None else "")
    cached = geometry_cache.get(key)
    if cached is None:
        cached = geometry_cache[key] = _read_object(obj, builder, matrix)
    geometry, slot_materials = cached
    if geometry is None:
        return
    builder.check_cancel()
    world = transform_geometry(geometry, matrix)
    builder.check_cancel()
    slots = np.clip(geometry.slot_indices, 0, len(slot_materials) - 1)
    builder.add_triangles(world.positions, slot_materials[slots], world.normals, world.uvs,
                          source=f"object '{obj.name}'", tangents=world.tangents,
                          colors=world.colors)


def _export_instance(obj, matrix, builder, geometry_cache):
    """A row of the instance table; the object's mesh is read and converted once. Keyed by
    the data's address: geometry-nodes instances of different geometry share one object
    and one data name ('Mesh'), but not the data."""
    key = (obj.name_full, obj.data.as_pointer() if obj.data is not None else 0)

    def make_mesh():
        cached = geometry_cache.get(key)
        if cached is None:
            cached = geometry_cache[key] = _read_object(obj, builder)
        geometry, slot_materials = cached
        return None if geometry is None else _instance_mesh(geometry, slot_materials, obj,
                                                            builder)

    return builder.add_instance(key, matrix, make_mesh)


def _instance_mesh(geometry, slot_materials, obj, builder):
    """The module's instance mesh (object space, corners unshared) for a MeshGeometry;
    triangles with non-finite corners dropped with a warning, as for world triangles."""
    count = geometry.triangle_count
    slots = np.clip(geometry.slot_indices, 0, len(slot_materials) - 1)
    finite = np.isfinite(geometry.positions.reshape(count, 9)).all(axis=1)
    if not finite.all():
        dropped = int(count - finite.sum())
        builder.dropped_triangles += dropped
        builder.warn(f"object '{obj.name}': dropped {dropped} triangle(s) with NaN or "
                     "infinite vertices")
        geometry = geometry.subset(finite)
        if geometry is None:
            return None
        slots = slots[finite]
    normals = geometry.normals
    if normals is not None and not np.isfinite(normals).all():
        bad = ~np.isfinite(normals).all(axis=1)
        normals = normals.copy()
        normals[bad] = face_normals(geometry.positions)[bad]
    count = geometry.triangle_count
    return {"positions": np.ascontiguousarray(geometry.positions, dtype=np.float32),
            "indices": np.arange(3 * count, dtype=np.uint32).reshape(count, 3),
            "normals": None if normals is None else np.ascontiguousarray(normals, np.float32),
            "uvs": (None if geometry.uvs is None
                    else np.ascontiguousarray(geometry.uvs, np.float32)),
            "tangents": (None if geometry.tangents is None
                         else np.ascontiguousarray(geometry.tangents, np.float32)),
            "colors": (None if geometry.colors is None
                       else np.ascontiguousarray(geometry.colors, np.float32)),
            "material_ids": np.ascontiguousarray(slot_materials[slots], dtype=np.uint32)}


def _add_strands(obj, builder, parts):
    """Adds (material slot, (positions, normals) or None) parts of hair, curves or points
    (world space) with the object's slot materials."""
    slot_materials = None
    for slot, triangles in parts:
        if triangles is None:
            continue
        if slot_materials is None:
            slot_materials = _slot_materials(obj, builder)
        positions, normals = triangles
        builder.add_triangles(positions, slot_materials[min(slot, len(slot_materials) - 1)],
                              normals, source=f"object '{obj.name}'")
        builder.check_cancel()


def _slot_materials(obj, builder, matrix=None):
    """The material table index of each of obj's slots (one default when it has none).
    An object hidden from camera rays or casting no shadow gets its own copies of its
    materials, flagged so; so does an object placed at matrix (not instanced) whose
    material reads Generated or Object coordinates (its textures' maps are its own)."""
    visibility = object_visibility(obj, builder.warn)
    textures = builder.textures
    if matrix is not None and any(reads_object_coordinates(slot.material)
                                  for slot in obj.material_slots):
        textures = builder.textures.for_object(object_spaces(obj, matrix))

    # An object in a light group gets its own copies of its materials, marked with the
    # group: the group of what emits is its material's (docs/light_groups.md).
    # So does an object with light or shadow links (docs/light_linking.md): its materials
    # carry its link set (as an emitter) and row (as a receiver and blocker).
    group = group_of(obj, builder.light_group_indices)
    links = builder.light_links
    linked = (links.link_set(obj), links.row(obj)) if links else (0, 0)
    own = ((group,) if group >= 0 else ()) + ((linked,) if linked != (0, 0) else ())

    def key(material):
        if textures.spaces is not None and reads_object_coordinates(material):
            return (_material_key(material), visibility, obj.name_full, group, linked)
        return (_material_key(material), visibility) + own

    def grouped(entries):
        if group >= 0:
            entries = [replace(m, light_group=group) for m in entries]
        if linked != (0, 0):
            entries = [replace(m, light_link_set=linked[0], light_link_row=linked[1])
                       for m in entries]
        return entries

    slot_materials = np.array(
        [builder.material_id(key(slot.material),
                             lambda slot=slot: grouped(_flagged(convert_material(
                                 slot.material, builder.warn, textures), visibility)))
         for slot in obj.material_slots] or
        [builder.material_id((None, visibility),
                             lambda: _flagged([DEFAULT_MATERIAL], visibility))],
        dtype=np.uint32)
    return slot_materials


def _flagged(entries, visibility):
    """A material's entries for an object hidden from camera rays or casting no shadow."""
    return [replace(material, visible_to_camera=visibility.camera,
                    casts_shadow=visibility.shadow) for material in entries]


def _read_object(obj, builder, matrix=None):
    """(object-space MeshGeometry or None, material table index per slot). UVs are read
    only when one of the object's materials has a texture. matrix: where an object placed as
    itself is (None for an instanced mesh)."""
    slot_materials = _slot_materials(obj, builder, matrix)
    need_uvs = any(builder.material_textured(int(i)) for i in slot_materials)
    need_tangents = any(builder.material_normal_mapped(int(i)) for i in slot_materials)
    color_names = sorted(set().union(*(builder.material_vertex_colors(int(i))
                                       for i in slot_materials)))
    color_attribute = color_names[0] if color_names else None
    if len(color_names) > 1:
        builder.warn(f"object '{obj.name}': its materials read the colour attributes "
                     f"{', '.join(repr(n) for n in color_names)}; one per object is rendered: "
                     f"'{color_attribute}' for all of them")
    volumes = [slot.material for slot in obj.material_slots if volume_only(slot.material)]
    if volumes and len(volumes) == len(obj.material_slots):
        builder.warn(f"object '{obj.name}': its material '{volumes[0].name}' has only a "
                     "Volume output; volumes are not supported, so the object is left out")
        return None, None
    builder.check_cancel()
    try:
        mesh = obj.to_mesh()
    except RuntimeError as error:
        builder.warn(f"object '{obj.name}' could not be converted to a mesh: {error}")
        return None, None
    try:
        geometry = (mesh_geometry(mesh, need_uvs, builder.check_cancel, need_tangents,
                                  color_attribute)
                    if mesh is not None else None)
    finally:
        obj.to_mesh_clear()
    if volumes and geometry is not None:
        builder.warn(f"object '{obj.name}': the faces with material '{volumes[0].name}' "
                     "(only a Volume output) are left out; volumes are not supported")
        volume_slots = np.array([volume_only(slot.material) for slot in obj.material_slots])
        keep = ~volume_slots[np.clip(geometry.slot_indices, 0, len(volume_slots) - 1)]
        geometry = geometry.subset(keep)
    if color_attribute is not None and geometry is not None and geometry.colors is None:
        # Cycles reads a colour attribute the mesh lacks as black.
        shown = f"'{color_attribute}'" if color_attribute else "a default"
        builder.warn(f"object '{obj.name}' has no {shown} point or corner colour attribute "
                     "that its material reads; rendering it black, as Cycles does")
        geometry = replace(geometry, colors=np.zeros_like(geometry.positions))
    if need_uvs and geometry is not None and geometry.uvs is None:
        # Cycles reads UV (0, 0) on a mesh without a UV map; textures on Generated or Object
        # coordinates need no UVs (the renderer still takes its uvs, all zero).
        if any(builder.material_reads_uvs(int(i)) for i in slot_materials):
            builder.warn(f"object '{obj.name}' has a textured material but no UV map; "
                         "its texture is sampled at UV (0, 0)")
        geometry = replace(geometry, uvs=np.zeros((len(geometry.positions), 2), np.float32))
    return geometry, slot_materials


def _material_key(material):
    return None if material is None else material.name_full
