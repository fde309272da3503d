// Includes Debian's tiny_gltf.h with the options every translation unit must agree on:
// images are decoded by image/image_file.h (external ones loaded by the glTF loader itself,
// with its own messages), and nothing is ever written.
#pragma once

#define TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_STB_IMAGE_WRITE
#define TINYGLTF_NO_EXTERNAL_IMAGE
#include <tiny_gltf.h>
