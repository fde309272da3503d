"""Motion blur's export (docs/motion_blur.md): Blender's shutter, and the camera's and each
moving object's and lamp's matrix_world at the motion steps, read by the render depsgraph at
subframes as Cycles does (RenderEngine.frame_set), the frame restored afterwards, and the
shutter curve. Deformation (armatures, shape keys, modifiers): the vertices (and normals) of
each mesh object that may deform, read at the same steps as its matrix, where its triangles
stay the same. The rolling shutter is warned about and not done."""

import math
from dataclasses import dataclass, field

import numpy as np

from ..compat import motion_blur_position, object_motion_blur
from .mesh import mesh_geometry

# Modifiers that move vertices over time; their motion is not exported (a warning).
DEFORMING_MODIFIERS = {'ARMATURE', 'MESH_DEFORM', 'LATTICE', 'CURVE', 'HOOK', 'SURFACE_DEFORM',
                       'CAST', 'DISPLACE', 'WAVE', 'SIMPLE_DEFORM', 'SMOOTH', 'CLOTH',
                       'SOFT_BODY', 'OCEAN', 'NODES', 'SHRINKWRAP', 'WARP'}


@dataclass
class MotionSamples:
    """Matrices at `times` (frames relative to the frame; Cycles' steps: 2^steps + 1 evenly
    over the shutter, the middle one at its centre)."""
    shutter_open: float
    shutter_length: float
    times: list
    objects: dict = field(default_factory=dict)  # instance_key -> [(4, 4) matrices]
    steps: dict = field(default_factory=dict)    # instance_key -> the object's step count
    # instance_key -> [(corner positions (3T, 3), corner normals or None)] per time
    vertices: dict = field(default_factory=dict)
    camera: list = field(default_factory=list)   # the camera's matrix_world per time
    camera_fov_x: list = field(default_factory=list)
    shutter_curve: list = field(default_factory=list)  # empty: a box shutter


# Points at which the shutter curve is read, as Cycles reads it (RAMP_TABLE_SIZE).
SHUTTER_CURVE_POINTS = 256


def shutter_curve(scene):
    """Render Properties > Motion Blur > Shutter Curve: its value at SHUTTER_CURVE_POINTS
    evenly spaced places from the shutter's opening to its closing, or [] where it is flat
    (a box, the module's default: the same passes' times bit for bit)."""
    mapping = scene.render.motion_blur_shutter_curve
    if not mapping.curves:
        return []
    mapping.initialize()
    curve = mapping.curves[0]
    values = [max(0.0, float(mapping.evaluate(curve, k / (SHUTTER_CURVE_POINTS - 1))))
              for k in range(SHUTTER_CURVE_POINTS)]
    if max(values) == min(values):
        return []
    return values


def shutter(scene):
    """(open, length) in frames relative to the frame, or None when motion blur is off."""
    if not scene.render.use_motion_blur:
        return None
    length = float(scene.render.motion_blur_shutter)
    if not length > 0.0:
        return None
    centre = {'START': 0.5 * length, 'CENTER': 0.0, 'END': -0.5 * length}.get(
        motion_blur_position(scene), 0.0)
    return centre - 0.5 * length, length


def step_count(motion_steps):
    """Cycles' object_motion_steps: 2^steps + 1 (3 for Blender's default 1), so that one
    step is the shutter's centre and fewer steps are a subset of more."""
    return (2 << (min(motion_steps, 8) - 1)) + 1


def may_deform(obj):
    """Whether a mesh object's vertices may move in the shutter (a deforming modifier or
    shape keys) with its deformation motion on: the objects whose vertices are read at the
    steps (reading every mesh at every step would cost every scene)."""
    cycles = getattr(obj, "cycles", None)
    deform = getattr(obj, "use_deform_motion", getattr(cycles, "use_deform_motion", True))
    if obj.type != 'MESH' or not deform:
        return False
    keys = obj.data.shape_keys if obj.data is not None else None
    return (any(m.type in DEFORMING_MODIFIERS for m in obj.modifiers) or
            (keys is not None and len(keys.key_blocks) > 1))


def read_vertices(obj):
    """An evaluated mesh object's corner positions and normals, as the export reads them
    (mesh.mesh_geometry), or None without faces."""
    mesh = obj.to_mesh()
    try:
        geometry = mesh_geometry(mesh) if mesh is not None else None
    finally:
        obj.to_mesh_clear()
    if geometry is None:
        return None
    return geometry.positions, geometry.normals


def instance_key(instance):
    """An object instance's name across depsgraph evaluations."""
    if instance.is_instance:
        parent = instance.parent.name_full if instance.parent is not None else ""
        return (instance.object.name_full, parent, tuple(instance.persistent_id))
    return (instance.object.name_full,)


