"""Finds and imports the compiled module ``_glslppm``.

Packaged, the module sits beside this file (with ``shaders/`` beside it). The extension
zip for official Blender builds holds one module per CPython it supports, each under
Python's own name for that ABI (``_glslppm.cpython-311-x86_64-linux-gnu.so``, ...;
the shared libraries each links in ``libs/cp311/`` ...), so the import below finds the
one matching the running Python, and a Python the zip has none for is named in the
message. For development and tests, ``GLSLPPM_MODULE_DIR`` names a build directory to import
it from instead. Import failures become a message for the render report, never
an exception at add-on registration: the add-on must register (and show its
settings) even where the module cannot load.
"""

import importlib
import os
import re
import sys

_cache = {}


def load():
    """Returns (module, None) or (None, message saying what to do)."""
    if "module" in _cache:
        return _cache["module"], None
    module_dir = os.environ.get("GLSLPPM_MODULE_DIR", "")
    errors = []
    if module_dir:
        try:
            module = _import_from(module_dir)
            _cache["module"] = module
            return module, None
        except ImportError as error:
            errors.append(f"GLSLPPM_MODULE_DIR={module_dir}: {error}")
    try:
        module = importlib.import_module("._glslppm", __package__)
        _cache["module"] = module
        return module, None
    except ImportError as error:
        errors.append(f"packaged module: {error}")
    python = "%d.%d" % sys.version_info[:2]
    bundled = bundled_pythons()
    held = (f"this add-on holds the module for Python {', '.join(bundled)}"
            if bundled else "this add-on holds no module")
    return None, (
        "the GLSLPPM native module _glslppm could not be loaded for Python "
        f"{python} ({'; '.join(errors)}); {held}: install the add-on built for this "
        "Blender, or set GLSLPPM_MODULE_DIR to a build directory")


def bundled_pythons(folder=None):
    """The Python versions ("3.11", ...) whose module lies in the package folder."""
    folder = folder or os.path.dirname(os.path.abspath(__file__))
    versions = []
    for name in sorted(os.listdir(folder)):
        match = re.fullmatch(r"_glslppm\.cpython-(\d)(\d+)-.*\.so", name)
        if match:
            versions.append(f"{match.group(1)}.{match.group(2)}")
    return sorted(versions, key=lambda v: tuple(map(int, v.split("."))))


def _import_from(module_dir):
    if not os.path.isdir(module_dir):
        raise ImportError("not a directory")
    if module_dir not in sys.path:
        sys.path.insert(0, module_dir)
    return importlib.import_module("_glslppm")
