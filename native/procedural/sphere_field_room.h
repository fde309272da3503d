// What the two sphere-field benchmark scenes share (million_scene.h: one mesh of many bumpy
// spheres; instances_scene.h: instances of one): the closed white room they stand in, lit by
// a ceiling area light, its materials and camera, and the bumpy sphere's tessellation. The
// room matches the Cornell box (x, z in [-1, 1], y in [0, 2]).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "scene/scene.h"

namespace glslppm {

// Materials: 0 the room, 1 the ceiling light, 2 the spheres.
std::vector<Material> sphere_field_materials();

// The floor, ceiling, back and side walls (material 0) and the light (material 1).
void append_sphere_field_room(OwnedMesh& mesh);

// Looking down at the field from above the box's open front, so that most of the spheres
// (and so most primary rays) are in view.
Camera sphere_field_camera();

// A uniform float in [0, 1) from two integers (a 32-bit integer hash, splitmix-style), so
// that the scenes do not depend on the standard library's distributions.
float hash01(std::uint32_t seed, std::uint32_t i);

// Rings of a latitude-longitude sphere (segments = 2 * rings) with about `budget` triangles:
// make_sphere gives 2 * rings * segments - 2 * segments = 4 r^2 - 4 r of them.
int sphere_rings_for(std::size_t budget);

// The bump of a point p of the unit sphere: 1 + 0.15 sin(7 theta + a) sin(5 phi + b), on its
// (theta, phi) recovered from p; the sphere is displaced radially by it.
float sphere_bump(const glm::vec3& p, float phase_a, float phase_b);

}  // namespace glslppm
