"""The GLSLPPM RenderEngine: export, build the native renderer, run SPPM passes and
stream the film into Blender's RenderResult until the passes or the time limit
are spent or the user cancels.

Every failure ends the render with a report and whatever image exists; nothing
escapes render() (an exception there would only print a traceback, and a native
crash would take Blender down, so the module validates scenes before it renders).
"""

import time
import traceback

import bpy
import numpy as np

from .. import native_module
from ..compat import FLAT_RECT
from ..export import ExportError, export_scene
from ..export.camera import convert_camera, view_camera, viewport_camera
from ..export.frame import FrameError, render_frame
from ..properties.preferences import render_device, render_devices
from . import memory, render_passes
from .cancellable import StageClock, call_cancellable
from .light_paths import old_max_bounces_warning
from .native_scene import film_options, native_scene, native_settings
from .progressive import DisplayClock, PassSchedule, long_render_warning, stats_line
from . import viewport


def render_size(render):
    """The image Blender expects: the render region's size, or the frame's."""
    try:
        frame = render_frame(render)
    except FrameError:
        return 1, 1
    return frame.width, frame.height


class GlslppmEngineMixin:
    """The engine's behaviour, apart from its registration. Blender 4.x breaks a
    registered RenderEngine class when another registered class derives from it, so
    variants (the tests' recording engine) derive from this mixin instead."""

    passes_done = 0
    last_stats = {}
    tile_progress = None  # (tile, tiles) while a frame renders as image tiles
    stage_clock = None
    view_layer = None  # the view layer being rendered: its passes (engine/render_passes.py)
    passes_left_empty = frozenset()  # requested passes left empty (VCM's light split)

    def update_render_passes(self, scene=None, renderlayer=None):
        """Blender asks which passes a view layer's result and Render Layers node have."""
        native, _ = native_module.load()
        render_passes.register(self, native, scene, renderlayer)

    def render(self, depsgraph):
        self.stage_clock = StageClock()
        self.tile_progress = None
        try:
            self._render(depsgraph)
        except Exception as error:  # noqa: BLE001 - the last line of defence
            traceback.print_exc()
            self.report_to_user('ERROR', f"unexpected error: {error!r}")

    def report_to_user(self, level, message):
        """Every message goes through here: Blender's report (the render window,
        and an exception for ERROR in scripts) with the engine's name in front."""
        self.report({level}, f"GLSLPPM: {message}")

    def should_stop(self):
        """Between passes: the user cancelled (Esc, closing the render window)."""
        return self.test_break()

    def _render(self, depsgraph):
        scene = depsgraph.scene
        width, height = render_size(scene.render)
        try:
            frame = render_frame(scene.render)
        except FrameError as error:
            self._fail(str(error), width, height)
            return
        native, problem = native_module.load()
        if native is None:
            self._fail(problem, width, height)
            return
        settings = scene.glslppm
        if self.is_preview:
            # Material and light previews: small, within the preview's pass budget.
            viewport.count("previews")
            settings = viewport.preview_settings(settings)
        views = view_names(scene.render)
        # Previews show Combined alone.
        self.view_layer = None if self.is_preview else depsgraph.view_layer
        passes = render_passes.requested(self.view_layer) if self.view_layer else set()
        missing = render_passes.not_rendered(self.view_layer) if self.view_layer else []
        if missing:
            self.report_to_user('WARNING', "passes GLSLPPM does not render are left out of "
                                "the result: " + ", ".join(missing) + " (docs/passes.md)")
        # VCM does not split Combined's light yet (docs/vcm.md): Direct, Indirect and
        # Caustics stay empty, said once; its other passes and the light groups are written.
        self.passes_left_empty = set()
        if settings.estimator == 'VCM':
            self.passes_left_empty = passes & render_passes.LIGHT_SPLIT
            passes -= self.passes_left_empty
        if self.passes_left_empty:
            self.report_to_user('WARNING', "the VCM estimator (in progress) does not split "
                                "Combined's light yet: the passes " +
                                ", ".join(sorted(self.passes_left_empty)) + " stay empty")
        devices = render_devices(settings)
        device = devices[0]
        film = film_options(scene)
        # Every chosen device, one worker each (PPPM); tiles too.
        try:
            full = native_settings(native, settings, width, height, scene.frame_current,
                                   film=film, device=devices, passes=sorted(passes))
        except (native.GlslppmError, ValueError, TypeError) as error:
            self._fail(f"the render settings are not valid: {error}", width, height)
            return
        limits = _device_limits(native, device)
        problem = memory.refusal(memory.estimate(native, full, len(views), limits), limits,
                                 memory.host_available())
        if problem is not None:
            # No result either: Blender's own would be the largest allocation of all.
            self.report_to_user('ERROR', problem)
            return

        self.update_stats("", "GLSLPPM | exporting scene")
        self.stage_clock.enter("export")
        camera_object = self.camera_override or scene.camera
        try:
            data = export_scene(depsgraph, camera_object, width, height, self.should_stop,
                                frame, engine=None if self.is_preview else self)
        except ExportError as error:
            self._fail(str(error), width, height)
            return
        if data is None:
            self._cancelled(width, height)
            return
        # Material and light previews render Blender's own preview scenes: what they would
        # warn about is not the user's to fix (issue 26), so they stay quiet.
        for warning in ([] if self.is_preview else data.warnings):
            self.report_to_user('WARNING', warning)
        old_bounces = None if self.is_preview else old_max_bounces_warning(scene)
        if old_bounces:
            self.report_to_user('WARNING', old_bounces)
        print(f"GLSLPPM: exported {data.triangle_count} triangles, {data.instance_count} "
              f"instances of {len(data.instance_meshes)} meshes, {len(data.lights)} lights, "
              f"{len(data.materials)} materials in {data.stats['seconds']:.2f} s")

        if not data.has_surfaces():
            self.report_to_user('WARNING', "the scene has no geometry; the image shows "
                                "only the world")
            self._fill(width, height, (0.0, 0.0, 0.0, 0.0) if film["transparent"]
                       else tuple(data.environment) + (1.0,))
            return
        if not data.emits_light():
            self.report_to_user('WARNING', "the scene has no lights, emissive materials "
                                "or world light; the image is black")
            self._fill(width, height, (0.0, 0.0, 0.0, 1.0))
            return

        for index, view in enumerate(views):
            if index > 0 and self.should_stop():
                break
            if view:
                # Each view (stereo eye) through its own camera, as Blender places it.
                self.active_view_set(view)
                camera = view_camera(scene, camera_object, view).evaluated_get(depsgraph)
                spherical = self.use_spherical_stereo(camera)
                data.camera = convert_camera(
                    camera, width, height, lambda message: None, frame,
                    view=(self.camera_model_matrix(camera, use_spherical_stereo=spherical),
                          self.camera_shift_x(camera, use_spherical_stereo=spherical)))
            native_data = native_scene(native, data)
            if not self._render_view(native, native_data, full, settings, width, height, view,
                                     warn=index == 0 and not self.is_preview):
                return

    def _render_view(self, native, native_data, full, settings, width, height, view, warn):
        """One view as the module's tiles: one (the frame as it is) where it fits, else bands
        of rows whose visible points fit the GPU's largest storage buffer, each a whole SPPM
        render of its rows (its own photon passes, the whole frame's radius and random
        streams: the tiles join without seams), streamed into the result as it finishes.
        The module runs the tile loop (for_each_tile, glslppm-render's too); this is one
        tile's work. False when the render stops: cancelled, or failed (the result is then
        filled where no tile was written)."""
        try:
            # Decided before anything is allocated.
            tiles = native.plan_tiles(native_data, full)["tiles"]
        except (native.GlslppmError, ValueError, RuntimeError) as error:
            self._fail(f"the renderer could not start: {error}", width, height)
            return False
        finished = [True]
        where = f" ({view})" if view else ""

        def render_tile(index, count, tile, tile_data, tile_settings):
            number, tiled = index + 1, count > 1
            if number > 1 and self.should_stop():
                return False  # the tiles written stay in the result
            if tiled:
                self.tile_progress = (number, count)
                self.update_stats("", f"GLSLPPM | tile {number}/{count}{where}: building BVH "
                                  "and GL programs")
            else:
                self.update_stats("", f"GLSLPPM | building BVH and GL programs{where}")
            self.stage_clock.enter("build")
            renderer = self._build_renderer(
                native, lambda flag: native.Renderer(tile_data, tile_settings, cancel=flag),
                width, height, written=number > 1)
            if renderer is None:
                if number == 1 and self.should_stop():
                    self._cancelled(width, height)
                finished[0] = number > 1
                return False
            if warn and number == 1:
                for warning in renderer.stats().get("warnings", []):
                    self.report_to_user('WARNING', warning)
            try:
                self._render_passes(native, renderer, settings, width, height, view,
                                    tile=(tile, number, count) if tiled else None,
                                    frame=(native_data, full) if tiled else None)
            finally:
                renderer.close()
            return True

        native.for_each_tile(native_data, full, tiles, render_tile)
        return finished[0]

    def _build_renderer(self, native, make, width, height, written=False):
        """The native renderer, make(cancel_flag), built on a worker thread that a cancel
        stops within milliseconds (a 2M-triangle BVH takes seconds); None when cancelled or
        failed. A driver's program compile cannot be interrupted: one still running after
        the grace period is left to finish, and its renderer to the garbage collector.
        written: tiles of the result are already written (a failure then only reports)."""
        flag = native.CancelFlag()
        try:
            renderer, stopped = call_cancellable(
                lambda: make(flag), self.should_stop, flag.set, grace=PASS_GRACE_SECONDS)
        except native.Cancelled:
            return None
        except (native.GlslppmError, ValueError, RuntimeError, TypeError) as error:
            message = f"the renderer could not start: {error}"
            if written:
                self.report_to_user('ERROR', message)
            else:
                self._fail(message, width, height)
            return None
        if stopped:
            if renderer is not None:
                renderer.close()  # the cancel came after the last point that polls it
            return None
        return renderer

    def _render_passes(self, native, renderer, settings, width, height, view="", tile=None,
                       frame=None):
        """Passes into the result: the whole width x height image, or tile = ((x, y, w, h),
        number, count) of it, y from the top, with its share of the time limit; frame: the
        whole frame's (scene, settings) for a tile's farm attributes."""
        prefix, x, y, share = "", 0, 0, 1
        if tile is not None:
            (x, top, tile_width, tile_height), number, count = tile
            y = height - top - tile_height  # Blender's rows run from the bottom
            width, height = tile_width, tile_height
            prefix, share = f"Tile {number}/{count} | ", count
        schedule = PassSchedule(settings.passes, settings.time_limit / share)
        clock = DisplayClock()
        result = self.begin_result(x, y, width, height, view=view)
        combined = result.layers[0].passes["Combined"]
        extra = (render_passes.result_passes(result, native, self.view_layer,
                                             leave_out=self.passes_left_empty)
                 if self.view_layer else {})
        self._group_passes = (render_passes.result_group_passes(result, self.view_layer)
                              if self.view_layer else {})
        start = time.perf_counter()
        film_ok = False
        abandoned = False
        warned_long = False
        self.stage_clock.enter("render")
        try:
            while not self.should_stop():
                elapsed = time.perf_counter() - start
                batch = schedule.next_batch(elapsed)
                if batch == 0:
                    break
                began = time.perf_counter()
                # A pass cannot be interrupted (the first can take a second on
                # llvmpipe): after a cancel the one in flight ends on its own, and
                # close() frees the GPU when it has.
                ran, stopped = call_cancellable(lambda: renderer.run(passes=batch),
                                                self.should_stop, renderer.cancel,
                                                grace=PASS_GRACE_SECONDS)
                if ran:
                    schedule.record(ran, time.perf_counter() - began)
                if stopped:
                    abandoned = ran is None
                    break
                self.passes_done = schedule.done
                elapsed = time.perf_counter() - start
                self.last_stats = renderer.stats()
                if not warned_long and tile is None:  # (tiles: each has its own limit)
                    warning = long_render_warning(schedule, elapsed,
                                                  self.last_stats.get("renderer", "?"))
                    if warning:
                        warned_long = True
                        self.report_to_user('WARNING', warning)
                self.update_stats("", "GLSLPPM | " + prefix +
                                  stats_line(schedule, self.last_stats, elapsed))
                done_tiles = 0 if tile is None else tile[1] - 1
                self.update_progress((done_tiles + schedule.progress(elapsed)) / share)
                if clock.due(elapsed):
                    film_ok = self._write_film(renderer, combined, extra)
                    self.update_result(result)
            if not abandoned:
                film_ok = self._write_film(renderer, combined, extra)
                # Written into the EXR's header by Blender (the whole render's result,
                # not this partial one, keeps stamp data): the pass indices, seed,
                # estimator, settings and scene hash glslppm-merge checks.
                final = self.get_result()
                frame_scene, frame_settings = frame or (None, None)
                for key, value in renderer.farm_attributes(frame_scene,
                                                           frame_settings).items():
                    final.stamp_data_add_field(key, value)
        except native.GlslppmError as error:
            self.report_to_user('ERROR', f"rendering failed after {schedule.done} passes: "
                                f"{error}")
        finally:
            if not film_ok:
                _set_rect(combined, np.zeros((height, width, 4), dtype=np.float32))
            self.end_result(result)
        print(f"GLSLPPM: {prefix}{schedule.done} passes in "
              f"{time.perf_counter() - start:.2f} s on {self.last_stats.get('renderer', '?')}")

    # --- the rendered viewport (engine/viewport.py holds its session) ---

    viewport_session = None
    viewport_texture = None

    def view_update(self, context, depsgraph):
        try:
            self._view_update(context, depsgraph)
        except Exception as error:  # noqa: BLE001 - never a traceback into the UI
            traceback.print_exc()
            if self.viewport_session is not None:
                self.viewport_session.fail(f"unexpected error: {error!r}")

    def view_draw(self, context, depsgraph):
        try:
            self._view_draw(context, depsgraph)
        except Exception as error:  # noqa: BLE001 - never a traceback into the UI
            traceback.print_exc()
            if self.viewport_session is not None:
                self.viewport_session.fail(f"unexpected error: {error!r}")
            self.update_stats("", f"GLSLPPM | error: {error!r}")

    def __del__(self):
        # Blender has invalidated the engine by now: its attributes cannot be read.
        viewport.close_session_of(self)

    def _view_update(self, context, depsgraph):
        settings = depsgraph.scene.glslppm
        session = self.viewport_session
        if session is None:
            native, problem = native_module.load()
            if native is None:
                self.update_stats("", f"GLSLPPM | error: {problem}")
                return
            session = self.viewport_session = viewport.Session(native,
                                                               render_device(settings))
            viewport.watch(self, session)
            viewport.ENGINE_SESSIONS[id(self)] = session
        session.set_limits(settings.viewport_passes, settings.viewport_time_limit)
        width, height = viewport.viewport_size(context.region, settings.viewport_pixel_size)
        film = film_options(depsgraph.scene)
        signature = viewport.settings_signature(settings, film)
        if session.data is None:
            camera = viewport_camera(context.region_data, width, height,
                                     0.5 * context.space_data.clip_end)
            data = session.export(depsgraph, camera, width, height)
            if data is not None:
                session.rebuild(data, settings, film, width, height, signature,
                                depsgraph.scene.frame_current)
                session.camera_key = viewport.view_key(context.region_data, width, height)
            return
        kind, reason = viewport.change_kind(depsgraph, session.data, session.objects)
        if kind is None and signature == session.signature:
            return
        print(f"GLSLPPM viewport: {kind or 'settings'} changed"
              + (f" ({reason})" if reason else ""))
        data = session.data
        if kind == "tables":
            data = session.export_tables(depsgraph)
        elif kind is not None:
            data = session.export(depsgraph, session.data.camera, *session.size)
        if data is None:
            return
        if kind == "tables" and signature == session.signature and session.update_tables(data):
            return
        session.rebuild(data, settings, film, *session.size, signature,
                        depsgraph.scene.frame_current)

    def _view_draw(self, context, depsgraph):
        scene = depsgraph.scene
        session = self.viewport_session
        if session is None:
            return
        settings = scene.glslppm
        region, region_data = context.region, context.region_data
        width, height = viewport.viewport_size(region, settings.viewport_pixel_size)
        key = viewport.view_key(region_data, width, height)
        if session.data is not None and session.error is None and key != session.camera_key:
            camera = viewport_camera(region_data, width, height,
                                     0.5 * context.space_data.clip_end)
            session.camera_key = key
            if session.size != (width, height) or not session.set_camera(camera):
                session.data.camera = camera
                session.rebuild(session.data, settings, film_options(scene), width, height,
                                session.signature, scene.frame_current)
        film = session.film()
        if film is not None:
            self.viewport_texture = viewport.film_texture(film)
        if session.error is not None:
            self.update_stats("", f"GLSLPPM | error: {session.error}")
            session.error_shown = True
            return
        if self.viewport_texture is not None:
            viewport.draw_texture(self, scene, self.viewport_texture, region.width,
                                  region.height)
        self.update_stats("", "GLSLPPM | " + session.status_line())

    def _write_film(self, renderer, combined, extra=None):
        """Combined and the render passes ({module name: RenderPass}) into the result.
        Combined is read bottom row first, as Blender stores it, into one array kept across
        the progressive updates: no flipped copy, no new memory per update."""
        shape = (renderer.settings.height, renderer.settings.width, 4)
        buffer = getattr(self, "_film_buffer", None)
        if buffer is None or buffer.shape != shape:
            buffer = self._film_buffer = np.empty(shape, np.float32)
        pixels = renderer.film(out=buffer, bottom_up=True).reshape(-1, 4)
        combined.rect.foreach_set(pixels.ravel() if FLAT_RECT else pixels)
        if extra:
            images = renderer.render_passes(list(extra), bottom_up=True)
            for name, render_pass in extra.items():
                _set_rect(render_pass, images[name])
        groups = getattr(self, "_group_passes", None)
        if groups:
            images = renderer.light_group_passes(bottom_up=True)
            for name, render_pass in groups.items():
                _set_rect(render_pass, images[name])
        return True

    def _fill(self, width, height, rgba):
        """A finished result of one colour (for scenes with nothing to render)."""
        result = self.begin_result(0, 0, width, height)
        pixels = np.empty((height, width, 4), dtype=np.float32)
        pixels[:] = rgba
        for render_pass in result.layers[0].passes:  # one Combined per view
            if render_pass.name == "Combined":
                _set_rect(render_pass, pixels)
        self.end_result(result)

    def _cancelled(self, width, height):
        """Cancelled before any pass: an empty (transparent) result, since Blender 3.4
        crashes when a cancelled render ends without one."""
        self._fill(width, height, (0.0, 0.0, 0.0, 0.0))

    def _fail(self, message, width, height):
        self.report_to_user('ERROR', message)
        self._fill(width, height, (0.0, 0.0, 0.0, 1.0))


