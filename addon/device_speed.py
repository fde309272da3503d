"""The render speed of an EGL device, measured, and the photons per pass it affords.

A pass costs the eye paths (eye trace and gather, per pixel, fixed whatever the photon
count) plus the photons (photon trace and hashing, per photon). measure_device_speed()
renders the built-in caustic scene for a fraction of a second with GL timer queries
(Settings(profile=True)) and splits the pass time that way:

    photon bounces/s = photons per pass x passes / (photon + hash stage seconds)
    eye rays/s       = pixels x passes / (the rest of the passes' wall time)

so that a pass of W x H pixels and P photons takes about W*H / eye_rate + P / photon_rate.
photons_for_pass_time() inverts that for a target pass time. Plain Python on the native
module, no bpy: the module tests call it as the add-on does.
"""

import math

CALIBRATION_SIZE = 128  # pixels on a side: llvmpipe's eye cost is about 25 ms a pass here
FIRST_PHOTONS = 4096
MAX_CALIBRATION_PHOTONS = 1 << 20
# A device whose photon stages take under this share of a pass is measured again with 8x the
# photons: on a fast GPU a small dispatch leaves it idle and would understate its rate.
MIN_PHOTON_SHARE = 0.25

# Measured speeds for this Blender session, by device index.
_speeds = {}


def measure_device_speed(native, device=-1, seconds=0.5):
    """Renders native.caustic_scene() at CALIBRATION_SIZE^2 on EGL device `device` (-1:
    automatic) for about `seconds` after one warm-up pass; returns a dict:
    photon_bounces_per_second, eye_rays_per_second, photons_per_pass (the count measured
    with), pass_seconds, passes, seconds, renderer (GL_RENDERER)."""
    scene = native.caustic_scene(sphere_rings=32)
    pixels = CALIBRATION_SIZE * CALIBRATION_SIZE
    photons = FIRST_PHOTONS
    while True:
        settings = native.Settings(width=CALIBRATION_SIZE, height=CALIBRATION_SIZE,
                                   photons_per_pass=photons, hash="exact", device=device,
                                   profile=True)
        renderer = native.Renderer(scene, settings)
        try:
            renderer.run(1)  # first-pass costs (buffer first touch, shader caches)
            before = renderer.stats()
            passes = 0
            while True:
                passes += renderer.run(1)
                after = renderer.stats()
                wall = after["seconds"] - before["seconds"]
                if passes >= 2 and wall >= seconds:
                    break
        finally:
            renderer.close()
        photon_seconds = (after["photon_seconds"] + after["hash_seconds"]
                          - before["photon_seconds"] - before["hash_seconds"])
        share = photon_seconds / wall
        if share >= MIN_PHOTON_SHARE or photons >= MAX_CALIBRATION_PHOTONS:
            break
        photons = min(photons * 8, MAX_CALIBRATION_PHOTONS)
    eye_seconds = max(wall - photon_seconds, 1e-9)
    return {
        "photon_bounces_per_second": photons * passes / max(photon_seconds, 1e-9),
        "eye_rays_per_second": pixels * passes / eye_seconds,
        "photons_per_pass": photons,
        "pass_seconds": wall / passes,
        "passes": passes,
        "seconds": wall,
        "renderer": after["renderer"],
    }


def device_speed(native, device=-1, seconds=0.5):
    """measure_device_speed() once per device for this session, then the cached result."""
    if device not in _speeds:
        _speeds[device] = measure_device_speed(native, device, seconds)
    return _speeds[device]


def cached_device_speed(device=-1):
    """The session's measurement for `device`, or None (drawing a panel must not measure)."""
    return _speeds.get(device)


def pass_seconds(speed, pixels, photons):
    """The time a pass of `pixels` eye paths and `photons` photons takes at `speed`."""
    return (pixels / speed["eye_rays_per_second"]
            + photons / speed["photon_bounces_per_second"])


def photons_for_pass_time(speed, pixels, target_seconds, lowest, highest):
    """Photons per pass so that a pass of `pixels` takes about target_seconds at `speed`:
    photon_rate x (target - eye cost), clamped to [lowest, highest] and rounded to the
    nearest power of two (in log2: a factor of at most sqrt(2) off the unrounded count)."""
    eye = pixels / speed["eye_rays_per_second"]
    wanted = speed["photon_bounces_per_second"] * (target_seconds - eye)
    wanted = min(max(wanted, lowest), highest)
    return int(min(max(2 ** round(math.log2(wanted)), lowest), highest))


def forget_device_speed(device=-1):
    """Drops the session's measurement for `device`, so the next device_speed() measures."""
    _speeds.pop(device, None)
