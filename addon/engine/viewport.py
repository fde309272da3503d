"""The rendered viewport: one export and one native renderer per 3D view in Rendered
shading, refined by passes on a worker thread while Blender's UI goes on, and restarted as
cheaply as the change allows:

- the view moved, zoomed or changed lens: ``set_camera`` (no export, no BVH build);
- the region was resized: a new renderer from the exported data (no export);
- a material, light or world changed: those tables exported again over the last export's
  geometry (``export_tables``: no mesh read) and ``update_tables`` (no BVH build), or a
  whole export and a new renderer where the change needs other programs or touches
  geometry;
- an object moved, was added or deleted, or a mesh changed: a new export and renderer.

What each restart did is counted in ``COUNTS`` (process-wide, for tests and the stats
line). Errors end the session's refinement with a message that view_draw shows in the
viewport's header; nothing raises into Blender.
"""

import threading
import time

import numpy as np

from ..export import ExportError, export_scene, export_tables
from .light_paths import bounce_limits
from .native_scene import native_scene, native_settings

# One run() call lasts about this long, so restarts and redraws wait at most that.
BATCH_SECONDS = 0.1

COUNTS = {"exports": 0, "table_exports": 0, "renderers": 0, "camera_restarts": 0,
          "table_updates": 0, "film_reads": 0, "previews": 0}
SESSIONS = []  # the open sessions, oldest first (tests read their state)
ENGINE_SESSIONS = {}  # id(engine) -> its Session, for the engine's __del__


def close_session_of(engine):
    session = ENGINE_SESSIONS.pop(id(engine), None)
    if session is not None:
        session.close()


def count(name):
    COUNTS[name] = COUNTS.get(name, 0) + 1


