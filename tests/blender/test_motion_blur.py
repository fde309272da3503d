"""Motion blur through the add-on (issue 32, docs/motion_blur.md): a keyframed strip moving
at constant speed under a sun, seen from above by an orthographic camera, renders as the
analytic box-filtered sweep (tests/python/test_motion_blur.py has the closed form); the
object's matrices come from the depsgraph evaluated at Blender's motion steps, and the
frame is set back afterwards."""

import math

import bpy
import numpy as np

import helpers
from helpers import add_camera, add_light, add_quad, diffuse_material

WIDTH, HEIGHT, HALF = 64, 16, 2.0
STRIP, SPEED, SHUTTER = 0.5, 3.0, 0.5       # units, units per frame, frames
ALBEDO, SUN = 0.8, 2.0


def use_motion_blur(scene, shutter, position='CENTER'):
    """Render Properties > Motion Blur on, with this shutter (in frames) and position (its
    property moved from Cycles' settings to the scene's render settings in 4.x)."""
    scene.render.use_motion_blur = True
    scene.render.motion_blur_shutter = shutter
    owner = scene.render if hasattr(scene.render, "motion_blur_position") else scene.cycles
    owner.motion_blur_position = position


def ramp_mean(a, b, c, d):
    """The mean over x in [a, b] of clip((x - c) / d, 0, 1)."""
    def antiderivative(u):
        return np.where(u < 0, 0.0, np.where(u < 1, 0.5 * u * u, u - 0.5))
    return d * (antiderivative((b - c) / d) - antiderivative((a - c) / d)) / (b - a)


def analytic_columns(shutter, left_at_open):
    edges = np.linspace(-HALF, HALF, WIDTH + 1)
    d = SPEED * shutter
    return (ramp_mean(edges[:-1], edges[1:], left_at_open, d) -
            ramp_mean(edges[:-1], edges[1:], left_at_open + STRIP, d))


def spread(profile):
    x = np.linspace(-HALF, HALF, WIDTH + 1)
    x = 0.5 * (x[:-1] + x[1:])
    w = profile / profile.sum()
    return float((w * (x - (w * x).sum()) ** 2).sum())


def linear_keys(id_data):
    """Every F-curve key of an ID's action made linear. Blender 4.4+ keeps F-curves in the
    layered action's channel bag (5.x has no Action.fcurves); 3.4 and 4.3 on the action."""
    action = id_data.animation_data.action
    if hasattr(action, "fcurves"):
        curves = list(action.fcurves)
    else:
        slot = id_data.animation_data.action_slot
        curves = [curve for layer in action.layers for strip in layer.strips
                  for curve in strip.channelbag(slot).fcurves]
    assert curves, "no F-curves found for the keyframes"
    for curve in curves:
        for point in curve.keyframe_points:
            point.interpolation = 'LINEAR'


def _linear_keyframe(obj, frame):
    """A location keyframe, every key of the object made linear."""
    obj.keyframe_insert("location", frame=frame)
    linear_keys(obj)


def _moving_strip_scene(position):
    scene = helpers.reset_scene(size=(WIDTH, HEIGHT))
    add_camera((0, 0, 4), (0, 0, 0), type='ORTHO', ortho_scale=2 * HALF)
    add_light('SUN', SUN)
    strip = add_quad("Strip", [(0, -1, 0), (STRIP, -1, 0), (STRIP, 1, 0), (0, 1, 0)],
                     material=diffuse_material("White", (ALBEDO,) * 3))
    # The strip's left edge at -0.25 at frame 1, moving at SPEED along x.
    for frame in (0, 2):
        strip.location = (-0.25 + SPEED * (frame - 1), 0, 0)
        _linear_keyframe(strip, frame)
    scene.frame_set(1)
    use_motion_blur(scene, SHUTTER, position)
    scene.glslppm.passes = 64
    scene.glslppm.photons_per_pass = 1024
    return scene, strip


