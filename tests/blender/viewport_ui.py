"""The rendered viewport and material preview tests, in Blender's real UI (under Xvfb):

    GLSLPPM_XVFB_FBDIR=FB xvfb-run -a -s "-screen 0 1280x800x24 -fbdir FB" \\
        blender --factory-startup -p 0 0 640 480 FILE.blend \\
        --python tests/blender/viewport_ui.py -- [--source addon | --module NAME]
        --out DIR [-k TEXT]

(a .blend on the command line keeps the splash screen away; scripts/test-viewport.sh
makes one). Blender's event loop must keep running while a test waits for passes,
redraws and preview jobs, so each test is a generator that yields the seconds to wait,
driven by a bpy.app.timers callback. Prints PASS/FAIL lines and "RESULT Blender X
(viewport): N passed, M failed, 0 skipped"; exits 1 when any test failed or the suite
did not finish.
"""

import argparse
import os
import struct
import sys
import time
import traceback

import bpy
import numpy as np
from mathutils import Vector

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(HERE, "..", "..", "demo"))

import helpers  # noqa: E402
from run import enable_addon  # noqa: E402

SIZE = None                # the 3D view's window region (main() fills the window with it)
PASSES = 48
PHOTONS = 16384


def parse_args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    parser = argparse.ArgumentParser(prog="viewport_ui.py")
    parser.add_argument("--module")
    parser.add_argument("--source")
    parser.add_argument("--out", required=True)
    parser.add_argument("-k", dest="keywords", action="append", default=[])
    parser.add_argument("--capture", help="save the docs' viewport image here instead")
    parser.add_argument("--capture-passes", type=int, default=8)
    return parser.parse_args(argv)


# --- the 3D view ---

def view3d():
    """(window, area, space, window region) of the first 3D view."""
    window = bpy.context.window_manager.windows[0]
    for area in window.screen.areas:
        if area.type == 'VIEW_3D':
            region = next(r for r in area.regions if r.type == 'WINDOW')
            return window, area, area.spaces.active, region


def viewport_module():
    return sys.modules[helpers.ADDON.__name__ + ".engine.viewport"]


def session():
    sessions = viewport_module().SESSIONS
    return sessions[-1] if sessions else None


def counts():
    return dict(viewport_module().COUNTS)


def set_view(space, location=(0.0, -3.6, 1.0), target=(0.0, 0.0, 1.0)):
    """A perspective 3D view from location towards target, the lens 50 mm."""
    rv3d = space.region_3d
    rv3d.view_perspective = 'PERSP'
    space.lens = 50.0
    direction = Vector(target) - Vector(location)
    rotation = direction.to_track_quat('-Z', 'Y')
    rv3d.view_rotation = rotation
    rv3d.view_distance = direction.length
    rv3d.view_location = Vector(target)


def plain_view(space):
    """Nothing drawn over the render: no overlays, gizmos, header or side regions."""
    space.overlay.show_overlays = False
    space.show_gizmo = False
    space.show_region_header = False
    space.show_region_toolbar = False
    space.show_region_ui = False
    if hasattr(space, "show_region_tool_header"):
        space.show_region_tool_header = False


def rendered(on=True):
    _, _, space, _ = view3d()
    space.shading.type = 'RENDERED' if on else 'SOLID'


def wait_until(condition, timeout, what):
    """Yields until condition() is true; fails after timeout seconds."""
    began = time.perf_counter()
    while not condition():
        if time.perf_counter() - began > timeout:
            raise AssertionError(f"waited {timeout} s for {what}")
        yield 0.1


def wait_finished(passes):
    yield from wait_until(lambda: session() is not None and session().error is None
                          and session().passes >= passes and session().finished,
                          180, f"{passes} viewport passes")
    yield 0.5  # the redraw of the last film
    yield from redraw()


def redraw():
    _, area, _, _ = view3d()
    area.tag_redraw()
    yield 0.3


