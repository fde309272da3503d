// Shading normals for vertices that have none.
#pragma once

#include "scene/scene.h"

namespace glslppm {

// Where some vertices have normals and others have zero ones (a part of the file without
// normals), the zero ones become the area-weighted mean of their triangles' geometric
// normals, so that the renderer never normalizes a zero vector. Does nothing when the mesh
// has no normals at all (the renderer then uses geometric normals everywhere).
void fill_missing_normals(OwnedMesh& mesh);

}  // namespace glslppm