def test_keyframed_strip_renders_the_box_filtered_sweep():
    """Shutter 0.5 centred on frame 1: the edge sweeps D = 1.5 units; each column against
    L times its analytic coverage (bound 0.1 L, as the module's test derives it) and the
    profile's spread within 0.3% (a 1% shutter error moves it 1.8%). Then "start on frame"
    shifts the same sweep by half a shutter."""
    helpers.load_native()
    radiance = ALBEDO * SUN / math.pi
    for position, opens_at in (('CENTER', -0.25), ('START', 0.0)):
        scene, strip = _moving_strip_scene(position)
        image, error, engine = helpers.render_recorded(f"motion_blur_{position.lower()}")
        assert error is None, error
        stats = helpers.last_render_stats()
        assert stats["motion"] == "instances", stats.get("motion")
        assert stats["instancing"] == "two-level", stats["instancing_reason"]
        assert scene.frame_current == 1 and scene.frame_subframe == 0.0
        assert tuple(strip.location) == (-0.25, 0.0, 0.0)
        warnings = helpers.warnings_of(engine)
        assert not any("motion blur is not supported" in w for w in warnings), warnings
        rows = image[..., 0].astype(np.float64) / radiance
        want = analytic_columns(SHUTTER, -0.25 + SPEED * opens_at)
        worst = float(np.abs(rows - want[None, :]).max())
        measured = spread(rows.mean(axis=0))
        exact = spread(want)
        longer = spread(analytic_columns(1.01 * SHUTTER, -0.25 + SPEED * opens_at))
        print(f"  {position}: worst pixel {worst:.3f} of L, spread {measured:.5f} analytic "
              f"{exact:.5f} ({measured / exact - 1:+.3%}), 1% longer shutter "
              f"{longer / exact - 1:+.3%}")
        assert worst < 0.1, worst
        assert abs(measured / exact - 1) < 0.003


def _renders_the_centred_sweep(name, label, motion, radiance=ALBEDO * SUN / math.pi):
    """Renders the scene as built (the strip, however it is made, keyframed as
    _moving_strip_scene keys it, shutter 0.5 centred on frame 1) and checks the closed-form
    sweep: worst pixel within 0.1 L, the profile's spread within 0.3%."""
    image, error, engine = helpers.render_recorded(name)
    assert error is None, error
    assert helpers.last_render_stats()["motion"] == motion, helpers.last_render_stats()
    rows = image[..., 0].astype(np.float64) / radiance
    want = analytic_columns(SHUTTER, -0.25 - SPEED * SHUTTER / 2)
    worst = float(np.abs(rows - want[None, :]).max())
    measured, exact = spread(rows.mean(axis=0)), spread(want)
    print(f"  {label}: worst pixel {worst:.3f} of L, spread {measured:.5f} analytic "
          f"{exact:.5f} ({measured / exact - 1:+.3%})")
    assert worst < 0.1, worst
    assert abs(measured / exact - 1) < 0.003
    return engine


def test_a_moving_collection_instance_renders_the_box_filtered_sweep():
    """Instances blur as objects do (issue 32 item 1): the strip kept in a collection that
    the view layer excludes, shown by an Empty instancing that collection, and the Empty
    keyframed as the strip is above. The depsgraph's instance (matched across the motion
    steps by its persistent id) moves; the image is the same closed-form sweep (worst pixel
    0.1 L, spread 0.3%, where a 1% shutter error moves it 1.8%; measured on 3.4.1 0.042 L,
    +0.094%)."""
    helpers.load_native()
    scene, strip = _moving_strip_scene('CENTER')
    strip.animation_data_clear()
    strip.location = (0.0, 0.0, 0.0)
    source = bpy.data.collections.new("Source")
    scene.collection.children.link(source)
    source.objects.link(strip)
    scene.collection.objects.unlink(strip)
    bpy.context.view_layer.layer_collection.children["Source"].exclude = True
    holder = bpy.data.objects.new("Holder", None)
    holder.instance_type = 'COLLECTION'
    holder.instance_collection = source
    scene.collection.objects.link(holder)
    for frame in (0, 2):
        holder.location = (-0.25 + SPEED * (frame - 1), 0, 0)
        _linear_keyframe(holder, frame)
    scene.frame_set(1)
    _renders_the_centred_sweep("motion_blur_collection_instance", "collection instance",
                               "instances")


