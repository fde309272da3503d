"""Image converter: Blender images -> TextureData for the renderer, one per image, wrap
mode, interpolation and uv map, shared by every material and the world that use it.

Pixels are read with ``foreach_get`` from ``image.pixels``, which is laid out as the
renderer wants it (row 0 at the bottom). Blender keeps 8-bit images in their file's
encoding there, float images in scene-linear values, hence:

- 8-bit sRGB          -> uint8 (pixels x 255, rounded; the renderer filters the bytes, then
                         decodes sRGB to linear, as Cycles)
- 8-bit Non-Color/Linear/Raw, and float images -> float32 linear as they are
- 8-bit in any other colour space -> float32 as stored, with a warning.

A missing file renders magenta (1, 0, 1), as Cycles renders it, with a warning naming the
image; an image that cannot be read otherwise falls back to the socket's own colour with a
warning. Export never fails over an image.
"""

import os

import bpy
import numpy as np

from .scene_data import TextureData

LINEAR_COLOR_SPACES = {"Non-Color", "Linear", "Linear Rec.709", "Raw", "Linear CIE-XYZ E",
                       "Linear CIE-XYZ D65", "Linear Rec.2020", "ACEScg", "ACES2065-1"}

# Image Texture extension -> the renderer's wrap (each as Cycles reads texels outside the
# image: shaders/common/textures.glsl).
WRAP_OF_EXTENSION = {'REPEAT': "repeat", 'CLIP': "clip", 'EXTEND': "extend", 'MIRROR': "mirror"}
IDENTITY_UV_MAP = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0))
# Image Texture interpolation -> the renderer's. Cubic is not implemented, and Cycles reads
# Smart as Cubic: both render as Linear, warned once per image.
INTERPOLATION_OF_NODE = {'Linear': "linear", 'Closest': "closest"}


class TextureTable:
    """The scene's textures, one per image, wrap and uv or position map (an image's pixels
    are read once and shared; the renderer packs them once): index() converts an image the
    first time it is seen. `spaces` (texture_mapping.ObjectSpaces) is the object materials
    are being converted for (for_object), None where there is none (instanced meshes)."""

    def __init__(self, warn, spaces=None, shared=None):
        self.spaces = spaces
        if shared is not None:  # a view of another table for one object
            self.textures, self._index, self._pixels, self._warned = shared
        else:
            self.textures, self._index, self._pixels, self._warned = [], {}, {}, set()
        self._warn = warn

    def for_object(self, spaces):
        """This table, converting for the object of spaces (its Generated and Object
        coordinates)."""
        return TextureTable(self._warn, spaces,
                            (self.textures, self._index, self._pixels, self._warned))

    def index(self, image, extension='REPEAT', warn=None, uv_map=IDENTITY_UV_MAP,
              position_map=None, interpolation='Linear'):
        """Index of image in the table, or -1 (missing or unreadable: warned)."""
        warn = warn or self._warn
        if image is None:
            warn("image texture node has no image; using the input's own colour")
            return -1
        wrap = WRAP_OF_EXTENSION.get(extension, "repeat")
        if extension not in WRAP_OF_EXTENSION:
            warn(f"image '{image.name}': extension {extension.title()} is rendered as Repeat")
        filtering = INTERPOLATION_OF_NODE.get(interpolation, "linear")
        if interpolation not in INTERPOLATION_OF_NODE and \
                (image.name_full, interpolation) not in self._warned:
            self._warned.add((image.name_full, interpolation))
            warn(f"image '{image.name}': {interpolation} interpolation is rendered as Linear")
        uv_map = tuple(tuple(float(x) for x in row) for row in uv_map)
        if position_map is not None:
            position_map = tuple(tuple(float(x) for x in row) for row in position_map)
        key = (image.name_full, wrap, uv_map, position_map, filtering)
        if key not in self._index:
            if image.name_full not in self._pixels:
                self._pixels[image.name_full] = image_texture(image, wrap, warn)
            texture = self._pixels[image.name_full]
            if texture is not None:
                texture = TextureData(texture.pixels, wrap, texture.name, uv_map, position_map,
                                      filtering)
            self._index[key] = -1 if texture is None else len(self.textures)
            if texture is not None:
                self.textures.append(texture)
        return self._index[key]


