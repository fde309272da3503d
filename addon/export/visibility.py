"""An object's ray visibility (Object > Visibility): camera and shadow visibility become
the material flags the renderer honours; the rest (diffuse, glossy, transmission and
volume rays, holdout, shadow catcher) have no counterpart and are warned about once per
object, naming the setting."""

from dataclasses import dataclass

# (property, the name Blender's Visibility panel shows) for the rays that still see an
# object whatever its setting.
UNSUPPORTED_RAYS = (
    ("visible_diffuse", "Diffuse"),
    ("visible_glossy", "Glossy"),
    ("visible_transmission", "Transmission"),
    ("visible_volume_scatter", "Volume Scatter"),
)


@dataclass(frozen=True)
class Visibility:
    camera: bool = True
    shadow: bool = True


def object_visibility(obj, warn):
    """Visibility of obj; warn(message) for each setting it cannot honour."""
    off = [label for name, label in UNSUPPORTED_RAYS if not getattr(obj, name, True)]
    if off:
        warn(f"object '{obj.name}': ray visibility off for {', '.join(off)} is not "
             "supported; those rays still see it (Object > Visibility > Ray Visibility)")
    if getattr(obj, "is_holdout", False):
        warn(f"object '{obj.name}': Holdout is not supported; it renders as an ordinary "
             "object (Object > Visibility > Mask > Holdout)")
    if getattr(obj, "is_shadow_catcher", False):
        warn(f"object '{obj.name}': Shadow Catcher is not supported; it renders as an "
             "ordinary object (Object > Visibility > Mask > Shadow Catcher)")
    return Visibility(camera=bool(getattr(obj, "visible_camera", True)),
                      shadow=bool(getattr(obj, "visible_shadow", True)))