def _strip_by_geometry_nodes(material):
    """An object whose geometry nodes put one instance of a STRIP x 2 grid (the strip, centred
    on the object's origin, of `material`) on one point."""
    tree = bpy.data.node_groups.new("StripInstance", 'GeometryNodeTree')
    if helpers.BLENDER_4:
        tree.interface.new_socket(name="Geometry", in_out='OUTPUT',
                                  socket_type='NodeSocketGeometry')
    else:
        tree.outputs.new('NodeSocketGeometry', "Geometry")
    nodes, links = tree.nodes, tree.links
    output = nodes.new('NodeGroupOutput')
    point = nodes.new('GeometryNodePoints')
    point.inputs["Count"].default_value = 1
    grid = nodes.new('GeometryNodeMeshGrid')
    grid.inputs["Size X"].default_value = STRIP
    grid.inputs["Size Y"].default_value = 2.0
    grid.inputs["Vertices X"].default_value = 2
    grid.inputs["Vertices Y"].default_value = 2
    assign = nodes.new('GeometryNodeSetMaterial')
    assign.inputs["Material"].default_value = material
    links.new(grid.outputs["Mesh"], assign.inputs["Geometry"])
    place = nodes.new('GeometryNodeInstanceOnPoints')
    links.new(point.outputs["Geometry"], place.inputs["Points"])
    links.new(assign.outputs["Geometry"], place.inputs["Instance"])
    links.new(place.outputs["Instances"], output.inputs[0])
    obj = bpy.data.objects.new("Holder", bpy.data.meshes.new("HolderBase"))
    bpy.context.scene.collection.objects.link(obj)
    obj.modifiers.new("StripInstance", 'NODES').node_group = tree
    return obj


def test_a_moving_geometry_nodes_instance_renders_the_box_filtered_sweep():
    """Geometry-nodes instances blur with their object (issue 32 item 1): the strip made by
    geometry nodes (Instance on Points) on a keyframed object, as above; the closed-form
    sweep (worst pixel 0.1 L, spread 0.3%; measured on 3.4.1 0.042 L, +0.094%)."""
    helpers.load_native()
    scene, strip = _moving_strip_scene('CENTER')
    material = strip.data.materials[0]
    bpy.data.objects.remove(strip)
    holder = _strip_by_geometry_nodes(material)
    for frame in (0, 2):
        holder.location = (-0.25 + SPEED * (frame - 1) + STRIP / 2, 0, 0)
        _linear_keyframe(holder, frame)
    scene.frame_set(1)
    _renders_the_centred_sweep("motion_blur_geometry_nodes", "geometry nodes instance",
                               "instances")


def test_a_keyframed_emitting_strip_renders_the_box_filtered_sweep():
    """A moving object that emits light blurs too: the strip given an Emission shader
    (strength 1.5, white) and no sun, keyframed as above. The add-on sends it as a moving
    instance; the renderer places it once with the emitters and rewrites it per pass
    (docs/motion_blur.md). The same closed form with L = 1.5: worst pixel 0.1 L, spread
    0.3% (measured on 3.4.1 0.042 L, +0.094%)."""
    helpers.load_native()
    scene, strip = _moving_strip_scene('CENTER')
    strip.data.materials[0] = helpers.emission_material("Glow", (1.0, 1.0, 1.0), 1.5)
    for obj in [o for o in scene.objects if o.type == 'LIGHT']:
        bpy.data.objects.remove(obj)
    engine = _renders_the_centred_sweep("motion_blur_emitting_strip", "emitting strip",
                                        "emitters", radiance=1.5)
    assert not any("motion blur" in w for w in helpers.warnings_of(engine))


def test_keyframed_camera_blurs_the_still_strip_the_same_way():
    """The strip stands at its frame place and the camera runs the other way at SPEED: the
    same sweep (the camera's matrices at the steps go to the module, the strip stays a
    placed-once mesh)."""
    helpers.load_native()
    scene, strip = _moving_strip_scene('CENTER')
    strip.animation_data_clear()
    strip.location = (-0.25, 0, 0)
    camera = scene.camera
    for frame in (0, 2):
        camera.location = (-SPEED * (frame - 1), 0, 4)
        _linear_keyframe(camera, frame)
    scene.frame_set(1)
    image, error, _ = helpers.render_recorded("motion_blur_camera")
    assert error is None, error
    stats = helpers.last_render_stats()
    assert stats["motion"] == "camera" and stats["instances"] == 0, stats.get("motion")
    rows = image[..., 0].astype(np.float64) / (ALBEDO * SUN / math.pi)
    want = analytic_columns(SHUTTER, -0.25 - SPEED * SHUTTER / 2)
    worst = float(np.abs(rows - want[None, :]).max())
    error = spread(rows.mean(axis=0)) / spread(want) - 1
    print(f"  camera: worst pixel {worst:.3f} of L, spread {error:+.3%}")
    assert worst < 0.1 and abs(error) < 0.003


