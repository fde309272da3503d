"""SceneData and scene.glslppm settings -> the native module's Scene and Settings.
The one place that knows the module's constructor signatures."""

from dataclasses import asdict


def native_scene(native, data):
    materials = [native.Material(**asdict(material)) for material in data.materials]
    lights = [native.Light(**asdict(light)) for light in data.lights]
    camera = native.Camera(**asdict(data.camera))
    return native.Scene(
        positions=data.positions, indices=data.indices, normals=data.normals,
        uvs=data.uvs, material_ids=data.material_ids, materials=materials,
        lights=lights, camera=camera, environment=tuple(data.environment))


def native_settings(native, settings, width, height, seed_offset=0):
    """settings is scene.glslppm; seed_offset varies the noise per animation frame."""
    return native.Settings(
        width=width, height=height,
        photons_per_pass=settings.photons_per_pass,
        alpha=settings.alpha,
        initial_radius=settings.radius(),
        max_depth=settings.max_bounces,
        hash=settings.hash_mode.lower(),
        rng=settings.rng.lower(),
        device=settings.device,
        seed=(settings.seed + seed_offset) % (2**31))
