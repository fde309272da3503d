"""Ray visibility per material (Blender's Object > Visibility > Camera and Shadow): a
square occluder 1 above a floor lit by a point light 2 above it. Each case is compared
with the same scene without the occluder (the floor's radiance under the light), or with
its shadow, within noise bounds measured at these settings (the floor's centre varies by
about 1.5% between seeds at 128 passes; a photon through a shadowless surface is stored
there and reaches the floor one pass later, a deficit of about 1/passes)."""
import math

import numpy as np
import pytest

from conftest import look_at, merge, native, quad
from scene_builders import render

FLOOR = quad((-2, 0, -2), (-2, 0, 2), (2, 0, 2), (2, 0, -2))
OCCLUDER = quad((-0.4, 1, -0.4), (-0.4, 1, 0.4), (0.4, 1, 0.4), (0.4, 1, -0.4))
FROM_ABOVE = look_at((0, 4, 0), (0, 0, 0), up=(0, 0, -1))
# Low and to the side: sees the floor under the occluder, not the occluder.
FROM_SIDE = look_at((3, 0.5, 0), (0, 0, 0))


def scene(camera, occluder=None):
    parts = [(*FLOOR, 0)]
    materials = [native.Material("diffuse", color=(0.5, 0.5, 0.5))]
    if occluder is not None:
        parts.append((*OCCLUDER, 1))
        materials.append(native.Material("diffuse", color=(0.5, 0.5, 0.5), **occluder))
    p, t, ids = merge(*parts)
    return native.Scene(p, t, material_ids=ids, materials=materials,
                        lights=[native.Light("point", power=200.0, position=(0, 2, 0))],
                        camera=native.Camera(camera, fov_x=math.radians(12)))


def centre(camera, occluder=None):
    """Mean radiance of the middle 8x8 pixels of a 32x32 image."""
    film, _, _ = render(native, scene(camera, occluder), 128, width=32, height=32,
                        photons_per_pass=1 << 15)
    assert np.isfinite(film).all()
    return float(film[12:20, 12:20].mean())


@pytest.fixture(scope="module")
def lit_floor():
    views = (("above", FROM_ABOVE), ("side", FROM_SIDE))
    return {view: centre(camera) for view, camera in views}


def test_default_occluder_is_seen_and_casts_its_shadow(lit_floor):
    """Seen from above, the occluder's top (1 from the light, the floor 2) is about 4x the
    floor's radiance; from the side, the floor under it is in shadow (< 5%)."""
    top = centre(FROM_ABOVE, {})
    shadow = centre(FROM_SIDE, {})
    print(f"top / floor {top / lit_floor['above']:.3f} (4 expected), "
          f"shadow / floor {shadow / lit_floor['side']:.4f}")
    assert 3.6 < top / lit_floor["above"] < 4.4
    assert shadow < 0.05 * lit_floor["side"]


def test_hidden_from_camera_shows_what_is_behind_it(lit_floor):
    """Not visible to the camera but casting its shadow: from above, the floor in its
    shadow (< 5% of the lit floor) instead of its bright top."""
    seen = centre(FROM_ABOVE, {"visible_to_camera": False})
    print(f"hidden occluder: centre / lit floor {seen / lit_floor['above']:.4f}")
    assert seen < 0.05 * lit_floor["above"]


def test_casting_no_shadow_leaves_the_floor_lit(lit_floor):
    """Casting no shadow: the floor under it is as lit as without it (within 4%); hidden
    from the camera too, the view from above is the bare lit floor (within 4%)."""
    side = centre(FROM_SIDE, {"casts_shadow": False})
    above = centre(FROM_ABOVE, {"casts_shadow": False, "visible_to_camera": False})
    ratios = side / lit_floor["side"], above / lit_floor["above"]
    print(f"shadowless occluder: floor under it / lit floor {ratios[0]:.4f}; "
          f"hidden and shadowless, from above {ratios[1]:.4f} (1 within 0.04)")
    assert abs(ratios[0] - 1.0) < 0.04
    assert abs(ratios[1] - 1.0) < 0.04


def test_shadowless_occluder_is_still_lit(lit_floor):
    """Casting no shadow changes nothing about its own light: its top is still about 4x
    the floor's radiance seen from above."""
    top = centre(FROM_ABOVE, {"casts_shadow": False})
    print(f"shadowless occluder top / floor {top / lit_floor['above']:.3f}")
    assert 3.6 < top / lit_floor["above"] < 4.4
