"""Render presets: named sets of ``scene.glslppm`` settings, in ONE table, applied by the
operator ``glslppm.apply_preset`` (Render Properties > Sampling > Preset).

Each preset's description cites the measurement that chose its numbers: the H200
convergence runs of 2026-11-21 (docs/performance.md, "NVIDIA H200", and
docs/performance/h200/converge/*.json: Cornell box and caustic scene at 512x512 against
100k- and 50k-pass references, RMSE at equal wall time).
"""

import bpy
from bpy.props import EnumProperty

# key -> label, description, and the settings it writes (property name -> value).
# radius_scale multiplies the automatic initial radius (use_auto_radius stays on).
PRESETS = {
    "PREVIEW": {
        "label": "Preview",
        "description": "Quick look at the lighting: 64 passes of 65,536 photons, stochastic "
                       "hash, twice the automatic radius (H200: 1,520 passes/s at 512x512; "
                       "2x radius cut the RMSE at 3.2 s from 0.0150 to 0.0117)",
        "settings": {
            "passes": 64, "time_limit": 0.0, "photons_per_pass": 65536, "alpha": 0.7,
            "use_auto_radius": True, "radius_scale": 2.0, "hash_mode": 'STOCHASTIC',
        },
    },
    "FINAL": {
        "label": "Final",
        "description": "Converged lighting: 4,096 passes of 262,144 photons, exact hash, twice "
                       "the automatic radius, alpha 0.7 (H200 Cornell box at equal time: "
                       "exact 0.0101 vs stochastic 0.0141 RMSE; 262,144 photons beat 65,536 "
                       "and 1M; alpha 0.7 keeps the -2/3 rate, measured -0.70)",
        "settings": {
            "passes": 4096, "time_limit": 0.0, "photons_per_pass": 262144, "alpha": 0.7,
            "use_auto_radius": True, "radius_scale": 2.0, "hash_mode": 'EXACT',
        },
    },
    "CAUSTICS": {
        "label": "Caustics",
        "description": "Sharp caustics: 8,192 passes of 262,144 photons, exact hash, half "
                       "the automatic radius, since a caustic's edge blurs by the radius (H200 "
                       "caustic scene at equal time: exact 0.0285 vs stochastic 0.0297 RMSE; "
                       "the half radius trades noise for sharpness: Cornell RMSE 0.0223 vs "
                       "0.0150 at 3.2 s)",
        "settings": {
            "passes": 8192, "time_limit": 0.0, "photons_per_pass": 262144, "alpha": 0.7,
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