def screenshot(name):
    """The 3D view's window region as the X server shows it: (H, W, 3) display values in
    [0, 1], row 0 at the top, also saved as OUT/name.png. Read from Xvfb's framebuffer
    file (xvfb-run -s "-fbdir DIR", DIR in GLSLPPM_XVFB_FBDIR): Blender's own read-backs
    (bpy.ops.screen.screenshot, GPUOffScreen.draw_view3d) return black on Blender 4.3
    under Xvfb, while the display shows the image."""
    directory = os.environ.get("GLSLPPM_XVFB_FBDIR")
    if not directory:
        raise RuntimeError("GLSLPPM_XVFB_FBDIR is not set: run under xvfb-run -s "
                           "\"-fbdir DIR\" (scripts/test-viewport.sh)")
    window, _, _, region = view3d()
    screen = read_xwd(os.path.join(directory, "Xvfb_screen0"))
    left = window.x + region.x
    top = screen.shape[0] - (window.y + region.y + region.height)
    crop = screen[top:top + region.height, left:left + region.width]
    assert crop.shape[:2] == (region.height, region.width), (crop.shape, left, top)
    image = bpy.data.images.new(name, region.width, region.height)
    rgba = np.concatenate([crop[::-1], np.ones(crop.shape[:2] + (1,), np.float32)], axis=2)
    image.pixels.foreach_set(rgba.ravel())
    image.filepath_raw = os.path.join(helpers.OUT, f"{name}.png")
    image.file_format = 'PNG'
    image.save()
    bpy.data.images.remove(image)
    return crop


def read_xwd(path):
    """An X window dump (the format of Xvfb's -fbdir file) of a 24-bit screen as
    (H, W, 3) floats in [0, 1], row 0 at the top."""
    with open(path, "rb") as f:
        data = f.read()
    header = struct.unpack(">25I", data[:100])
    header_size, depth, width, height = header[0], header[3], header[4], header[5]
    byte_order, bits_per_pixel, bytes_per_line, colours = (header[7], header[11],
                                                           header[12], header[19])
    if depth != 24 or bits_per_pixel != 32:
        raise RuntimeError(f"{path}: depth {depth}, {bits_per_pixel} bits per pixel; "
                           "expected a 24-bit screen (-screen 0 WxHx24)")
    offset = header_size + colours * 12
    rows = np.frombuffer(data, np.uint8, count=height * bytes_per_line, offset=offset)
    pixels = rows.reshape(height, bytes_per_line)[:, :width * 4].reshape(height, width, 4)
    rgb = pixels[..., 2::-1] if byte_order == 0 else pixels[..., 1:4]  # BGRX or XRGB
    return rgb.astype(np.float32) / 255.0


def srgb(linear):
    linear = np.clip(linear, 0.0, 1.0)
    return np.where(linear <= 0.0031308, 12.92 * linear,
                    1.055 * np.power(linear, 1.0 / 2.4) - 0.055)


def cornell(glass=False):
    import cornell_box
    scene = helpers.reset_scene(size=SIZE)
    cornell_box.build_cornell_box(glass=glass, mirror=False)
    scene.render.dither_intensity = 0.0
    settings = scene.glslppm
    settings.viewport_passes = PASSES
    settings.viewport_photons_per_pass = PHOTONS
    settings.passes = PASSES
    settings.photons_per_pass = PHOTONS
    return scene


