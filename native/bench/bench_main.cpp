// glslppm-bench: dispatches to one benchmark by name (argv[1]).
#include <cstdio>
#include <cstring>

int bench_bvh(int argc, char** argv);
int bench_rng(int argc, char** argv);
int bench_passes(int argc, char** argv);

int main(int argc, char** argv) {
    if (argc >= 2 && std::strcmp(argv[1], "bvh") == 0) return bench_bvh(argc - 2, argv + 2);
    if (argc >= 2 && std::strcmp(argv[1], "rng") == 0) return bench_rng(argc - 2, argv + 2);
    if (argc >= 2 && std::strcmp(argv[1], "passes") == 0) return bench_passes(argc - 2, argv + 2);
    std::fprintf(stderr, "usage: glslppm-bench bvh --triangles N [--leaf-size K] "
                         "[--order-count 6|1] [--json]\n"
                         "       glslppm-bench rng --generator paper|pcg [--json] ...\n"
                         "       glslppm-bench passes [--width W --height H --photons N --passes K "
                         "--hash M --rng G --device D] [--json]\n");
    return 2;
}
