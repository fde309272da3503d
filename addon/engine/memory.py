"""Whether a render fits, decided before anything is allocated: the GPU buffers the
module will make (its memory_estimate: native/render/memory_estimate.h, the sizes the
renderer allocates), the host copies of the film and Blender's own result, against the
device's limits and the host's available memory. A render that does not fit is refused at
once with the numbers, instead of failing minutes later with a black full-size result.
"""

import os

# Host bytes per pixel: Blender's float RGBA result and the copy it saves or shows (2 x 16),
# the module's film read-back and the add-on's copy of it (2 x 16), and the initial
# statistics the module uploads (2 vec4).
HOST_PER_PIXEL = 2 * 16 + 2 * 16 + 2 * 16
HOST_PER_PHOTON = 3 * 16

GIB = float(1 << 30)


def estimate(native, settings, views=1, limits=None):
    """Bytes: {"gpu", "largest_buffer", "host"} for a render of the module's Settings: the
    GPU's from the module (before export: light tracing's splats counted wherever the
    settings allow it), the host's from Blender's and the add-on's copies. limits: the
    module's device_limits() (or None where the device could not be asked)."""
    largest = limits.get("max_storage_buffer_bytes", 0) if limits else 0
    gpu = native.memory_estimate(settings, largest_block=largest)
    pixels = settings.width * settings.height
    host = views * pixels * HOST_PER_PIXEL + settings.photons_per_pass * HOST_PER_PHOTON
    # The per-pixel buffers are not among the largest: a frame whose visible points exceed
    # one buffer renders as image tiles (the module's plan_tiles).
    return {"gpu": gpu["gpu"], "largest_buffer": gpu["largest_photon_buffer"], "host": host}


def host_available():
    """Bytes of host memory available now (MemAvailable), or None where unknown."""
    try:
        with open("/proc/meminfo") as meminfo:
            for line in meminfo:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except OSError:
        pass
    try:
        return os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (OSError, ValueError):
        return None


def refusal(needs, limits, available):
    """A message saying why the render cannot fit, or None when it may.
    limits is the module's device_limits() (or None), available host bytes (or None)."""
    problems = []
    if limits:
        largest = limits.get("max_storage_buffer_bytes", 0)
        if largest and needs["largest_buffer"] > largest:
            problems.append(f"its largest GPU buffer needs {needs['largest_buffer'] / GIB:.2f} "
                            f"GiB, more than the {largest / GIB:.2f} GiB this GPU allows in one "
                            "buffer")
        # Only a hardware GPU's own figure counts (some software renderers answer the
        # NVX query with a meaningless number; their buffers are host memory, below).
        memory = 0 if limits.get("software") else limits.get("memory_bytes", 0)
        if memory > 0 and needs["gpu"] > memory:
            problems.append(f"it needs {needs['gpu'] / GIB:.2f} GiB of GPU memory, more than "
                            f"the GPU's {memory / GIB:.2f} GiB")
    host = needs["host"]
    if limits and limits.get("software"):
        host += needs["gpu"]  # a software renderer's buffers live in host memory
    if available is not None and host > available:
        problems.append(f"it needs {host / GIB:.2f} GiB of host memory, more than the "
                        f"{available / GIB:.2f} GiB available")
    if not problems:
        return None
    return ("the render does not fit: " + "; ".join(problems) +
            ". Lower the resolution (or use a render region) or the photons per pass")