class Session:
    """One rendered viewport's export, renderer and pass worker."""

    def __init__(self, native, device):
        self.native = native
        self.device = device
        self.data = None            # SceneData of the last export
        self.renderer = None
        self._film = None  # the array film() reads into
        self.size = None            # (width, height) of the renderer's image
        self.camera_key = None
        self.passes = 0             # passes of the current image, as the worker last saw
        self.drawn_passes = -1
        self.started = time.perf_counter()
        self.finished = False       # the pass or time limit was reached
        self.error = None
        self.error_shown = False
        self.warnings = []
        self.limits = (1024, 0.0)   # (passes, seconds)
        self.seconds_per_pass = None
        self.stats = {}
        self.signature = None
        self.objects = None         # object_names() at the last export
        self.camera_key = None
        self._closed = False
        self._build = None          # a _Build the worker has yet to construct
        self._lock = threading.Lock()
        self._wake = threading.Condition(self._lock)
        self._closing = False
        self._worker = threading.Thread(target=self._work, name="glslppm-viewport",
                                        daemon=True)
        self._worker.start()
        SESSIONS.append(self)

    # --- called from Blender's main thread ---

    def export(self, depsgraph, camera, width, height):
        """A new export of the whole scene (SceneData), or None after an error."""
        try:
            data = export_scene(depsgraph, None, width, height, camera=camera)
        except ExportError as error:
            self.fail(str(error))
            return None
        count("exports")
        self.objects = object_names(depsgraph)
        self.warnings = list(data.warnings)
        if not data.has_surfaces():
            self.fail("the scene has no geometry")
            return None
        if not data.emits_light():
            self.fail("the scene has no lights, emissive materials or world light")
            return None
        return data

    def export_tables(self, depsgraph):
        """The last export with depsgraph's materials, lights and world and no mesh read,
        or a whole new export where the edit reaches the geometry (export_tables: None)."""
        try:
            data = export_tables(depsgraph, self.data)
        except ExportError as error:
            self.fail(str(error))
            return None
        if data is None:
            return self.export(depsgraph, self.data.camera, *self.size)
        count("table_exports")
        self.warnings = list(data.warnings)
        if not data.emits_light():
            self.fail("the scene has no lights, emissive materials or world light")
            return None
        return data

    def rebuild(self, data, settings, film, width, height, signature=None, frame=0):
        """A new renderer for data at width x height, built on the worker thread (a BVH
        build takes seconds for millions of triangles; the UI goes on meanwhile, and a
        later rebuild or close() cancels it within milliseconds)."""
        self.stop_renderer()
        native = self.native
        try:
            # Read on this (Blender's) thread: the worker must not touch bpy.
            build = _Build(data, native_settings(native, _viewport_settings(settings), width,
                                                 height, frame, film=film, device=self.device),
                           native.CancelFlag())
        except (native.GlslppmError, ValueError, RuntimeError, TypeError) as error:
            self.fail(f"the renderer could not start: {error}")
            return
        with self._lock:
            self.data = data
            self.size = (width, height)
            self.signature = signature
            self.error = None
            self._build = build
            self._wake.notify_all()

    def set_camera(self, camera):
        """The view changed: the same renderer looks through the new camera (True), or
        the renderer in the making will (True); False when the camera needs a new
        renderer."""
        with self._lock:
            renderer, building = self.renderer, self._build is not None
            self.data.camera = camera  # a build in progress checks it when it is done
        if renderer is None:
            return building
        renderer.cancel()
        try:
            changed = renderer.set_camera(self.native.Camera(**_camera_fields(camera)))
        except (self.native.GlslppmError, ValueError, RuntimeError) as error:
            self.fail(f"the camera could not be set: {error}")
            return True
        if changed:
            count("camera_restarts")
            self._restarted()
        return changed

    def update_tables(self, data):
        """Materials, lights or world changed: True when the renderer took them."""
        with self._lock:
            renderer = self.renderer
        if renderer is None:
            return False
        renderer.cancel()
        try:
            changed = renderer.update_tables(native_scene(self.native, data))
        except (self.native.GlslppmError, ValueError, RuntimeError) as error:
            self.fail(f"the scene could not be updated: {error}")
            return True
        if changed:
            self.data = data
            count("table_updates")
            self._restarted()
        return changed

    def set_limits(self, passes, seconds):
        with self._lock:
            if (passes, seconds) != self.limits:
                self.limits = (passes, seconds)
                self.finished = False
                self._wake.notify_all()

    def film(self):
        """The film (H, W, 4), bottom row first as a texture wants it, when passes ran since
        the last call, else None. Read into one array kept across redraws (the texture is
        made from it at once), so a redraw writes no new memory."""
        with self._lock:
            renderer, passes = self.renderer, self.passes
        if renderer is None or passes == self.drawn_passes or passes == 0:
            return None
        shape = (renderer.settings.height, renderer.settings.width, 4)
        if self._film is None or self._film.shape != shape:
            self._film = np.empty(shape, np.float32)
        try:
            film = renderer.film(out=self._film, bottom_up=True)
        except (self.native.GlslppmError, RuntimeError) as error:
            self.fail(f"the film could not be read: {error}")
            return None
        count("film_reads")
        self.drawn_passes = passes
        return film

    def needs_redraw(self):
        with self._lock:
            if self.error is not None:
                return not self.error_shown
            return self.renderer is not None and self.passes != self.drawn_passes

    def running(self):
        with self._lock:
            return self.renderer is not None and not self.finished and self.error is None

    def fail(self, message):
        self.stop_renderer()
        with self._lock:
            self.error = message
            self.error_shown = False

    def stop_renderer(self):
        with self._lock:
            renderer, self.renderer = self.renderer, None
            build, self._build = self._build, None
            self.passes = 0
        if build is not None:
            build.cancel.set()  # a construction in progress stops within milliseconds
        if renderer is not None:
            renderer.close()  # cancels a run in flight; the GPU is freed when it returns

    def status_line(self):
        """Pass 12/1024 | 0.05 s/pass | 3 s"""
        with self._lock:
            passes, limit = self.passes, self.limits[0]
            per_pass, finished = self.seconds_per_pass, self.finished
            elapsed = time.perf_counter() - self.started
        parts = [f"Pass {passes}/{limit}"]
        if per_pass:
            parts.append(f"{per_pass:.3f} s/pass")
        parts.append(f"{elapsed:.1f} s" + (" (done)" if finished else ""))
        if self.warnings:
            more = f" (+{len(self.warnings) - 1} more)" if len(self.warnings) > 1 else ""
            parts.append(f"warning: {self.warnings[0]}{more}")
        return " | ".join(parts)

    def close(self):
        """Stops the worker and frees the GL context and every buffer."""
        with self._lock:
            if self._closed:
                return
            self._closed = True
            self._closing = True
            self._wake.notify_all()
        self.stop_renderer()
        self._worker.join(timeout=5.0)
        if self in SESSIONS:
            SESSIONS.remove(self)

    def _restarted(self):
        with self._lock:
            self.passes = 0
            self.drawn_passes = -1
            self.started = time.perf_counter()
            self.finished = False
            self._wake.notify_all()

    # --- the worker thread ---

    def _construct(self, build):
        """Builds the renderer of a _Build; it becomes the session's unless superseded."""
        native = self.native
        camera = build.data.camera
        try:
            renderer = native.Renderer(native_scene(native, build.data), build.settings,
                                       cancel=build.cancel)
        except native.Cancelled:
            return
        except (native.GlslppmError, ValueError, RuntimeError, TypeError) as error:
            with self._lock:
                if self._build is build:
                    self._build = None
                    self.error = f"the renderer could not start: {error}"
                    self.error_shown = False
            return
        with self._lock:
            current = self._build is build and not self._closing
            if current:
                self._build = None
                self.renderer = renderer
                moved = build.data.camera is not camera
        if not current:
            renderer.close()
            return
        count("renderers")
        if moved:  # the view changed while the renderer was built
            try:
                renderer.set_camera(native.Camera(**_camera_fields(build.data.camera)))
            except (native.GlslppmError, ValueError, RuntimeError) as error:
                with self._lock:
                    self.error = f"the camera could not be set: {error}"
                    self.error_shown = False
        self._restarted()

    def _work(self):
        while True:
            with self._lock:
                while not self._closing and self._build is None and (
                        self.renderer is None or self.finished or self.error is not None):
                    self._wake.wait()
                if self._closing:
                    return
                build = self._build
            if build is not None:
                self._construct(build)
                continue
            with self._lock:
                if self.renderer is None or self.finished or self.error is not None:
                    continue
                renderer = self.renderer
                passes, seconds = self.limits
                elapsed = time.perf_counter() - self.started
                if self.passes >= passes or (seconds > 0.0 and elapsed >= seconds):
                    self.finished = True
                    continue
                batch = 1
                if self.seconds_per_pass:
                    batch = max(1, min(passes - self.passes,
                                       int(BATCH_SECONDS / self.seconds_per_pass)))
            began = time.perf_counter()
            try:
                ran = renderer.run(passes=batch)
                stats = renderer.stats()
            except self.native.GlslppmError as error:
                with self._lock:
                    if renderer is self.renderer:
                        self.error = f"rendering failed: {error}"
                continue
            except RuntimeError:
                continue  # closed under the run: the next loop sees the new state
            with self._lock:
                if renderer is not self.renderer:
                    continue
                if ran:
                    per_pass = (time.perf_counter() - began) / ran
                    self.seconds_per_pass = per_pass if self.seconds_per_pass is None \
                        else 0.5 * (self.seconds_per_pass + per_pass)
                self.passes = stats["passes"]
                self.stats = stats


