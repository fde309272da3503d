// libFuzzer target: scene validation and the BVH from raw buffers.
//
// The bytes are read as a mesh (counts, positions, indices, normals, uvs, material ids; NaN
// and Inf bit patterns, out-of-range indices and mismatched lengths included) and a few
// rays. Two oracles, each an abort() when it fails:
//   1. validate_mesh throws exactly when an independent check finds a bad array, and its
//      message names the FIRST bad element of a bad array; otherwise kept + dropped
//      triangles partition the input.
//   2. For a valid mesh, the packed MTBVH and TBVH (build_packed_bvh) hold every kept
//      triangle once, and closest_hit / any_hit agree with brute force bit for bit (the
//      exactness contract of bvh/intersect.h).
//
// Input layout (FuzzedDataProvider; what runs out reads as zeros):
//   header: vertex count 0..48, triangle count 0..64, flags, leaf size 0..8, bins 1..40,
//           material count 1..4, scale index
//   coordinate: one byte b; 0x80 = 4 raw float bytes follow, else int8(b) * scale (a small
//           integer grid: shared vertices, shared edges, coplanar and degenerate triangles)
//   index: one byte b; b < 0xF8 = b mod vertex count, else out of range (V + small, or ~0u)
//   rays: up to 24, each a kind byte then coordinates (see read_ray)
#include <fuzzer/FuzzedDataProvider.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "bvh/packed_bvh.h"
#include "bvh/traverse_cpu.h"
#include "scene/mesh.h"

