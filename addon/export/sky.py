"""Sky Texture: Blender's sky models (Nishita up to 4.x; Single and Multiple Scattering,
its 5.x successors; Hosek-Wilkie, Preetham) evaluated by Blender itself. A second
Blender renders the node with Cycles (export/sky_bake.py) into an equirectangular map,
the sky without its sun disc, which becomes the environment map; the sun disc of the
physical skies becomes a sun light of the disc's measured irradiance, direction and size.
Results are kept per set of node settings for the session, so an animation bakes once (a
bake takes about 2-10 s on two cores).

When the bake fails (no Blender binary, Cycles missing, a timeout) the world falls back
to grey with a warning naming the world and the reason.
"""

import json
import os
import subprocess
import tempfile
import time

import bpy
import numpy as np

from .. import compat
from .scene_data import LightData, TextureData

MAP_SIZE = (256, 128)
MAP_SAMPLES = 16
TIMEOUT_SECONDS = 120

# The node settings that shape each sky, as the bake reproduces them. 5.0 split Nishita
# into 'SINGLE_SCATTERING' and 'MULTIPLE_SCATTERING' and renamed dust_density to
# aerosol_density.
_PHYSICAL = ("sun_disc", "sun_size", "sun_intensity", "sun_elevation", "sun_rotation",
             "altitude", "air_density", "ozone_density")
SETTINGS = {
    'NISHITA': _PHYSICAL + ("dust_density",),
    'SINGLE_SCATTERING': _PHYSICAL + ("aerosol_density",),
    'MULTIPLE_SCATTERING': _PHYSICAL + ("aerosol_density",),
    'HOSEK_WILKIE': ("sun_direction", "turbidity", "ground_albedo"),
    'PREETHAM': ("sun_direction", "turbidity"),
}
# The skies whose sun disc (sun_disc, sun_elevation, sun_rotation, sun_size) becomes a
# sun light; the others draw no disc.
SUN_DISC_TYPES = ('NISHITA', 'SINGLE_SCATTERING', 'MULTIPLE_SCATTERING')
# The Node's own properties, which no sky type reads.
_NODE_PROPERTIES = {"rna_type", "type", "location", "width", "width_hidden", "height",
                    "dimensions", "name", "label", "inputs", "outputs", "internal_links",
                    "parent", "use_custom_color", "color", "select", "show_options",
                    "show_preview", "hide", "mute", "show_texture", "bl_idname", "bl_label",
                    "bl_description", "bl_icon", "bl_static_type", "bl_width_default",
                    "bl_width_min", "bl_width_max", "bl_height_default", "bl_height_min",
                    "bl_height_max", "texture_mapping", "color_mapping", "warning_propagation",
                    "location_absolute", "color_tag", "is_active_output"}

_baked = {}


class SkyBakeError(Exception):
    pass


def sky_settings(node, warn=None):
    """The node's sky type and settings as plain values (JSON and dictionary keys). A sky
    type this add-on does not know (a newer Blender's) is baked with every setting the
    node has, its sun disc (if any) in the map, after a warning naming it."""
    settings = {"sky_type": node.sky_type}
    names = SETTINGS.get(node.sky_type)
    if names is None:
        if warn is not None:
            warn(f"the Sky Texture's type '{node.sky_type}' is not known to this add-on; "
                 "it is baked as Blender renders it, with its sun disc (if any) in the "
                 "environment map instead of a sun light")
        names = sorted(p.identifier for p in node.bl_rna.properties
                       if not p.is_readonly and p.identifier not in _NODE_PROPERTIES
                       and p.type in ('BOOLEAN', 'INT', 'FLOAT'))
    for name in names:
        value = getattr(node, name)
        settings[name] = tuple(float(v) for v in value) if hasattr(value, "__len__") \
            else (bool(value) if isinstance(value, bool) else float(value))
    return settings


def bake_sky(node, strength, warn, textures, add_light):
    """The environment texture index for a Sky Texture node (its sun disc added as a sun
    light of strength x the disc's irradiance), or -1 after a warning."""
    settings = sky_settings(node, warn)
    key = json.dumps(settings, sort_keys=True)
    if key not in _baked:
        try:
            _baked[key] = _bake(settings)
        except SkyBakeError as error:
            warn(f"the Sky Texture could not be evaluated ({error}); the world is grey")
            return -1
    pixels, sun = _baked[key]
    index = len(textures.textures)
    textures.textures.append(TextureData(pixels, wrap="repeat", name=f"sky {node.name}"))
    if sun is not None and strength > 0.0:
        irradiance = np.array(sun["irradiance"]) * strength
        power = float(irradiance.max())
        if power > 0.0:
            add_light(LightData("sun", tuple(float(c) for c in irradiance / power), power,
                                direction=tuple(-float(c) for c in sun["direction"]),
                                angle=float(sun["angle"])))
    return index


def _bake(settings):
    """(pixels (H, W, 4) float32, row 0 at the bottom; sun dict or None)."""
    binary = bpy.app.binary_path
    if not binary or not os.path.exists(binary):
        raise SkyBakeError("Blender's own binary is not available to render it")
    script = os.path.join(os.path.dirname(os.path.abspath(__file__)), "sky_bake.py")
    started = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="glslppm-sky-") as folder:
        request = {
            "settings": {k: v for k, v in settings.items()},
            "sun_disc": settings["sky_type"] in SUN_DISC_TYPES and bool(settings["sun_disc"]),
            "compat": os.path.abspath(compat.__file__),
            "map": os.path.join(folder, "sky.exr"),
            "sun": os.path.join(folder, "sun.json"),
            "size": MAP_SIZE, "samples": MAP_SAMPLES,
        }
        path = os.path.join(folder, "request.json")
        with open(path, "w") as file:
            json.dump(request, file)
        try:
            run = subprocess.run(
                [binary, "-b", "--factory-startup", "--python-exit-code", "1",
                 "--python", script, "--", path],
                capture_output=True, text=True, timeout=TIMEOUT_SECONDS)
        except (OSError, subprocess.TimeoutExpired) as error:
            raise SkyBakeError(f"Blender could not render it: {error}") from error
        if run.returncode != 0 or not os.path.exists(request["map"]):
            last = (run.stderr or run.stdout).strip().splitlines()[-1:] or ["no output"]
            raise SkyBakeError(f"Blender's render of it failed: {last[0]}")
        pixels = _read_exr(request["map"])
        sun = None
        if os.path.exists(request["sun"]):
            with open(request["sun"]) as file:
                sun = json.load(file)
    if not np.isfinite(pixels).all():
        raise SkyBakeError("its render holds NaN or infinite values")
    print(f"GLSLPPM: baked the {settings['sky_type'].title()} sky in "
          f"{time.perf_counter() - started:.1f} s")
    return pixels, sun


def _read_exr(path):
    image = bpy.data.images.load(path, check_existing=False)
    try:
        width, height = image.size
        pixels = np.empty(width * height * 4, dtype=np.float32)
        image.pixels.foreach_get(pixels)
    finally:
        bpy.data.images.remove(image)
    pixels = pixels.reshape(height, width, 4)
    pixels[..., 3] = 1.0
    return np.ascontiguousarray(pixels)
