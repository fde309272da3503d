"""Blender datablocks -> plain numpy/record data for the native module: one
converter per datablock kind (mesh, material, image, light, camera, world),
``scene.export_scene`` walks the evaluated depsgraph and calls them."""

from .scene import ExportError, export_scene, export_tables  # noqa: F401
from .scene_data import CameraData, LightData, MaterialData, SceneData  # noqa: F401
