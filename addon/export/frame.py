"""The pixels Blender asks for: the frame's size (resolution times percentage), the
render region within it, and the pixels' shape.

Blender sizes the frame with integer arithmetic (``BKE_render_resolution``: x * percent
/ 100) and cuts the region from it with float borders truncated to whole pixels
(``render_init_from_main``), counting rows from the bottom; its RenderResult is the
region's size, which Blender then crops or pastes into the full frame. Cycles places
its border the same way, so matching these numbers matches Cycles' pixels.
"""

from dataclasses import dataclass

import numpy as np


@dataclass
class RenderFrame:
    full_width: int
    full_height: int
    x: int = 0               # the region's first column
    y: int = 0               # its first row, counted from the bottom as Blender does
    width: int = 0           # the image rendered: the region's size
    height: int = 0
    pixel_aspect: float = 1.0  # a pixel's height over its width (aspect y / x)

    @property
    def is_region(self):
        return (self.width, self.height) != (self.full_width, self.full_height)

    @property
    def region(self):
        """The module's Camera region: (column, row from the top, full width, full
        height), or None for the whole frame."""
        if not self.is_region:
            return None
        return (self.x, self.full_height - self.y - self.height, self.full_width,
                self.full_height)

    @property
    def film_size(self):
        """The frame's shape as the camera sees it: pixel counts times the pixels' shape
        (what Blender's sensor fit compares)."""
        return float(self.full_width), float(self.full_height) * self.pixel_aspect


class FrameError(ValueError):
    """The render settings describe no pixels (an empty region)."""


def render_frame(render):
    """RenderFrame for scene.render."""
    full_width = max(1, render.resolution_x * render.resolution_percentage // 100)
    full_height = max(1, render.resolution_y * render.resolution_percentage // 100)
    aspect_x, aspect_y = float(render.pixel_aspect_x), float(render.pixel_aspect_y)
    pixel_aspect = aspect_y / aspect_x if aspect_x > 0.0 and aspect_y > 0.0 else 1.0
    frame = RenderFrame(full_width, full_height, 0, 0, full_width, full_height,
                        pixel_aspect)
    if not render.use_border:
        return frame
    # In float32, as Blender multiplies them, so the truncation lands on its pixel.
    f32 = np.float32
    x0 = int(f32(render.border_min_x) * f32(full_width))
    x1 = int(f32(render.border_max_x) * f32(full_width))
    y0 = int(f32(render.border_min_y) * f32(full_height))
    y1 = int(f32(render.border_max_y) * f32(full_height))
    if x1 <= x0 or y1 <= y0:
        raise FrameError("the render region is empty: draw a larger region (Ctrl+B in the "
                         "camera view) or turn Output > Render Region off")
    frame.x, frame.y, frame.width, frame.height = x0, y0, x1 - x0, y1 - y0
    return frame