def test_motion_blur_off_renders_the_frame_still():
    """Motion blur off: no motion goes to the module, the strip stands at its frame place
    (full coverage over 8 columns) and the frame is untouched."""
    helpers.load_native()
    scene, _ = _moving_strip_scene('CENTER')
    scene.render.use_motion_blur = False
    image, error, _ = helpers.render_recorded("motion_blur_off")
    assert error is None, error
    assert helpers.last_render_stats()["motion"] == "none"
    rows = image[..., 0].astype(np.float64) / (ALBEDO * SUN / math.pi)
    want = analytic_columns(1e-6, -0.25)
    assert float(np.abs(rows - want[None, :]).max()) < 1e-3


def ramp_squared_mean(a, b, c, d):
    """The mean over x in [a, b] of clip((x - c) / d, 0, 1)^2."""
    def antiderivative(u):
        return np.where(u < 0, 0.0, np.where(u < 1, u ** 3 / 3, u - 2.0 / 3.0))
    return d * (antiderivative((b - c) / d) - antiderivative((a - c) / d)) / (b - a)


def centroid(profile):
    x = np.linspace(-HALF, HALF, WIDTH + 1)
    x = 0.5 * (x[:-1] + x[1:])
    return float((profile * x).sum() / profile.sum())


def test_shutter_curve_weights_the_sweep():
    """Render Properties > Motion Blur > Shutter Curve as a ramp from closed at the opening
    to open at the closing: the times' density is 2 s over the shutter, and each column reads
    L times the chance that the strip covers it (the module's test has the closed form).
    Bounds: 0.1 L per pixel (as the box's); the profile's centroid within D / 256 (Koksma,
    256 passes) + 0.002 = 0.008 units of the closed form's, where a box shutter's lies D/6 =
    0.25 units earlier and a shutter 1% longer's 0.01 later (the module's test measured
    +0.0122 for it). No warning about the curve."""
    helpers.load_native()
    scene, _ = _moving_strip_scene('CENTER')
    scene.glslppm.passes = 256
    curve = scene.render.motion_blur_shutter_curve
    points = curve.curves[0].points  # Blender's default: (0, 1), (0.5, 1), (1, 1)
    saved = [(tuple(p.location), p.handle_type) for p in points]
    for p in points:
        p.location = (p.location[0], p.location[0])
        p.handle_type = 'VECTOR'
    curve.update()
    try:
        image, error, engine = helpers.render_recorded("motion_blur_shutter_curve")
    finally:
        for p, (location, handle) in zip(points, saved):
            p.location = location
            p.handle_type = handle
        curve.update()
    assert error is None, error
    assert not any("shutter curve" in w for w in helpers.warnings_of(engine))
    rows = image[..., 0].astype(np.float64) / (ALBEDO * SUN / math.pi)
    edges = np.linspace(-HALF, HALF, WIDTH + 1)
    c, d = -0.25 - SPEED * SHUTTER / 2, SPEED * SHUTTER
    want = (ramp_squared_mean(edges[:-1], edges[1:], c, d) -
            ramp_squared_mean(edges[:-1], edges[1:], c + STRIP, d))
    worst = float(np.abs(rows - want[None, :]).max())
    shift = centroid(rows.mean(axis=0)) - centroid(want)
    box = centroid(analytic_columns(SHUTTER, c)) - centroid(want)
    print(f"  shutter curve (ramp): worst pixel {worst:.3f} of L, centroid {shift:+.4f} units "
          f"from the closed form's (a box shutter's {box:+.4f})")
    assert worst < 0.1, worst
    assert abs(shift) < 0.008, shift
    assert abs(box) > 0.2