namespace {

using namespace glslppm;

// Scene scales from the design's extremes (1e-3..1e5 units, triangles 1e-7 of that) to
// magnitudes whose products overflow, and denormal-sized grids.
constexpr float kScales[8] = {1.0f, 1e-3f, 1e5f, 1e-7f, 0.5f, 1e-30f, 1e30f, 3e36f};

enum Flags : std::uint8_t {
    kNormals = 1,
    kUvs = 2,
    kMaterialIds = 4,
    kLengthMismatch = 8,  // normals/uvs/material ids one row short
    kParallel = 16,
};

struct Input {
    std::vector<glm::vec3> positions, normals;
    std::vector<glm::uvec3> triangles;
    std::vector<glm::vec2> uvs;
    std::vector<std::uint32_t> material_ids;
    std::uint32_t material_count = 1;
    float scale = 1.0f;  // the grid step of int8 coordinates
    BvhBuildOptions options;
    MeshView view() const { return MeshView{positions, triangles, normals, uvs, material_ids, {}}; }
};

// SCENE_FUZZ_VERBOSE=1: one line per input saying what it exercised (to check seeds).
bool verbose() {
    static const bool on = std::getenv("SCENE_FUZZ_VERBOSE") != nullptr;
    return on;
}

[[noreturn]] void finding(const std::string& what) {
    std::fprintf(stderr, "scene_fuzz finding: %s\n", what.c_str());
    std::abort();
}

float read_coordinate(FuzzedDataProvider& in, float scale) {
    const auto b = in.ConsumeIntegral<std::uint8_t>();
    if (b == 0x80) return std::bit_cast<float>(in.ConsumeIntegral<std::uint32_t>());
    return static_cast<float>(static_cast<std::int8_t>(b)) * scale;
}

glm::vec3 read_vec3(FuzzedDataProvider& in, float scale) {
    const float x = read_coordinate(in, scale);
    const float y = read_coordinate(in, scale);
    return {x, y, read_coordinate(in, scale)};
}

std::uint32_t read_index(FuzzedDataProvider& in, std::uint32_t vertex_count) {
    const auto b = in.ConsumeIntegral<std::uint8_t>();
    if (b < 0xF8) return vertex_count ? b % vertex_count : b;
    return b == 0xFF ? ~0u : vertex_count + (b - 0xF8);
}

Input read_mesh(FuzzedDataProvider& in) {
    Input m;
    const auto vertices = in.ConsumeIntegralInRange<std::uint32_t>(0, 48);
    const auto triangles = in.ConsumeIntegralInRange<std::uint32_t>(0, 64);
    const auto flags = in.ConsumeIntegral<std::uint8_t>();
    m.options.leaf_size = in.ConsumeIntegralInRange(0, 8);
    m.options.bins = in.ConsumeIntegralInRange(1, 40);
    m.options.parallel = flags & kParallel;
    m.material_count = in.ConsumeIntegralInRange<std::uint32_t>(1, 4);
    const float scale = m.scale = kScales[in.ConsumeIntegralInRange(0, 7)];
    const std::uint32_t short_by = (flags & kLengthMismatch) ? 1 : 0;

    for (std::uint32_t i = 0; i < vertices; ++i) m.positions.push_back(read_vec3(in, scale));
    for (std::uint32_t t = 0; t < triangles; ++t) {
        const std::uint32_t a = read_index(in, vertices), b = read_index(in, vertices);
        m.triangles.emplace_back(a, b, read_index(in, vertices));
    }
    if (flags & kNormals)
        for (std::uint32_t i = short_by; i < vertices; ++i)
            m.normals.push_back(read_vec3(in, 1.0f / 64.0f));
    if (flags & kUvs)
        for (std::uint32_t i = short_by; i < vertices; ++i) {
            const float u = read_coordinate(in, 1.0f / 64.0f);
            m.uvs.emplace_back(u, read_coordinate(in, 1.0f / 64.0f));
        }
    if (flags & kMaterialIds)
        for (std::uint32_t t = short_by; t < triangles; ++t) {
            const auto b = in.ConsumeIntegral<std::uint8_t>();
            m.material_ids.push_back(b < 0xF0 ? b % m.material_count : b);
        }
    return m;
}

bool finite3(const glm::vec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

// Oracle 1, written independently of validate_mesh: the first bad element of each array
// (-1: none), and whether an optional array's length disagrees with its reference.
struct Expected {
    long positions = -1, normals = -1, uvs = -1, indices = -1, material_ids = -1;
    bool length_mismatch = false;
    bool any() const {
        return length_mismatch || positions >= 0 || normals >= 0 || uvs >= 0 || indices >= 0 ||
               material_ids >= 0;
    }
};

template <class T, class Bad>
long first_bad(const std::vector<T>& v, Bad bad) {
    for (std::size_t i = 0; i < v.size(); ++i)
        if (bad(v[i])) return static_cast<long>(i);
    return -1;
}

Expected expected_errors(const Input& m) {
    Expected e;
    const std::size_t n = m.positions.size();
    e.length_mismatch = (!m.normals.empty() && m.normals.size() != n) ||
                        (!m.uvs.empty() && m.uvs.size() != n) ||
                        (!m.material_ids.empty() && m.material_ids.size() != m.triangles.size());
    e.positions = first_bad(m.positions, [](const glm::vec3& p) { return !finite3(p); });
    e.normals = first_bad(m.normals, [](const glm::vec3& p) { return !finite3(p); });
    e.uvs = first_bad(
        m.uvs, [](const glm::vec2& p) { return !std::isfinite(p.x) || !std::isfinite(p.y); });
    e.indices = first_bad(m.triangles,
                          [n](const glm::uvec3& t) { return t.x >= n || t.y >= n || t.z >= n; });
    if (m.material_ids.size() == m.triangles.size())
        e.material_ids =
            first_bad(m.material_ids, [&](std::uint32_t id) { return id >= m.material_count; });
    return e;
}

// The message must name a bad array and, for an element error, that array's first bad
// element: "<array>[<index>]: ..." or, for a length mismatch, "<array>: has ...".
void check_message(const Expected& e, const std::string& message) {
    const struct {
        const char* name;
        long first;
    } arrays[] = {{"positions", e.positions},
                  {"normals", e.normals},
                  {"uvs", e.uvs},
                  {"indices", e.indices},
                  {"material_ids", e.material_ids}};
    for (const auto& a : arrays) {
        const std::string name = a.name;
        if (message.rfind(name + ": has ", 0) == 0 && e.length_mismatch) return;
        if (a.first >= 0 && message.rfind(name + "[" + std::to_string(a.first) + "]: ", 0) == 0)
            return;
    }
    finding("validate_mesh message names no bad element: \"" + message + "\"");
}

void check_partition(const Input& m, const ValidMesh& valid) {
    if (valid.kept.size() + valid.stats.degenerate_dropped != m.triangles.size() ||
        valid.stats.input_triangles != m.triangles.size())
        finding("kept + dropped triangles != input triangles");
    if (!std::is_sorted(valid.kept.begin(), valid.kept.end()) ||
        std::adjacent_find(valid.kept.begin(), valid.kept.end()) != valid.kept.end())
        finding("kept triangle ids are not strictly ascending");
    for (const std::uint32_t id : valid.kept) {
        const glm::uvec3 t = m.triangles.at(id);
        if (is_degenerate(m.positions[t.x], m.positions[t.y], m.positions[t.z]))
            finding("degenerate triangle " + std::to_string(id) + " was kept");
    }
}

// Every kept triangle exactly once among the packed triangles (original id in v1.w).
void check_packed_triangles(const ValidMesh& valid, const PackedBvh& bvh) {
    if (bvh.triangle_count != valid.kept.size() || bvh.stats.triangles != valid.kept.size())
        finding("packed triangle count != kept triangle count");
    std::vector<std::uint32_t> ids;
    for (std::uint32_t i = 0; i < bvh.triangle_count; ++i)
        ids.push_back(std::bit_cast<std::uint32_t>(bvh.triangles[3 * i + 1].w));
    std::sort(ids.begin(), ids.end());
    if (ids != valid.kept) finding("packed triangles are not the kept triangles");
}

// A ray of one of four kinds (random, or aimed at a vertex, an edge midpoint, a centroid),
// with one or two direction components zeroed now and then (axis-parallel rays in the
// planes of axis-aligned faces), and tmin > 0 or a finite tmax now and then.
std::optional<Ray> read_ray(FuzzedDataProvider& in, const ValidMesh& valid, float scale) {
    const auto kind = in.ConsumeIntegral<std::uint8_t>();
    Ray ray;
    ray.origin = read_vec3(in, scale);
    const auto& view = valid.view;
    const std::uint32_t pick = in.ConsumeIntegral<std::uint8_t>();
    if ((kind & 3) == 0 || valid.kept.empty()) {
        ray.dir = read_vec3(in, scale);
    } else {
        const glm::uvec3 t = view.triangles[valid.kept[pick % valid.kept.size()]];
        const glm::vec3 a = view.positions[t.x], b = view.positions[t.y], c = view.positions[t.z];
        const glm::vec3 target = (kind & 3) == 1   ? a
                                 : (kind & 3) == 2 ? (a + b) * 0.5f
                                                   : (a + b + c) / 3.0f;
        ray.dir = target - ray.origin;
    }
    if (kind & 4) ray.dir[(kind >> 4) % 3] = 0.0f;
    if (kind & 8) ray.dir[((kind >> 4) + 1) % 3] = 0.0f;
    if (kind & 64) ray.tmin = std::fabs(read_coordinate(in, 1.0f / 128.0f));
    if (kind & 128) ray.tmax = ray.tmin + std::fabs(read_coordinate(in, 1.0f / 32.0f));
    // The renderer never traces a ray with a non-finite or zero direction.
    if (!finite3(ray.origin) || !finite3(ray.dir) || ray.dir == glm::vec3(0.0f) ||
        !std::isfinite(ray.tmin) || !(ray.tmax > ray.tmin))
        return std::nullopt;
    return ray;
}

std::string describe(const Ray& r, const Hit& a, const Hit& b) {
    char text[512];
    std::snprintf(text, sizeof text,
                  "origin (%a %a %a) dir (%a %a %a) tmin %a tmax %a: bvh tri %d t %a u %a v %a, "
                  "brute force tri %d t %a u %a v %a",
                  r.origin.x, r.origin.y, r.origin.z, r.dir.x, r.dir.y, r.dir.z, r.tmin, r.tmax,
                  a.triangle, a.t, a.u, a.v, b.triangle, b.t, b.u, b.v);
    return text;
}

bool same_hit(const Hit& a, const Hit& b) {
    if (a.triangle != b.triangle) return false;
    if (a.triangle < 0) return true;
    return std::bit_cast<std::uint32_t>(a.t) == std::bit_cast<std::uint32_t>(b.t) &&
           std::bit_cast<std::uint32_t>(a.u) == std::bit_cast<std::uint32_t>(b.u) &&
           std::bit_cast<std::uint32_t>(a.v) == std::bit_cast<std::uint32_t>(b.v);
}

// Returns how many rays hit something.
int check_rays(FuzzedDataProvider& in, const ValidMesh& valid, const PackedBvh& mtbvh,
               const PackedBvh& tbvh, float scale) {
    int hits = 0;
    for (int i = 0; i < 24 && in.remaining_bytes() > 0; ++i) {
        const std::optional<Ray> ray = read_ray(in, valid, scale);
        if (!ray) continue;
        const Hit reference = closest_hit_brute_force(valid, *ray);
        const bool any_reference = any_hit_brute_force(valid, *ray);
        hits += reference.triangle >= 0;
        if (any_reference != (reference.triangle >= 0))
            finding("any_hit_brute_force disagrees with closest_hit_brute_force: " +
                    describe(*ray, reference, reference));
        for (const PackedBvh* bvh : {&mtbvh, &tbvh}) {
            const Hit hit = closest_hit(*bvh, *ray);
            const char* name = bvh->order_count == 6 ? "MTBVH" : "TBVH";
            if (!same_hit(hit, reference))
                finding(std::string(name) +
                        " closest_hit != brute force: " + describe(*ray, hit, reference));
            if (any_hit(*bvh, *ray) != any_reference)
                finding(std::string(name) +
                        " any_hit != brute force: " + describe(*ray, hit, reference));
        }
    }
    return hits;
}

// Known defect, reported to the lead (kept input: tests/fuzz/scene/crash-bvh-bin-nan):
// build_sah_bvh's BinMapping casts NaN to int (UB) once centroid sums or differences
// overflow, i.e. for coordinates beyond FLT_MAX / 4. SCENE_FUZZ_SKIP_KNOWN=1 skips the BVH
// for such meshes so that a long run can look for other defects; the replay in `make test`
// does not set it, so the kept input fails there until the defect is fixed.
bool skip_known_defect(const Input& m) {
    static const bool skip = std::getenv("SCENE_FUZZ_SKIP_KNOWN") != nullptr;
    if (!skip) return false;
    const float bound = std::numeric_limits<float>::max() / 4.0f;
    return std::any_of(m.positions.begin(), m.positions.end(), [&](const glm::vec3& p) {
        return std::fabs(p.x) > bound || std::fabs(p.y) > bound || std::fabs(p.z) > bound;
    });
}

bool options_valid(const BvhBuildOptions& o) {
    return o.leaf_size >= 1 && o.bins >= 2 && o.bins <= 256;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    FuzzedDataProvider in(data, size);
    const Input mesh = read_mesh(in);
    const Expected expected = expected_errors(mesh);
    if (verbose()) {
        float largest = 0.0f;
        for (const glm::vec3& p : mesh.positions)
            largest = std::fmax(
                largest, std::fmax(std::fabs(p.x), std::fmax(std::fabs(p.y), std::fabs(p.z))));
        std::fprintf(stderr, "%zu vertices, %zu triangles, scale %g, largest |coordinate| %g\n",
                     mesh.positions.size(), mesh.triangles.size(), mesh.scale, largest);
    }
    std::optional<ValidMesh> valid;
    try {
        valid = validate_mesh(mesh.view(), mesh.material_count);
    } catch (const SceneError& e) {
        if (!expected.any()) finding(std::string("valid mesh rejected: ") + e.what());
        check_message(expected, e.what());
        if (verbose()) std::fprintf(stderr, "rejected: %s\n", e.what());
        return 0;
    }
    if (expected.any()) finding("invalid mesh accepted");
    check_partition(mesh, *valid);
    if (skip_known_defect(mesh)) return 0;

    if (!options_valid(mesh.options)) {
        try {
            build_packed_bvh(*valid, mesh.options, 6);
        } catch (const std::invalid_argument&) {
            return 0;
        }
        finding("bad BVH options accepted");
    }
    const PackedBvh mtbvh = build_packed_bvh(*valid, mesh.options, 6);
    const PackedBvh tbvh = build_packed_bvh(*valid, mesh.options, 1);
    check_packed_triangles(*valid, mtbvh);
    check_packed_triangles(*valid, tbvh);
    // Rays use the scene's own grid, so that they start on vertex coordinates exactly.
    const int hits = check_rays(in, *valid, mtbvh, tbvh, mesh.scale);
    if (verbose())
        std::fprintf(stderr, "valid: %zu kept, %zu dropped, %u nodes, %d ray hits\n",
                     valid->kept.size(), valid->stats.degenerate_dropped, mtbvh.node_count, hits);
    return 0;
}
