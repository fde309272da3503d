"""SceneData and scene.glslppm settings -> the native module's Scene and Settings.
The one place that knows the module's constructor signatures."""

from dataclasses import asdict

from ..compat import BUMP_SHADOWING
from .light_paths import bounce_limits


def native_material(native, material):
    fields = asdict(material)
    fields["vertex_color"] = material.vertex_color is not None  # the attribute's name is export's
    group = fields.pop("light_group")
    link_set, link_row = fields.pop("light_link_set"), fields.pop("light_link_row")
    result = native.Material(**fields)
    result.light_group = group
    result.light_link_set, result.light_link_row = link_set, link_row
    return result


def native_light(native, light):
    fields = asdict(light)
    group = fields.pop("light_group")
    link_set = fields.pop("light_link_set")
    result = native.Light(**fields)
    result.light_group = group
    result.light_link_set = link_set
    return result


def native_scene(native, data):
    materials = [native_material(native, material) for material in data.materials]
    lights = [native_light(native, light) for light in data.lights]
    camera = native.Camera(**asdict(data.camera))
    # Fields, not asdict(): asdict would deep-copy every texture's pixels.
    textures = [native.Texture(texture.pixels, wrap=texture.wrap, name=texture.name,
                               uv_map=texture.uv_map, position_map=texture.position_map,
                               interpolation=texture.interpolation)
                for texture in data.textures]
    scene = native.Scene(
        positions=data.positions, indices=data.indices, normals=data.normals,
        uvs=data.uvs, material_ids=data.material_ids, materials=materials,
        lights=lights, camera=camera, environment=tuple(data.environment),
        textures=textures, environment_texture=data.environment_texture,
        environment_to_world=data.environment_to_world,
        instance_meshes=data.instance_meshes or None, instances=data.instances,
        instance_mesh=data.instance_mesh, tangents=data.tangents, colors=data.colors)
    # Light groups (docs/light_groups.md): every group of the view layer gets its pass, as
    # in Cycles, whether an emitter uses it or not.
    scene.light_groups = list(data.light_groups)
    scene.world_light_group = data.world_light_group
    # Light and shadow linking (docs/light_linking.md; Blender 4.0+).
    scene.light_link_receives = list(data.light_link_receives)
    scene.shadow_link_blocks = list(data.shadow_link_blocks)
    if data.motion:
        scene.set_motion(**data.motion)
    return scene


def film_options(scene):
    """The module's transparent and transparent_glass: Blender's Film > Transparent, and
    Cycles' Transparent Glass beside it (off where the Cycles add-on is absent)."""
    transparent = bool(scene.render.film_transparent)
    cycles = getattr(scene, "cycles", None)
    glass = bool(getattr(cycles, "film_transparent_glass", False))
    return {"transparent": transparent, "transparent_glass": transparent and glass}


def vcm_techniques(settings):
    """The VCM Techniques setting, for the VCM estimator (the module refuses it otherwise)."""
    if settings.estimator != 'VCM':
        return {}
    technique = getattr(settings, "vcm_techniques", 'PT_LT_VM')
    return {"vcm_techniques": {'PT_LT': "pt+lt", 'PT': "pt", 'PT_LT_VM': "pt+lt+vm"}[technique]}


def native_settings(native, settings, width, height, seed_offset=0, film=None, device=None,
                    passes=()):
    """settings is scene.glslppm; seed_offset varies the noise per animation frame; film is
    film_options(); device (the preferences' choice, resolved by the engine: an index, or a
    list of them for one worker each) overrides settings.device; passes: the render passes
    beside Combined, by the module's names (engine/render_passes.py)."""
    devices = device if isinstance(device, (list, tuple)) else None
    if devices is not None:
        device = devices[0] if devices else -1
        devices = list(devices) if len(devices) > 1 else []
    return native.Settings(
        estimator=settings.estimator.lower(),
        **vcm_techniques(settings),
        first_pass=settings.first_pass,
        devices=devices or [],
        **(film or {}),
        width=width, height=height,
        photons_per_pass=settings.photons_per_pass,
        alpha=settings.alpha,
        initial_radius=settings.radius(),
        radius_scale=settings.radius_scale,
        **bounce_limits(settings),
        hash=settings.hash_mode.lower(),
        rng=settings.rng.lower(),
        direct_light=settings.direct_light.lower(),
        light_tracing=settings.light_tracing,
        photon_warm_up=getattr(settings, "photon_warm_up", True),
        glossy_threshold=settings.glossy_threshold,
        instancing=settings.instancing.lower().replace("_", "-"),
        device=settings.device if device is None else device,
        seed=(settings.seed + seed_offset) % (2**31),
        max_block_bytes=settings.max_block_bytes,
        bump_shadowing=BUMP_SHADOWING,
        passes=list(passes))