def _viewport_settings(settings):
    """scene.glslppm with the viewport's photons per pass. SPPM's photon warm-up stays on:
    the viewport renders the computation F12 does (viewport_ui's tests compare the two),
    so a camera move's first image waits for it."""
    return _Overridden(settings, photons_per_pass=settings.viewport_photons_per_pass)


def preview_settings(settings):
    """scene.glslppm for a material or light preview: its pass budget, no time limit, the
    viewport's photons per pass."""
    return _Overridden(settings, passes=settings.preview_passes, time_limit=0.0,
                       photons_per_pass=settings.viewport_photons_per_pass)


class _Build:
    """A renderer to make on the worker: the exported data, the native Settings, and the
    flag that cancels the construction."""

    def __init__(self, data, settings, cancel):
        self.data = data
        self.settings = settings
        self.cancel = cancel


class _Overridden:
    """A settings object read through, with some values replaced."""

    def __init__(self, base, **values):
        self._base = base
        self._values = values

    def __getattr__(self, name):
        if name in self._values:
            return self._values[name]
        return getattr(self._base, name)


def _camera_fields(camera):
    from dataclasses import asdict
    return asdict(camera)


def view_key(region_data, width, height):
    """What a camera restart depends on: the view and window matrices and the size."""
    return (tuple(map(tuple, region_data.view_matrix)),
            tuple(map(tuple, region_data.window_matrix)), width, height)


