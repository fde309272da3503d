"""Scene input from numpy: used in place when it fits, and every bad array named."""
import numpy as np
import pytest

from conftest import quad


def triangle():
    p = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], dtype=np.float32)
    t = np.array([[0, 1, 2]], dtype=np.uint32)
    return p, t


def test_scene_uses_arrays_without_copy(glslppm):
    p, t = quad([0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0])
    scene = glslppm.Scene(p, t)
    assert scene.triangle_count == 2
    assert scene.shares_memory_with_input


@pytest.mark.parametrize("name,kwargs,message", [
    ("positions dtype", dict(positions=np.zeros((3, 3), np.float64)),
     "positions: expected dtype float32"),
    ("positions shape", dict(positions=np.zeros((3, 2), np.float32)),
     "positions: expected shape (N, 3)"),
    ("indices dtype", dict(indices=np.zeros((1, 3), np.int64)), "indices: expected dtype uint32"),
    ("indices shape", dict(indices=np.zeros((3,), np.uint32)), "indices: expected shape (N, 3)"),
    ("normals shape", dict(normals=np.zeros((3, 4), np.float32)), "normals: expected shape (N, 3)"),
    ("uvs dtype", dict(uvs=np.zeros((3, 2), np.float64)), "uvs: expected dtype float32"),
    ("material_ids dtype", dict(material_ids=np.zeros((1,), np.int32)),
     "material_ids: expected dtype uint32"),
])
def test_wrong_dtype_or_shape_names_the_array(glslppm, name, kwargs, message):
    p, t = triangle()
    args = dict(positions=p, indices=t)
    args.update(kwargs)
    with pytest.raises(ValueError) as e:
        glslppm.Scene(**args)
    assert message in str(e.value), name


def test_index_out_of_range_names_the_first_bad_triangle(glslppm):
    p, t = triangle()
    t = np.array([[0, 1, 2], [0, 1, 2], [0, 1, 7], [0, 9, 2]], dtype=np.uint32)
    with pytest.raises(ValueError,
                       match=r"indices\[2\]: vertex index 7 is out of range \(3 vertices\)"):
        glslppm.Scene(p, t)


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_nan_or_inf_coordinates_name_the_vertex(glslppm, bad):
    p, t = triangle()
    p = np.concatenate([p, p]).astype(np.float32)
    p[4, 2] = bad
    with pytest.raises(ValueError, match=r"positions\[4\]: coordinate is NaN or Inf"):
        glslppm.Scene(p, t)


def test_nan_normals_and_uvs_are_named(glslppm):
    p, t = triangle()
    n = np.zeros((3, 3), np.float32)
    n[1, 0] = np.nan
    with pytest.raises(ValueError, match=r"normals\[1\]"):
        glslppm.Scene(p, t, normals=n)
    uv = np.zeros((3, 2), np.float32)
    uv[2, 1] = np.inf
    with pytest.raises(ValueError, match=r"uvs\[2\]"):
        glslppm.Scene(p, t, uvs=uv)


def test_row_count_mismatch_is_named(glslppm):
    p, t = triangle()
    with pytest.raises(ValueError, match="normals: has 2 rows but positions has 3"):
        glslppm.Scene(p, t, normals=np.zeros((2, 3), np.float32))
    with pytest.raises(ValueError, match="material_ids: has 2 entries"):
        glslppm.Scene(p, t, material_ids=np.zeros((2,), np.uint32))


def test_material_id_out_of_range(glslppm):
    p, t = triangle()
    with pytest.raises(ValueError,
                       match=r"material_ids\[0\]: material 3 does not exist \(1 materials\)"):
        glslppm.Scene(p, t, material_ids=np.array([3], np.uint32), materials=[glslppm.Material()])


def test_bad_settings_are_named(glslppm):
    with pytest.raises(ValueError, match="alpha"):
        glslppm.Settings(alpha=1.5)
    with pytest.raises(ValueError, match="hash: 'fast' is not a hash mode"):
        glslppm.Settings(hash="fast")
    with pytest.raises(ValueError, match="rng: 'mt' is not a generator"):
        glslppm.Settings(rng="mt")
    with pytest.raises(ValueError, match="width/height"):
        glslppm.Settings(width=0)


def test_built_in_scene_does_not_claim_to_share_numpy_memory(glslppm):
    """Scenes the module builds own their arrays: the property says so instead of reading
    their storage as numpy arrays (it used to crash)."""
    assert glslppm.cornell_box().shares_memory_with_input is False


@pytest.mark.parametrize("light,message", [
    (dict(power=-1.0), r"lights\[1\]\.power: -1 is negative"),
    (dict(power=float("inf")), r"lights\[1\]\.power: inf is not a finite number"),
    (dict(color=(1.0, float("nan"), 1.0)), r"lights\[1\]\.color: has a NaN"),
    (dict(power=3e38, color=(10.0, 1.0, 1.0)), r"lights\[1\]\.power: times its colour overflows"),
    (dict(kind="spot", spot_size=4.0), r"lights\[1\]\.spot_size: 4 is outside \(0, pi\]"),
    (dict(kind="sun", direction=(0.0, 0.0, 0.0)), r"lights\[1\]\.direction: is zero"),
    (dict(kind="area", size_x=0.0), r"lights\[1\]\.size_x: 0 is not a positive number"),
    (dict(radius=-0.5), r"lights\[1\]\.radius: -0.5 is negative"),
])
def test_bad_light_values_are_rejected_by_name(glslppm, light, message):
    """One policy for every light field, whichever way the scene was made: a bad value is
    an error naming it, never dropped."""
    g = glslppm
    lights = [g.Light("point", power=10.0, position=(0, 1, 0)), g.Light(**light)]
    scene = g.Scene(*triangle(), lights=lights)
    with pytest.raises(ValueError, match=message):
        g.Renderer(scene, g.Settings(width=8, height=8, photons_per_pass=64))


@pytest.mark.parametrize("camera,message", [
    (dict(fov_x=3.5), r"camera\.fov_x: 3\.5 is outside \(0, pi\)"),
    (dict(pixel_aspect=0.0), r"camera\.pixel_aspect: 0 is not a positive number"),
    (dict(projection="orthographic", ortho_scale=-1.0), r"camera\.ortho_scale"),
    (dict(aperture_radius=0.1, focus_distance=0.0), r"camera\.focus_distance"),
])
def test_bad_camera_values_are_rejected_by_name(glslppm, camera, message):
    g = glslppm
    scene = g.Scene(*triangle(), lights=[g.Light("point", position=(0, 1, 0))],
                    camera=g.Camera(np.eye(4, dtype=np.float32), **camera))
    with pytest.raises(ValueError, match=message):
        g.Renderer(scene, g.Settings(width=8, height=8, photons_per_pass=64))


def test_bad_material_and_world_values_are_rejected_by_name(glslppm):
    g = glslppm
    light = [g.Light("point", position=(0, 1, 0))]
    cases = [
        (dict(materials=[g.Material(emission=(-1, 0, 0))], lights=light),
         r"materials\[0\]\.emission: has a negative component"),
        (dict(materials=[g.Material("dielectric", ior=0.0)], lights=light),
         r"materials\[0\]\.ior: 0 is not a positive number"),
        (dict(materials=[g.Material()], environment=(float("inf"), 0, 0)),
         r"environment: has a NaN or infinite component"),
    ]
    for kwargs, message in cases:
        with pytest.raises(ValueError, match=message):
            g.Renderer(g.Scene(*triangle(), **kwargs),
                       g.Settings(width=8, height=8, photons_per_pass=64))