def view_names(render):
    """The views Blender renders: [""] (the one camera) without multi-view; else the views
    in use (Stereo 3D: its left and right), each rendered through its own camera."""
    if not render.use_multiview:
        return [""]
    stereo = render.views_format == 'STEREO_3D'
    names = [view.name for view in render.views
             if view.use and (not stereo or view.name in ("left", "right"))]
    return names or [""]


_limits = {}


def _device_limits(native, device):
    """The module's device_limits() for a device, asked once per session (None when the
    device cannot be opened: the renderer will then say why)."""
    if device not in _limits:
        try:
            _limits[device] = native.device_limits(device)
        except (native.GlslppmError, RuntimeError, AttributeError):
            _limits[device] = None
    return _limits[device]


def _set_rect(render_pass, pixels):
    """pixels (height, width, channels), bottom row first as Blender's rect wants them (the
    module flips its films in the read-back: film(bottom_up=True), render_passes(...,
    bottom_up=True)). foreach_set copies the buffer in one go (assigning rect converts
    pixel by pixel: 1 s for a 1920x1080 frame, against 0.01-0.03 s); Blender 4.x wants it
    flat, 3.x as (pixels, channels): 4 for Combined, 1 or 3 for the other passes."""
    pixels = np.ascontiguousarray(pixels, dtype=np.float32).reshape(-1, render_pass.channels)
    render_pass.rect.foreach_set(pixels.ravel() if FLAT_RECT else pixels)


# How long a cancel waits for the pass (or compile) in flight before leaving it to finish
# alone.
PASS_GRACE_SECONDS = 0.25


class GlslppmRenderEngine(GlslppmEngineMixin, bpy.types.RenderEngine):
    bl_idname = "GLSLPPM"
    bl_label = "GLSLPPM"
    bl_use_preview = True                # material and light previews render with SPPM
    bl_use_postprocess = True
    bl_use_eevee_viewport = True         # Material Preview shading via EEVEE; Rendered: ours
    bl_use_shading_nodes_custom = False  # the standard shader nodes in the node editor