def viewport_size(region, pixel_size):
    return max(1, region.width // pixel_size), max(1, region.height // pixel_size)


def object_names(depsgraph):
    """The evaluated objects by name: a collection update that changes none of them (Blender
    4.3 sends some for unrelated edits) changes nothing rendered."""
    return frozenset(obj.name for obj in depsgraph.objects)


def change_kind(depsgraph, data, known_objects=None):
    """What a depsgraph update asks of the viewport, and why: ("geometry", reason)
    (re-export and a new renderer), ("tables", reason) (re-export, update_tables), or
    (None, "") (nothing it renders)."""
    area_lights = data is not None and any(light.kind == "area" for light in data.lights)
    kind, reason = None, ""
    for update in depsgraph.updates:
        id_type = type(update.id).__name__
        what = f"{id_type} '{update.id.name}'"
        if id_type == "Object":
            obj = update.id
            if not (update.is_updated_geometry or update.is_updated_transform):
                continue
            if obj.type == 'CAMERA':
                continue  # the viewport looks through its own view
            if obj.type == 'LIGHT' and not area_lights:
                kind, reason = kind or "tables", reason or what
                continue
            return "geometry", what
        if id_type == "Image":
            # Images reach the renderer as textures built with it; others (a script's,
            # a screenshot's) are none of its business.
            if data is not None and update.id.name in {t.name for t in data.textures}:
                return "geometry", what
            continue
        if id_type == "Collection":
            if known_objects is None or object_names(depsgraph) != known_objects:
                return "geometry", what  # objects added, deleted, hidden or shown
            continue
        if id_type in ("Mesh", "Curve", "Curves", "PointCloud", "MetaBall", "TextCurve",
                       "ParticleSettings"):
            if update.is_updated_geometry:
                return "geometry", what
        if id_type in ("Material", "World", "ShaderNodeTree"):
            kind, reason = kind or "tables", reason or what
        if id_type in ("Light", "AreaLight", "PointLight", "SpotLight", "SunLight"):
            if area_lights:
                return "geometry", what
            kind, reason = kind or "tables", reason or what
    return kind, reason


def settings_signature(settings, film):
    """The render settings a viewport renderer is built with: a change rebuilds it."""
    return (settings.viewport_photons_per_pass, settings.alpha, settings.radius(),
            settings.radius_scale, tuple(bounce_limits(settings).items()), settings.hash_mode,
            settings.rng,
            settings.direct_light, settings.light_tracing, settings.seed,
            tuple(sorted(film.items())))


def film_texture(film):
    """A GPU texture of the film, read bottom row first (ViewportSession.film)."""
    import gpu
    height, width = film.shape[:2]
    pixels = film.reshape(-1)
    buffer = gpu.types.Buffer('FLOAT', pixels.size, pixels)
    return gpu.types.GPUTexture((width, height), format='RGBA32F', data=buffer)


def draw_texture(engine, scene, texture, width, height):
    """The film over the whole region through Blender's display transform (view transform,
    look, exposure, display device), as the final render is shown."""
    import gpu
    from gpu_extras.presets import draw_texture_2d
    gpu.state.blend_set('ALPHA_PREMULT')
    engine.bind_display_space_shader(scene)
    draw_texture_2d(texture, (0, 0), width, height)
    engine.unbind_display_space_shader()
    gpu.state.blend_set('NONE')


REDRAW_SECONDS = 0.1


def watch(engine, session):
    """A timer on Blender's main thread: asks for a redraw when passes have run since the
    last one, and closes the session once Blender has freed the engine (leaving Rendered
    shading), which invalidates it."""
    import bpy

    def tick():
        if session._closed:
            return None
        try:
            if session.needs_redraw():
                engine.tag_redraw()
            else:
                engine.is_animation  # raises ReferenceError once Blender freed the engine
        except ReferenceError:
            session.close()
            for key, value in list(ENGINE_SESSIONS.items()):
                if value is session:
                    del ENGINE_SESSIONS[key]
            return None
        return REDRAW_SECONDS

    bpy.app.timers.register(tick, first_interval=REDRAW_SECONDS)
