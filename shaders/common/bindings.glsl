// Where every buffer, the Frame block and the texture atlases are bound: the one list the
// GPU stages and the C++ share. native/render/gpu_layout.h includes this file as it is, so
// it holds nothing but #defines and comments (valid GLSL and valid C++ alike).
#ifndef GLSLPPM_BINDINGS_GLSL
#define GLSLPPM_BINDINGS_GLSL

// Shader storage blocks.
#define BINDING_BVH_NODES 0        // MTBVH boxes (common/mtbvh.glsl)
#define BINDING_BVH_LINKS 1        // MTBVH hit/miss links, six orders
#define BINDING_TRIANGLES 2        // packed triangles
#define BINDING_EMITTERS 3         // lights photons start from (common/emitters.glsl)
#define BINDING_MATERIALS 4        // GpuMaterial records (common/bsdf.glsl)
#define BINDING_COUNTERS 5         // pass counters (common/sppm_buffers.glsl)
#define BINDING_VISIBLE_POINTS 6   // one visible point per pixel
#define BINDING_PIXEL_STATS 7      // SPPM's tau, N and R per pixel
#define BINDING_DIRECT_LIGHT 8     // light seen directly, compensated sums
#define BINDING_PHOTON_PATHS 9     // photon paths in flight (path regeneration)
#define BINDING_PHOTONS 10         // photons stored this pass
#define BINDING_RNG_STATES 11      // generator state, pixels then photon threads
#define BINDING_FILM 12            // the resolved image
#define BINDING_HASH_CELLS 13      // spatial hash cells
#define BINDING_HASH_SORTED 14     // exact hash: photon indices sorted by cell
#define BINDING_NORMALS 15         // vertex normals per packed triangle
#define BINDING_UVS 16             // texture coordinates per packed triangle
#define BINDING_TEXTURE_INFO 17    // each image's place in its atlas
#define BINDING_ENVIRONMENT_CDF 18 // the environment map's sampling distribution
#define BINDING_RADIUS_STATS 19    // per-thread sums of the radii, for stats()
#define BINDING_INSTANCES 20       // two-level MTBVH instance records (common/mtbvh_instances.glsl)
#define BINDING_PASS_FILMS 21      // render passes beside Combined (common/pass_films.glsl)
#define BINDING_VERTEX_COLORS 22   // vertex colours per packed triangle (common/scene_buffers.glsl)
#define BINDING_LIGHT_SPLATS 23    // light tracing's splats and their sums (common/light_splats.glsl)
#define BINDING_DEFORM_POSITIONS 24 // deforming meshes' vertices at their motion steps (deform_mesh.comp)
#define BINDING_DEFORM_NORMALS 25   // and their vertex normals
#define BINDING_DEFORM_TRIANGLES 26 // their packed triangles' vertices
#define BINDING_DEFORM_REFIT 27     // their bottom trees' nodes by depth, deepest first

// Uniform block and texture units.
#define BINDING_FRAME 0            // uniform Frame (common/frame.glsl)
#define TEXTURE_UNIT_SRGB_ATLAS 0  // 8-bit sRGB images
#define TEXTURE_UNIT_FLOAT_ATLAS 1 // float images

#endif