def test_what_motion_blur_leaves_out_warns():
    """A shutter curve that never opens and the rolling shutter are not done: each is named
    in a warning, and the transform still blurs (as with a box shutter). Shape keys that do
    not move in the shutter deform nothing (no warning, no deformation)."""
    helpers.load_native()
    scene, strip = _moving_strip_scene('CENTER')
    strip.shape_key_add(name="Basis")
    strip.shape_key_add(name="Bend")
    curve = scene.render.motion_blur_shutter_curve
    points = curve.curves[0].points
    saved = [tuple(p.location) for p in points]
    for p in points:
        p.location = (p.location[0], 0.0)
    curve.update()
    cycles = getattr(scene, "cycles", None)
    rolling = cycles is not None and hasattr(cycles, "rolling_shutter_type")
    if rolling:
        cycles.rolling_shutter_type = 'TOP'
    try:
        image, error, engine = helpers.render_recorded("motion_blur_warns")
    finally:
        if rolling:
            cycles.rolling_shutter_type = 'NONE'
        for p, location in zip(points, saved):
            p.location = location
        curve.update()
    assert error is None, error
    warnings = helpers.warnings_of(engine)
    expected = ["motion blur: the shutter curve is 0 everywhere (the shutter never opens); it "
                "is left out, the shutter opens and closes at once"]
    if rolling:
        expected.append("motion blur: the rolling shutter is not done (every row sees the "
                        "whole shutter)")
    for message in expected:
        assert any(message in w for w in warnings), (message, warnings)
    assert not any("deformation" in w for w in warnings), warnings
    assert helpers.last_render_stats()["motion"] == "instances"
    assert np.isfinite(image).all() and image[..., 0].max() < 0.5 * ALBEDO * SUN / math.pi


def test_keyframed_sun_tilts_over_the_shutter():
    """A sun keyframed to turn about y at 2 rad a frame, 0.7 rad off the vertical at frame 1,
    over a diffuse floor seen from above: shutter 0.5 centred on the frame, so it turns from
    0.2 to 1.2 rad, and the floor's radiance is albedo E / pi times the mean cosine,
    (sin 1.2 - sin 0.2) / 1.0 = 0.7334 (the frame's cos 0.7 is 4.3% above): the image's mean
    within what 256 stratified pass times allow, |cos 1.2 - cos 0.2| / 256 / 0.7334 = 0.33%.
    A keyframed area light moves too (no warning)."""
    helpers.load_native()
    scene = helpers.reset_scene(size=(32, 32))
    add_camera((0, 0, 4), (0, 0, 0), type='ORTHO', ortho_scale=2 * HALF)
    add_quad("Floor", [(-3, -3, 0), (3, -3, 0), (3, 3, 0), (-3, 3, 0)],
             material=diffuse_material("White", (ALBEDO,) * 3))
    sun = add_light('SUN', SUN)
    sun.data.angle = 0.0
    area = add_light('AREA', 1.0, location=(0, 0, 3))
    for frame in (0, 2):
        sun.rotation_euler = (0.0, 0.7 + 2.0 * (frame - 1), 0.0)
        sun.keyframe_insert("rotation_euler", frame=frame)
        area.location = (frame - 1.0, 0.0, 3.0)
        area.keyframe_insert("location", frame=frame)
    linear_keys(sun)
    linear_keys(area)
    scene.frame_set(1)
    use_motion_blur(scene, SHUTTER)
    scene.glslppm.passes = 256
    scene.glslppm.photons_per_pass = 1024
    image, error, engine = helpers.render_recorded("motion_blur_sun")
    assert error is None, error
    assert helpers.last_render_stats()["motion"] == "lights"
    warnings = helpers.warnings_of(engine)
    assert not any("motion" in w for w in warnings), warnings
    area.data.energy = 0.0  # the floor against the sun alone
    image, error, _ = helpers.render_recorded("motion_blur_sun_alone")
    assert error is None, error
    mean_cos = math.sin(1.2) - math.sin(0.2)
    expected = ALBEDO * SUN * mean_cos / math.pi
    measured = float(image[..., :3].astype(np.float64).mean())
    print(f"  tilting sun: floor {measured:.5f} against {expected:.5f} "
          f"({measured / expected - 1:+.3%})")
    strata = abs(math.cos(1.2) - math.cos(0.2)) / 256 / mean_cos
    assert abs(measured / expected - 1) < strata
