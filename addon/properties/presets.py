"""Render presets: named sets of ``scene.glslppm`` settings, in ONE table, applied by the
operator ``glslppm.apply_preset`` (Render Properties > Sampling > Preset).

Each preset's description says what it is for and cites the measurement that chose
its numbers (docs/performance/, issue 6). The numbers below are provisional until
the benchmark runs that choose them are in.
"""

import bpy
from bpy.props import EnumProperty

# key -> label, description, and the settings it writes (property name -> value).
# radius_scale multiplies the automatic initial radius (use_auto_radius stays on).
PRESETS = {
    "PREVIEW": {
        "label": "Preview",
        "description": "Fast look at the lighting: 32 passes of 65,536 photons, "
                       "stochastic hash (provisional; measurement pending in "
                       "docs/performance/)",
        "settings": {
            "passes": 32, "time_limit": 0.0, "photons_per_pass": 65536, "alpha": 0.7,
            "use_auto_radius": True, "radius_scale": 1.0, "hash_mode": 'STOCHASTIC',
        },
    },
    "FINAL": {
        "label": "Final",
        "description": "Converged diffuse and glossy lighting: 1,000 passes of 262,144 "
                       "photons, stochastic hash (provisional; measurement pending in "
                       "docs/performance/)",
        "settings": {
            "passes": 1000, "time_limit": 0.0, "photons_per_pass": 262144, "alpha": 0.7,
            "use_auto_radius": True, "radius_scale": 1.0, "hash_mode": 'STOCHASTIC',
        },
    },
    "CAUSTICS": {
        "label": "Caustics",
        "description": "Sharp caustics: 2,000 passes of 1,048,576 photons, exact hash, "
                       "half the automatic initial radius (provisional; measurement "
                       "pending in docs/performance/)",
        "settings": {
            "passes": 2000, "time_limit": 0.0, "photons_per_pass": 1048576, "alpha": 0.7,
            "use_auto_radius": True, "radius_scale": 0.5, "hash_mode": 'EXACT',
        },
    },
}


def apply_preset(settings, key):
    """Writes preset key's values into settings (scene.glslppm); KeyError if unknown."""
    for name, value in PRESETS[key]["settings"].items():
        setattr(settings, name, value)


class GLSLPPM_OT_apply_preset(bpy.types.Operator):
    """Set passes, photons per pass, alpha, radius and hash mode from a preset"""
    bl_idname = "glslppm.apply_preset"
    bl_label = "Apply GLSLPPM Preset"
    bl_options = {'REGISTER', 'UNDO'}

    __annotations__ = {
        "preset": EnumProperty(
            name="Preset",
            items=[(key, preset["label"], preset["description"])
                   for key, preset in PRESETS.items()]),
    }

    @classmethod
    def poll(cls, context):
        return context.scene is not None

    def execute(self, context):
        apply_preset(context.scene.glslppm, self.preset)
        self.report({'INFO'}, f"GLSLPPM: {PRESETS[self.preset]['label']} preset applied")
        return {'FINISHED'}


classes = (GLSLPPM_OT_apply_preset,)


def register():
    for cls in classes:
        bpy.utils.register_class(cls)


def unregister():
    for cls in reversed(classes):
        bpy.utils.unregister_class(cls)
