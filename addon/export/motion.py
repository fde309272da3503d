"""Motion blur's export (docs/motion_blur.md): Blender's shutter, and the camera's and each
moving object's matrix_world at the motion steps, read by evaluating the render depsgraph at
subframes as Cycles does (RenderEngine.frame_set), the frame restored afterwards, and the
shutter curve. Transform motion only: deformation (armatures, shape keys, modifiers) and the
rolling shutter are warned about and not done."""

import math
from dataclasses import dataclass, field

import numpy as np

from ..compat import motion_blur_position, object_motion_blur

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
    most = 1
    for obj in scene.objects:
        use, steps = object_motion_blur(obj)
        if use and obj.type in geometry_types:
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
                if obj.type not in geometry_types or not instance.show_self:
                    continue
                use, steps = object_motion_blur(obj)
                if not use:
                    continue
                key = instance_key(instance)
                samples.objects.setdefault(key, []).append(
                    np.array(instance.matrix_world, dtype=np.float32))
                samples.steps[key] = step_count(steps)
            if camera_object is not None:
                evaluated = camera_object.evaluated_get(depsgraph)
                samples.camera.append(np.array(evaluated.matrix_world, dtype=np.float64))
                samples.camera_fov_x.append(fov_of(evaluated))
    finally:
        engine.frame_set(frame, subframe)
    # An instance seen at some steps only (appearing, disappearing) does not blur.
    samples.objects = {k: m for k, m in samples.objects.items() if len(m) == count}
    return samples


def object_steps(samples, key):
    """(times, (N, 4, 4) matrices) of one object at its own step count, or None when it
    does not move in the shutter."""
    matrices = samples.objects.get(key)
    if matrices is None or all(np.array_equal(m, matrices[0]) for m in matrices):
        return None
    stride = (len(samples.times) - 1) // (samples.steps[key] - 1)
    picked = range(0, len(samples.times), stride)
    return ([samples.times[k] for k in picked],
            np.ascontiguousarray([matrices[k] for k in picked], dtype=np.float32))


def unsupported_motion_warnings(scene, objects):
    """What motion blur leaves out, for a render with it on: deforming objects, a shutter
    curve that never opens, the rolling shutter."""
    warnings = []
    for obj in objects:
        use, _ = object_motion_blur(obj)
        cycles = getattr(obj, "cycles", None)
        deform = getattr(obj, "use_deform_motion", getattr(cycles, "use_deform_motion", True))
        if not (use and deform) or obj.type != 'MESH':
            continue
        keys = obj.data.shape_keys if obj.data is not None else None
        modifiers = [m.type for m in obj.modifiers if m.type in DEFORMING_MODIFIERS]
        if modifiers or (keys is not None and len(keys.key_blocks) > 1):
            warnings.append(f"object '{obj.name}': deformation motion blur (armatures, shape "
                            "keys, modifiers) is not done: it blurs its transform only")
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
