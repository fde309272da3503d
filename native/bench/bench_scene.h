// The scenes the benchmarks run on, by name: `cornell` (the built-in Cornell box),
// `cornell-diffuse` (the same without its mirror and glass spheres: the Cycles comparison),
// `caustic` (glass sphere over a floor), `million[:N]` (a field of bumpy spheres of about N
// triangles, default 1M; `100k`, `4M` suffixes accepted), `furnace` (a closed box whose walls
// all emit Le = 1 and reflect a = 0.5, seen from its centre: the radiance is known exactly,
// see furnace_radiance), `instances:NxM` (N instances of one bumpy sphere of about M
// triangles in the same room: scenes/instances_scene.h; instances:1xM is the mesh once), or
// a scene file (.gltf, .glb, .obj; native/loaders/scene_file.h). Any of them with `+motion`
// (e.g. instances:10000x100k+motion): every instance and the camera move in a shutter of
// half a frame (motion blur, docs/motion_blur.md).
// `aspect` is the render's width / height.
#pragma once

#include <string>

#include "render/settings.h"
#include "scene/scene.h"

namespace glslppm {

// Throws std::invalid_argument naming the spec when it is none of the above.
Scene make_bench_scene(const std::string& spec, float aspect = 1.0f);

// The radiance every pixel of `furnace` converges to under a Total of max_bounces (Cycles'
// rule, docs/bounces.md: N + 1 scatters): each scatter adds a^k Le, so L = Le (1 - a^(N+2)) /
// (1 - a), which tends to the furnace's Le / (1 - a) = 2 (1.999992 at the default 16; 1.5 at 0,
// direct light only).
double furnace_radiance(int max_bounces);

// "1000", "100k", "4M" -> a count; throws std::invalid_argument otherwise.
std::size_t parse_count(const std::string& text);

// Strict numbers for the benchmarks' options: the whole text must be a finite number (an
// integer where one is asked for), else std::invalid_argument naming the option, never a
// silent 0. option_* read argv[i + 1] and advance i past it.
double parse_number(const std::string& option, const std::string& text);
long long parse_integer(const std::string& option, const std::string& text);
double option_number(const std::string& option, int argc, char** argv, int& i);
long long option_integer(const std::string& option, int argc, char** argv, int& i);

// Reads one option that every end-to-end benchmark shares (--width, --height, --photons,
// --hash, --rng, --direct, --device (N, N,M,... or all), --estimator, --scene, --instancing) at
// argv[i], advancing i past its value; false when
// argv[i] is none of them.
bool parse_render_option(int argc, char** argv, int& i, RenderSettings& settings,
                         std::string& scene_spec);

}  // namespace glslppm
