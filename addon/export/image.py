"""Image converter. The renderer takes no textures yet (they come with the scene-breadth
issue), so an image stands in as its mean linear colour, with a warning; a missing
or unreadable file falls back to the socket's own colour, also with a warning.
"""

import os

import bpy
import numpy as np


def image_mean_color(image, fallback, warn):
    if image is None:
        warn("image texture node has no image; using the input's own colour")
        return fallback
    if image.source == 'FILE' and image.packed_file is None:
        path = bpy.path.abspath(image.filepath, library=image.library)
        if not os.path.isfile(path):
            warn(f"image '{image.name}' is missing ({path or 'no file path'}); "
                 "using the input's own colour")
            return fallback
    width, height = image.size
    channels = image.channels
    if width * height * channels == 0:
        warn(f"image '{image.name}' could not be read; using the input's own colour")
        return fallback
    pixels = np.empty(width * height * channels, dtype=np.float32)
    image.pixels.foreach_get(pixels)
    rgb = pixels.reshape(-1, channels)[:, :3] if channels >= 3 else \
        np.repeat(pixels.reshape(-1, channels)[:, :1], 3, axis=1)
    if not image.is_float and image.colorspace_settings.name == 'sRGB':
        rgb = srgb_to_linear(rgb)
    mean = tuple(float(c) for c in rgb.mean(axis=0))
    warn(f"image textures are not supported yet; image '{image.name}' rendered as its "
         f"mean colour ({mean[0]:.3f}, {mean[1]:.3f}, {mean[2]:.3f})")
    return mean


def srgb_to_linear(values):
    """The sRGB transfer function inverted (IEC 61966-2-1)."""
    values = np.asarray(values, dtype=np.float32)
    return np.where(values <= 0.04045, values / 12.92, ((values + 0.055) / 1.055) ** 2.4)
