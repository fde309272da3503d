"""The device-speed measurement the add-on's presets size photons per pass from
(addon/device_speed.py: plain Python on the module, loaded here from its file)."""
import importlib.util
import math
import os

import pytest

SOURCE = os.path.join(os.path.dirname(__file__), "..", "..", "addon", "device_speed.py")
spec = importlib.util.spec_from_file_location("device_speed", SOURCE)
device_speed = importlib.util.module_from_spec(spec)
spec.loader.exec_module(device_speed)

# Two half-second measurements on a machine shared with other jobs: llvmpipe's rates moved
# by up to 25 % between back-to-back runs here; a factor of 2 still catches a split of the
# pass time that is wrong (eye and photon costs swapped, a stage counted twice).
AGREEMENT = 2.0


def test_measured_rates_are_finite_positive_and_repeatable(glslppm):
    """Two back-to-back measurements agree within AGREEMENT; another job taking the shared
    cores during one of them (a 4.9x drop was seen) is not the module's fault, so up to three
    pairs are measured and one must agree."""
    pairs = []
    for _ in range(3):
        first = device_speed.measure_device_speed(glslppm, seconds=0.5)
        second = device_speed.measure_device_speed(glslppm, seconds=0.5)
        for speed in (first, second):
            for name in ("photon_bounces_per_second", "eye_rays_per_second"):
                assert math.isfinite(speed[name]) and speed[name] > 0, (name, speed)
            assert speed["passes"] >= 2 and speed["seconds"] >= 0.5, speed
            assert speed["renderer"], speed
        ratios = {name: first[name] / second[name]
                  for name in ("photon_bounces_per_second", "eye_rays_per_second")}
        pairs.append(ratios)
        if all(1 / AGREEMENT < r < AGREEMENT for r in ratios.values()):
            return
    raise AssertionError(f"no pair of measurements agreed within {AGREEMENT}x: {pairs}")


def test_the_rates_predict_the_pass_time(glslppm):
    # The model the presets invert: a pass of W*H pixels and P photons takes
    # W*H / eye rate + P / photon rate. At the calibration's own size and photon count it
    # must give the measured pass time, since the two rates split exactly that time.
    speed = device_speed.measure_device_speed(glslppm, seconds=0.5)
    pixels = device_speed.CALIBRATION_SIZE ** 2
    predicted = device_speed.pass_seconds(speed, pixels, speed["photons_per_pass"])
    assert predicted == pytest.approx(speed["pass_seconds"], rel=1e-6)


def test_photons_for_pass_time_inverts_the_model():
    speed = {"photon_bounces_per_second": 1e6, "eye_rays_per_second": 1e6}
    # 0.0655 s of photons after 0.0655 s of eye paths at 1 M/s: 65,536 photons exactly.
    pixels = 65536
    assert device_speed.photons_for_pass_time(speed, pixels, 2 * 0.065536, 1, 1 << 30) == 65536
    # Rounded to the nearest power of two in log2, clamped to [lowest, highest].
    assert device_speed.photons_for_pass_time(speed, pixels, 0.065536 + 0.05, 1, 1 << 30) \
        == 65536  # 50,000 photons: log2 15.6 -> 2^16
    assert device_speed.photons_for_pass_time(speed, pixels, 0.01, 4096, 1 << 20) == 4096
    assert device_speed.photons_for_pass_time(speed, pixels, 100.0, 4096, 1 << 20) == 1 << 20