def region_grid_means(image, grid):
    h, w = image.shape[:2]
    return np.array([[image[i * h // grid:(i + 1) * h // grid,
                            j * w // grid:(j + 1) * w // grid].mean(axis=(0, 1))
                      for j in range(grid)] for i in range(grid)])


# --- the tests ---

def test_viewport_matches_the_final_render_of_the_same_view():
    """The viewport after PASSES passes against F12 through a camera placed where the view
    is (Blender's view is a 72 mm sensor at the view's lens), same passes, photons and
    seed: the two renders are the same computation, so the display values differ by the
    8-bit screenshot and half-float texture rounding. Bounds: 3x3 region means within
    0.02, 99% of pixels within 0.06 (display units); and the image is not black."""
    scene = cornell()
    _, _, space, region = view3d()
    set_view(space)
    rendered()
    yield from wait_finished(PASSES)
    shot = screenshot("viewport_converged")
    assert shot.shape[:2] == (SIZE[1], SIZE[0]), shot.shape
    rv3d = space.region_3d
    camera = bpy.data.cameras.new("ViewCamera")
    camera.lens = space.lens
    camera.sensor_width = 72.0
    camera.sensor_fit = 'AUTO'
    obj = bpy.data.objects.new("ViewCamera", camera)
    obj.matrix_world = rv3d.view_matrix.inverted()
    scene.collection.objects.link(obj)
    scene.camera = obj
    rendered(False)
    yield 0.5
    final = srgb(helpers.render_image("viewport_final")[..., :3])
    assert shot.mean() > 0.1, f"the viewport is black ({shot.mean():.3f})"
    means = np.abs(region_grid_means(shot, 3) - region_grid_means(final, 3))
    print(f"viewport vs final: region means differ by {means.max():.4f} at most, "
          f"mean {shot.mean():.3f} vs {final.mean():.3f}")
    assert means.max() <= 0.02, means
    difference = np.abs(shot - final).max(axis=2)
    share = float((difference <= 0.06).mean())
    print(f"viewport vs final: {share * 100:.2f}% of pixels within 0.06")
    assert share >= 0.99, share


def test_orthographic_viewport_matches_the_final_render():
    """An orthographic 3D view from inside the box's front (the back half of the room lies
    behind the view's origin) against F12 through an orthographic camera where Blender
    places the view: ortho scale 2 x distance x 36 mm / lens, the camera at the view's
    origin pulled back by half the clip end. Bounds: 3x3 region means within 0.02 as in
    the perspective test; 97% of pixels within 0.06 (measured 98.6%): both cameras sit
    500 units from the box, where float32 rounds the two paths' ray origins differently by
    about 3e-5, so rays at edges land on different sides and those pixels' noise differs."""
    scene = cornell()
    _, _, space, _ = view3d()
    set_view(space, location=(0.0, -0.5, 1.0), target=(0.0, 0.5, 1.0))
    space.region_3d.view_perspective = 'ORTHO'
    space.region_3d.view_distance = 1.0
    rendered()
    yield from wait_finished(PASSES)
    shot = screenshot("viewport_orthographic")
    rv3d = space.region_3d
    camera = bpy.data.cameras.new("ViewCamera")
    camera.type = 'ORTHO'
    camera.ortho_scale = 2.0 * rv3d.view_distance * 36.0 / space.lens
    camera.sensor_fit = 'AUTO'
    camera.clip_start, camera.clip_end = 1e-3, space.clip_end
    obj = bpy.data.objects.new("ViewCamera", camera)
    matrix = rv3d.view_matrix.inverted()
    matrix.translation += matrix.col[2].xyz * (0.5 * space.clip_end)
    obj.matrix_world = matrix
    scene.collection.objects.link(obj)
    scene.camera = obj
    rendered(False)
    yield 0.5
    final = srgb(helpers.render_image("viewport_orthographic_final")[..., :3])
    assert shot.mean() > 0.1, f"the viewport is black ({shot.mean():.3f})"
    means = np.abs(region_grid_means(shot, 3) - region_grid_means(final, 3))
    difference = np.abs(shot - final).max(axis=2)
    share = float((difference <= 0.06).mean())
    print(f"orthographic viewport vs final: region means within {means.max():.4f}, "
          f"{share * 100:.2f}% of pixels within 0.06")
    assert means.max() <= 0.02, means
    assert share >= 0.97, share


def test_pixel_size_renders_at_a_fraction_of_the_region():
    """Pixel Size 2: the renderer's image is half the region's width and height, drawn over
    the whole region; its 3x3 region means match F12 of the same view at that half size
    within 0.02."""
    scene = cornell()
    scene.glslppm.viewport_pixel_size = 2
    _, _, space, region = view3d()
    set_view(space)
    rendered()
    yield from wait_finished(PASSES)
    size = session().size
    assert size == (region.width // 2, region.height // 2), size
    shot = screenshot("viewport_pixel_size_2")
    camera = bpy.data.cameras.new("ViewCamera")
    camera.lens, camera.sensor_width, camera.sensor_fit = space.lens, 72.0, 'AUTO'
    obj = bpy.data.objects.new("ViewCamera", camera)
    obj.matrix_world = space.region_3d.view_matrix.inverted()
    scene.collection.objects.link(obj)
    scene.camera = obj
    scene.render.resolution_x, scene.render.resolution_y = size
    rendered(False)
    yield 0.5
    final = srgb(helpers.render_image("viewport_pixel_size_final")[..., :3])
    means = np.abs(region_grid_means(shot, 3) - region_grid_means(final, 3))
    print(f"pixel size 2: {size[0]}x{size[1]} over {region.width}x{region.height}, region "
          f"means within {means.max():.4f}")
    assert shot.mean() > 0.1, shot.mean()
    assert means.max() <= 0.02, means


def test_camera_move_restarts_without_export_or_bvh_build():
    cornell()
    _, _, space, _ = view3d()
    set_view(space)
    rendered()
    yield from wait_finished(PASSES)
    before, image_before = counts(), screenshot("camera_before")
    resets = session().stats.get("camera_updates", 0)
    set_view(space, location=(0.6, -3.4, 1.3), target=(-0.1, 0.2, 0.8))
    began = time.perf_counter()
    yield from wait_until(lambda: counts()["camera_restarts"] > before["camera_restarts"],
                          10, "the camera restart")
    yield from wait_until(lambda: session().passes >= 1 and session().drawn_passes >= 1,
                          10, "the first image after the move")
    print(f"camera move to first new image: {time.perf_counter() - began:.3f} s "
          "(UI, timers and llvmpipe included)")
    yield from wait_finished(PASSES)
    after, image_after = counts(), screenshot("camera_after")
    assert after["exports"] == before["exports"], (before, after)
    assert after["renderers"] == before["renderers"], (before, after)
    assert after["camera_restarts"] == before["camera_restarts"] + 1, (before, after)
    assert session().stats["camera_updates"] == resets + 1
    assert session().stats["passes"] == PASSES
    changed = np.abs(image_after - image_before).mean()
    assert changed > 0.02, f"the image did not change with the view ({changed:.4f})"


def test_material_colour_change_shows_without_bvh_build():
    scene = cornell()
    _, _, space, _ = view3d()
    set_view(space)
    rendered()
    yield from wait_finished(PASSES)
    before, image_before = counts(), screenshot("material_before")
    red = bpy.data.materials["Red"]
    node = next(n for n in red.node_tree.nodes if n.type == 'BSDF_DIFFUSE')
    node.inputs["Color"].default_value = (0.05, 0.05, 0.8, 1.0)
    yield from wait_until(lambda: counts()["table_updates"] > before["table_updates"],
                          10, "the material update")
    yield from wait_finished(PASSES)
    after, image_after = counts(), screenshot("material_after")
    assert after["renderers"] == before["renderers"], (before, after)
    # The materials again over the last export's geometry: no mesh read.
    assert after["exports"] == before["exports"], (before, after)
    assert after["table_exports"] == before["table_exports"] + 1, (before, after)
    # The left wall: the pixels that were clearly red are clearly blue now.
    wall = (image_before[..., 0] > 0.2) & (image_before[..., 0] > 2.0 * image_before[..., 2])
    assert wall.mean() > 0.02, f"no red wall in view ({wall.mean():.4f} of the pixels)"
    wall_before = image_before[wall].mean(axis=0)
    wall_after = image_after[wall].mean(axis=0)
    print(f"left wall ({wall.mean() * 100:.1f}% of the view) before {wall_before}, "
          f"after {wall_after}")
    assert wall_after[2] > 2.0 * wall_after[0], wall_after
    del scene


def test_time_limit_stops_refinement_and_redraws():
    """Viewport Time Limit 3 s: the worker stops within a batch (0.1 s) and a pass of the
    limit, and after that no pass runs and no film is read (redraws stopped)."""
    scene = cornell()
    scene.glslppm.viewport_passes = 100000
    scene.glslppm.viewport_time_limit = 3.0
    _, _, space, _ = view3d()
    set_view(space)
    rendered()
    yield from wait_until(lambda: session() is not None and session().finished, 30,
                          "the time limit")
    began = time.perf_counter()
    per_pass = session().seconds_per_pass or 0.0
    ran_for = session().stats.get("seconds", 0.0)
    yield 1.0
    passes, reads = session().passes, counts()["film_reads"]
    yield 1.5
    print(f"time limit 3 s: {passes} passes in {ran_for:.2f} s of run(), "
          f"{per_pass:.3f} s a pass")
    assert 0 < passes < 100000
    assert ran_for <= 3.0 + 0.2 + 2.0 * per_pass, (ran_for, per_pass)
    assert session().passes == passes, "passes ran after the time limit"
    assert counts()["film_reads"] == reads, "the film was read after the time limit"
    assert time.perf_counter() - began >= 2.5


def test_object_move_rebuilds():
    cornell()
    _, _, space, _ = view3d()
    set_view(space)
    rendered()
    yield from wait_finished(4)
    before = counts()
    bpy.data.objects["Back"].location.y -= 0.3
    yield from wait_until(lambda: counts()["renderers"] > before["renderers"], 20,
                          "the rebuild after the move")
    after = counts()
    assert after["exports"] == before["exports"] + 1, (before, after)
    assert after["renderers"] == before["renderers"] + 1, (before, after)
    assert after["camera_restarts"] == before["camera_restarts"]
    # Deleting an object rebuilds too, and the session renders the scene without it.
    yield from wait_finished(4)
    bpy.data.objects.remove(bpy.data.objects["Right"])
    yield from wait_until(lambda: counts()["renderers"] > after["renderers"], 20,
                          "the rebuild after the delete")
    yield from wait_until(lambda: session().passes >= 1, 20, "a pass after the delete")
    assert session().data.triangle_count == 8, session().data.triangle_count


def test_leaving_rendered_shading_frees_the_context_and_gl_objects():
    native = helpers.load_native()
    cornell()
    _, _, space, _ = view3d()
    set_view(space)
    rendered()
    yield from wait_until(lambda: session() is not None and session().passes >= 2, 60,
                          "two passes")
    live = native.gl_object_counts()
    assert live["contexts"] >= 1 and live["buffers"] > 0, live
    rendered(False)
    yield from wait_until(lambda: not viewport_module().SESSIONS, 10,
                          "the session to close")
    left = native.gl_object_counts()
    assert all(value == 0 for value in left.values()), left


def test_error_shows_as_text_and_blender_goes_on():
    scene = cornell()
    for obj in list(bpy.data.objects):
        if obj.type == 'LIGHT':
            bpy.data.objects.remove(obj)
    _, _, space, _ = view3d()
    set_view(space)
    rendered()
    yield from wait_until(lambda: session() is not None and session().error is not None
                          and session().error_shown, 20, "the error to be drawn")
    assert "no lights" in session().error, session().error
    screenshot("error")  # the UI still draws
    # Blender goes on: a light brings the image back.
    light = bpy.data.lights.new("Lamp", 'POINT')
    light.energy = 200.0
    obj = bpy.data.objects.new("Lamp", light)
    obj.location = (0.0, 0.0, 1.5)
    scene.collection.objects.link(obj)
    yield from wait_until(lambda: session().error is None and session().passes >= 2, 30,
                          "passes after the fix")


def test_material_preview_renders_a_sphere():
    """The Properties editor's material preview through this engine: Blender renders the
    preview scene's sphere with the material, and the icon is not black."""
    scene = cornell()
    material = bpy.data.materials.new("PreviewMaterial")
    helpers.compat().use_nodes(material)
    principled = material.node_tree.nodes["Principled BSDF"]
    principled.inputs["Base Color"].default_value = (0.8, 0.3, 0.1, 1.0)
    bpy.data.objects["Floor"].data.materials[0] = material
    before = counts()["previews"]
    # What the engine reports while it renders previews (issue 26: Blender's own preview
    # scene's materials earned warnings the user cannot act on). The real engine's method,
    # wrapped to keep a record of its calls.
    mixin = sys.modules[helpers.ADDON.__name__ + ".engine.render_engine"].GlslppmEngineMixin
    original = mixin.report_to_user
    preview_reports = []

    def recording(engine, level, message):
        if engine.is_preview:
            preview_reports.append((level, message))
        return original(engine, level, message)

    mixin.report_to_user = recording
    try:
        window, area, _, _ = view3d()
        with bpy.context.temp_override(window=window, area=area, id=material):
            bpy.ops.ed.lib_id_generate_preview()
        yield from wait_until(lambda: counts()["previews"] > before, 60,
                              "a preview render by this engine")
        preview = material.preview
        yield from wait_until(lambda: max(preview.image_pixels_float[:]) > 0.0, 120,
                              "the preview image")
        yield 1.0
    finally:
        mixin.report_to_user = original
    warnings = [r for r in preview_reports if r[0] == 'WARNING']
    assert not warnings, f"previews warned: {warnings}"
    width, height = preview.image_size
    pixels = np.array(preview.image_pixels_float[:], dtype=np.float32).reshape(height, width, 4)
    centre = pixels[height // 3:2 * height // 3, width // 3:2 * width // 3, :3]
    print(f"preview {width}x{height}: centre mean {centre.mean(axis=(0, 1))}")
    assert centre.mean() > 0.05, centre.mean(axis=(0, 1))
    assert centre[..., 0].mean() > centre[..., 2].mean(), "not the orange material"
    del scene


TESTS = [test_viewport_matches_the_final_render_of_the_same_view,
         test_orthographic_viewport_matches_the_final_render,
         test_pixel_size_renders_at_a_fraction_of_the_region,
         test_camera_move_restarts_without_export_or_bvh_build,
         test_material_colour_change_shows_without_bvh_build,
         test_time_limit_stops_refinement_and_redraws,
         test_object_move_rebuilds,
         test_leaving_rendered_shading_frees_the_context_and_gl_objects,
         test_error_shows_as_text_and_blender_goes_on,
         test_material_preview_renders_a_sphere]


# --- the driver ---

class Driver:
    def __init__(self, tests):
        self.tests = list(tests)
        self.passed, self.failed = [], []
        self.current = None
        self.began = 0.0
        self.started = time.perf_counter()

    def tick(self):
        try:
            if self.current is None:
                if not self.tests:
                    return self.finish()
                test = self.tests.pop(0)
                self.name = test.__name__
                window, area, space, region = view3d()
                plain_view(space)
                rendered(False)
                self.current = self.clean_start(test)
                self.began = time.perf_counter()
            wait = next(self.current)
            return wait
        except StopIteration:
            self.passed.append(self.name)
            print(f"PASS viewport.{self.name} ({time.perf_counter() - self.began:.1f} s)",
                  flush=True)
        except Exception:  # noqa: BLE001 - a failing test, whatever it raised
            self.failed.append(self.name)
            print(f"FAIL viewport.{self.name} ({time.perf_counter() - self.began:.1f} s)",
                  flush=True)
            traceback.print_exc()
            sys.stdout.flush()
        self.current = None
        return 0.2

    @staticmethod
    def clean_start(test):
        """The previous test's session closed first, so that each test sees its own."""
        yield from wait_until(lambda: not viewport_module().SESSIONS, 10,
                              "the previous session to close")
        yield from test()

    def finish(self):
        version = ".".join(map(str, bpy.app.version))
        seconds = time.perf_counter() - self.started
        print(f"RESULT Blender {version} (viewport): {len(self.passed)} passed, "
              f"{len(self.failed)} failed, 0 skipped in {seconds:.0f} s", flush=True)
        for name in self.failed:
            print(f"FAILED viewport.{name}", flush=True)
        os._exit(1 if self.failed else 0)


def capture_for_docs(path, passes):
    """Not a test: the Cornell box with glass and mirror spheres in the rendered viewport,
    header text shown, saved after `passes` passes (docs/viewport.md's image)."""
    import cornell_box
    scene = helpers.reset_scene(size=SIZE)
    cornell_box.build_cornell_box(glass=True, mirror=True)
    scene.glslppm.viewport_passes = 1024
    _, _, space, _ = view3d()
    space.overlay.show_overlays = True
    set_view(space, location=(0.3, -3.9, 1.1), target=(0.0, 0.0, 0.9))
    rendered()
    yield from wait_until(lambda: session() is not None and session().passes >= passes, 120,
                          f"{passes} passes")
    yield 0.5
    helpers.OUT, name = os.path.dirname(path), os.path.splitext(os.path.basename(path))[0]
    screenshot(name)
    print(f"captured {path} at pass {session().passes}", flush=True)


def main():
    args = parse_args()
    helpers.OUT = os.path.abspath(args.out)
    os.makedirs(helpers.OUT, exist_ok=True)
    helpers.SOURCE_MODE = bool(args.source)
    helpers.ADDON, helpers.ADDON_NAME = enable_addon(args)
    tests = [t for t in TESTS
             if not args.keywords or any(k in t.__name__ for k in args.keywords)]
    if args.capture:
        def capture():
            yield from capture_for_docs(os.path.abspath(args.capture), args.capture_passes)
        capture.__name__ = "capture_for_docs"
        tests = [capture]
    driver = Driver(tests)

    def start():
        # The 3D view alone in the window, without top bar and status bar.
        global SIZE
        window, area, space, region = view3d()
        with bpy.context.temp_override(window=window, area=area, region=region):
            bpy.ops.screen.screen_full_area(use_hide_panels=True)
        yield 1.0
        window, area, space, region = view3d()
        plain_view(space)
        yield 1.0
        window, area, space, region = view3d()
        SIZE = (region.width, region.height)
        print(f"3D view window region {region.width}x{region.height}", flush=True)

    setup = start()

    def tick():
        try:
            return next(setup)
        except StopIteration:
            bpy.app.timers.register(driver.tick, first_interval=0.2)
            return None

    bpy.app.timers.register(tick, first_interval=1.0)


main()