def image_missing(image):
    """The path a file image should load from, when that file is gone; else None."""
    if image.source != 'FILE' or image.packed_file is not None:
        return None
    path = bpy.path.abspath(image.filepath, library=image.library)
    return None if os.path.isfile(path) else (path or "no file path")


# Cycles' colour for an image it cannot find (TEX_IMAGE_MISSING_R/G/B/A).
MISSING_IMAGE_RGBA = (1.0, 0.0, 1.0, 1.0)


def image_pixels(image, warn):
    """(H, W, 4) float32 of image.pixels (row 0 at the bottom): one magenta texel for a
    missing file, as Cycles shows it; None (warned) for an image that cannot be read."""
    missing = image_missing(image)
    if missing is not None:
        warn(f"image '{image.name}' is missing ({missing}); rendering it magenta, as Cycles "
             "does")
        return np.array(MISSING_IMAGE_RGBA, dtype=np.float32).reshape(1, 1, 4)
    if image.source == 'TILED' and len(image.tiles) > 1:
        first = image.tiles[0].number
        warn(f"image '{image.name}' is a UDIM image of {len(image.tiles)} tiles; only tile "
             f"{first} is used, for every UV")
    width, height = image.size
    channels = image.channels
    if width * height * channels == 0:
        warn(f"image '{image.name}' could not be read; using the input's own colour")
        return None
    flat = np.empty(width * height * channels, dtype=np.float32)
    image.pixels.foreach_get(flat)
    flat = flat.reshape(height, width, channels)
    if channels == 4:
        return flat
    rgba = np.ones((height, width, 4), dtype=np.float32)
    if channels >= 3:
        rgba[..., :3] = flat[..., :3]
    else:
        rgba[..., :3] = flat[..., :1]  # grey (with alpha for two channels)
        if channels == 2:
            rgba[..., 3] = flat[..., 1]
    return rgba


def image_texture(image, wrap, warn):
    """TextureData for one image, or None (warned)."""
    pixels = image_pixels(image, warn)
    if pixels is None:
        return None
    if image_missing(image) is not None:
        return TextureData(pixels, wrap, image.name)  # magenta, linear
    space = image.colorspace_settings.name
    if not image.is_float and space == "sRGB":
        encoded = np.rint(np.clip(pixels, 0.0, 1.0) * 255.0).astype(np.uint8)
        return TextureData(encoded, wrap, image.name)
    if not image.is_float and space not in LINEAR_COLOR_SPACES:
        warn(f"image '{image.name}': colour space {space} is rendered as linear")
    pixels = np.nan_to_num(pixels, nan=0.0, posinf=0.0, neginf=0.0)
    return TextureData(np.ascontiguousarray(pixels, dtype=np.float32), wrap, image.name)


def image_mean_color(image, fallback, warn):
    """The mean linear colour of an image (for inputs that take no texture), or fallback."""
    if image is None:
        warn("image texture node has no image; using the input's own colour")
        return fallback
    pixels = image_pixels(image, warn)
    if pixels is None:
        return fallback
    rgb = pixels[..., :3].reshape(-1, 3)
    if image_missing(image) is not None:
        return tuple(float(c) for c in rgb[0])
    if not image.is_float and image.colorspace_settings.name == "sRGB":
        rgb = srgb_to_linear(rgb)
    mean = tuple(float(c) for c in rgb.mean(axis=0))
    warn(f"image '{image.name}' drives an input that takes no texture; rendered as its "
         f"mean colour ({mean[0]:.3f}, {mean[1]:.3f}, {mean[2]:.3f})")
    return mean


def srgb_to_linear(values):
    """The sRGB transfer function inverted (IEC 61966-2-1)."""
    values = np.asarray(values, dtype=np.float32)
    return np.where(values <= 0.04045, values / 12.92, ((values + 0.055) / 1.055) ** 2.4)
