// The implementations of the single-header parsers from Debian's packages (tinygltf,
// tinyobjloader, stb_image), compiled here rather than linked from their shared libraries so
// that sanitizer and fuzzing builds instrument the parsers as well as our loaders.
// Their own warnings are not ours to fix: this file is compiled with -w.
#define TINYGLTF_IMPLEMENTATION
#include "loaders/tinygltf_config.h"

#define TINYOBJLOADER_IMPLEMENTATION
#include <tiny_obj_loader.h>

#define STB_IMAGE_IMPLEMENTATION
#include <stb/stb_image.h>
