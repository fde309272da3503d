"""A pure-Python stand-in for the native module with its API (see the module's
docstrings), for developing the add-on where ``_glslppm`` is not built. Its
film is a flat grey that brightens with passes; it checks arguments the way the
native module promises to (ValueError naming the array)."""

import time

import numpy as np


class GlslppmError(RuntimeError):
    pass


class _Record:
    def __init__(self, **kwargs):
        self.__dict__.update(kwargs)


def Material(kind="diffuse", color=(0.8, 0.8, 0.8), ior=1.5, emission=(0, 0, 0)):
    assert kind in ("diffuse", "conductor", "dielectric"), kind
    return _Record(kind=kind, color=color, ior=ior, emission=emission)


def Light(kind, color, power, position=(0, 0, 0), direction=(0, 0, -1), spot_size=0.0,
          spot_blend=0.0, radius=0.0, angle=0.0):
    assert kind in ("point", "spot", "sun"), kind
    return _Record(kind=kind, color=color, power=power, position=position,
                   direction=direction)


def Camera(to_world, fov_x, shift_x=0.0, shift_y=0.0, projection="perspective",
           ortho_scale=1.0, aperture_radius=0.0, focus_distance=1.0):
    assert np.asarray(to_world).shape == (4, 4)
    return _Record(to_world=to_world, fov_x=fov_x)


def Scene(positions, indices, normals=None, uvs=None, material_ids=None, materials=(),
          lights=(), camera=None, environment=(0, 0, 0)):
    for name, array, dtype, width in (("positions", positions, np.float32, 3),
                                      ("indices", indices, np.uint32, 3)):
        if array.dtype != dtype or array.ndim != 2 or array.shape[1] != width:
            raise ValueError(f"{name}: expected {dtype.__name__} (N, {width})")
    bad = np.flatnonzero(~np.isfinite(positions).all(axis=1))
    if len(bad):
        raise ValueError(f"positions: non-finite value at index {bad[0]}")
    return _Record(triangles=len(indices), materials=materials, lights=lights,
                   camera=camera, environment=environment)


def Settings(width, height, photons_per_pass=65536, alpha=0.7, initial_radius=0.0,
             max_depth=16, hash="stochastic", rng="paper", device=-1, seed=0):
    return _Record(width=width, height=height, photons_per_pass=photons_per_pass)


class Renderer:
    def __init__(self, scene, settings):
        self.scene, self.settings = scene, settings
        self.passes = 0
        self.seconds = 0.0

    def run(self, passes=1):
        began = time.perf_counter()
        time.sleep(0.002 * passes)
        self.passes += passes
        self.seconds += time.perf_counter() - began

    def film(self):
        film = np.empty((self.settings.height, self.settings.width, 4), dtype=np.float32)
        film[..., :3] = 0.5 * self.passes / (self.passes + 1)
        film[..., 3] = 1.0
        return film

    def stats(self):
        photons = self.passes * self.settings.photons_per_pass
        return {"passes": self.passes, "photons_emitted": photons, "seconds": self.seconds,
                "photons_per_second": photons / max(self.seconds, 1e-9),
                "rays_per_second": 0.0, "mean_radius": 0.01 / (1 + self.passes),
                "renderer": "fake", "variant": "fake", "triangles": self.scene.triangles,
                "degenerate_dropped": 0}

    def close(self):
        pass