def sample_motion(engine, depsgraph, camera_object, fov_of, geometry_types):
    """MotionSamples for a final render, or None when motion blur is off. engine.frame_set
    moves the render depsgraph; the frame and subframe are set back before returning.
    fov_of(evaluated camera object) gives its fov_x."""
    scene = depsgraph.scene
    interval = shutter(scene)
    if interval is None:
        return None
    shutter_open, length = interval
    sampled = set(geometry_types) | {'LIGHT'}  # lamps move too (their emitters, per pass)
    most = 1
    for obj in scene.objects:
        use, steps = object_motion_blur(obj)
        if use and obj.type in sampled:
            most = max(most, steps)
    count = step_count(most)
    centre = shutter_open + 0.5 * length
    times = [centre + length * (k / (count - 1) - 0.5) for k in range(count)]
    samples = MotionSamples(shutter_open, length, times, shutter_curve=shutter_curve(scene))
    frame, subframe = scene.frame_current, scene.frame_subframe
    try:
        for t in times:
            target = frame + subframe + t
            whole = math.floor(target)
            engine.frame_set(int(whole), target - whole)
            for instance in depsgraph.object_instances:
                obj = instance.object
                if obj.type not in sampled or (obj.type != 'LIGHT' and not instance.show_self):
                    continue
                use, steps = object_motion_blur(obj)
                if not use:
                    continue
                key = instance_key(instance)
                samples.objects.setdefault(key, []).append(
                    np.array(instance.matrix_world, dtype=np.float32))
                samples.steps[key] = step_count(steps)
                if obj.type != 'LIGHT' and not instance.is_instance and \
                        may_deform(obj.original):
                    samples.vertices.setdefault(key, []).append(read_vertices(obj))
            if camera_object is not None:
                evaluated = camera_object.evaluated_get(depsgraph)
                samples.camera.append(np.array(evaluated.matrix_world, dtype=np.float64))
                samples.camera_fov_x.append(fov_of(evaluated))
    finally:
        engine.frame_set(frame, subframe)
    # An instance seen at some steps only (appearing, disappearing) does not blur.
    samples.objects = {k: m for k, m in samples.objects.items() if len(m) == count}
    samples.vertices = {k: v for k, v in samples.vertices.items() if len(v) == count}
    return samples


def light_steps(samples, key):
    """Scene.set_motion's (times, (N, 4, 4) matrices) of an exported light (point, spot, sun
    or area: the module moves each) that moves in the shutter, None where it stands still."""
    return object_steps(samples, key)


def picked_steps(samples, key):
    """The indices into samples.times of one object's own steps."""
    stride = (len(samples.times) - 1) // (samples.steps[key] - 1)
    return range(0, len(samples.times), stride)


def object_steps(samples, key):
    """(times, (N, 4, 4) matrices) of one object at its own step count, or None when it
    does not move in the shutter."""
    matrices = samples.objects.get(key)
    if matrices is None or all(np.array_equal(m, matrices[0]) for m in matrices):
        return None
    picked = picked_steps(samples, key)
    return ([samples.times[k] for k in picked],
            np.ascontiguousarray([matrices[k] for k in picked], dtype=np.float32))


def object_deformation(samples, key, mesh, name):
    """(times, (S, 3T, 3) positions, (S, 3T, 3) normals or None) of one object's vertices at
    its steps, for Scene.set_motion's meshes; None where they do not move. mesh: the
    exported instance mesh (its corners). A (warning,) where the vertices cannot be used."""
    steps = samples.vertices.get(key)
    if steps is None:
        return None
    picked = [steps[k] for k in picked_steps(samples, key)]
    corners = len(mesh["positions"])
    if any(s is None or len(s[0]) != corners for s in picked):
        return (f"object '{name}': its triangles change in the shutter (or some were left "
                "out), so its deformation is not blurred, as in Cycles",)
    positions = np.ascontiguousarray([s[0] for s in picked], dtype=np.float32)
    if all(np.array_equal(p, positions[0]) for p in positions):
        return None
    normals = None
    if mesh.get("normals") is not None:
        normals = np.ascontiguousarray(
            [s[1] if s[1] is not None else mesh["normals"] for s in picked], dtype=np.float32)
    if not (np.isfinite(positions).all() and (normals is None or np.isfinite(normals).all())):
        return (f"object '{name}': a vertex is not finite at a motion step, so its "
                "deformation is not blurred",)
    times = [samples.times[k] for k in picked_steps(samples, key)]
    return times, positions, normals


def vertices_move(samples, key):
    """Whether an object's vertices were read at the steps and differ between them (or
    change in number: object_deformation then says why they are not used)."""
    steps = samples.vertices.get(key)
    if not steps or any(s is None for s in steps):
        return bool(steps) and any(s is not None for s in steps)
    first = steps[0][0]
    return any(s[0].shape != first.shape or not np.array_equal(s[0], first) for s in steps)


def unsupported_motion_warnings(scene):
    """What motion blur leaves out, for a render with it on: a shutter curve that never
    opens, the rolling shutter."""
    warnings = []
    curve = scene.render.motion_blur_shutter_curve
    points = [p.location[1] for c in curve.curves[:1] for p in c.points]
    if points and max(points) <= 0.0:
        warnings.append("motion blur: the shutter curve is 0 everywhere (the shutter never "
                        "opens); it is left out, the shutter opens and closes at once")
    cycles = getattr(scene, "cycles", None)
    if getattr(cycles, "rolling_shutter_type", 'NONE') != 'NONE':
        warnings.append("motion blur: the rolling shutter is not done (every row sees the "
                        "whole shutter)")
    return warnings
