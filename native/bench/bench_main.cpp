// glslppm-bench: dispatches to one benchmark by name (argv[1]).
#include <cstdio>
#include <cstring>
#include <exception>

int bench_bvh(int argc, char** argv);
int bench_rng(int argc, char** argv);
int bench_passes(int argc, char** argv);
int bench_rays(int argc, char** argv);
int bench_converge(int argc, char** argv);
int bench_specialization(int argc, char** argv);
int bench_long_run(int argc, char** argv);
int bench_restart(int argc, char** argv);
int bench_refit(int argc, char** argv);

namespace {

void usage(std::FILE* out);

// The subcommand's own exit status; a bad option or any other error is one line naming it
// and exit status 2 (never an abort).
int dispatch(int argc, char** argv) {
    if (argc >= 2 && (std::strcmp(argv[1], "--help") == 0 || std::strcmp(argv[1], "-h") == 0)) {
        usage(stdout);
        return 0;
    }
    if (argc >= 2 && std::strcmp(argv[1], "bvh") == 0) return bench_bvh(argc - 2, argv + 2);
    if (argc >= 2 && std::strcmp(argv[1], "rng") == 0) return bench_rng(argc - 2, argv + 2);
    if (argc >= 2 && std::strcmp(argv[1], "passes") == 0) return bench_passes(argc - 2, argv + 2);
    if (argc >= 2 && std::strcmp(argv[1], "rays") == 0) return bench_rays(argc - 2, argv + 2);
    if (argc >= 2 && std::strcmp(argv[1], "converge") == 0) return bench_converge(argc - 2, argv + 2);
    if (argc >= 2 && std::strcmp(argv[1], "specialize") == 0)
        return bench_specialization(argc - 2, argv + 2);
    if (argc >= 2 && std::strcmp(argv[1], "longrun") == 0) return bench_long_run(argc - 2, argv + 2);
    if (argc >= 2 && std::strcmp(argv[1], "restart") == 0) return bench_restart(argc - 2, argv + 2);
    if (argc >= 2 && std::strcmp(argv[1], "refit") == 0) return bench_refit(argc - 2, argv + 2);
    usage(stderr);
    return 2;
}

void usage(std::FILE* out) {
    std::fprintf(out, "usage: glslppm-bench bvh --triangles N [--leaf-size K] "
                         "[--order-count 6|1] [--json]\n"
                         "       glslppm-bench rng --generator paper|pcg [--json] ...\n"
                         "       glslppm-bench passes [--width W --height H --photons N --passes K "
                         "--hash M --rng G --direct sampled|photons|sampled-no-mis --glossy-threshold R "
                         "--emitter-mis-fraction Q --device D --scene S --light-tracing on|off "
                         "--estimator sppm|pppm|vcm --vcm-techniques pt|lt|pt+lt "
                         "--render-passes all|depth,...] [--light-groups N] [--json]\n"
                         "       glslppm-bench rays [--rays N --batches B --scenes a,b --leaf 1,2,4,8 "
                         "--layout mtbvh,tbvh] [--json]\n"
                         "       glslppm-bench converge [--scene S --passes K --alpha a,b "
                         "--photons n,m --radius-scale x,y --hash h --rng g --direct sampled,photons] "
                         "[--json]\n"
                         "       glslppm-bench specialize [--scene S --width W --height H "
                         "--photons N --passes K --rounds R --each] [--json]\n"
                         "       glslppm-bench longrun [--passes K --photons N --width W]\n"
                         "       glslppm-bench restart [--scene S --width W --height H --photons N "
                         "--moves K] [--json]\n"
                         "       glslppm-bench refit [--triangles N --amplitudes a,b --rays R] "
                         "[--json]\n"
                         "  scenes: cornell, cornell-diffuse, cornell-glossy, caustic, million[:N] (e.g. million:100k), "
                         "furnace (converge: against its exact radiance), or a .gltf/.glb/.obj "
                         "file; any of them +motion (instances and camera move: motion blur),\n"
                         "    instances:NxM +deform (the meshes' vertices ripple: deformation blur)\n");
}

}  // namespace

int main(int argc, char** argv) {
    try {
        return dispatch(argc, argv);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "glslppm-bench %s: %s\n", argc >= 2 ? argv[1] : "", e.what());
        return 2;
    }
}
