// glslppm-merge: merges PPPM renders of one frame made on several machines (disjoint pass
// sets of the same scene, seed and settings) into the image of one render of all the passes.
#include <cstdio>
#include <exception>
#include <map>
#include <string>
#include <vector>

#include "render/farm_merge.h"

using namespace glslppm;

namespace {

const char* kUsage =
    "usage: glslppm-merge A.exr B.exr ... -o OUT.exr\n"
    "  Merges EXR files written by glslppm (glslppm-render --estimator pppm, or the Blender\n"
    "  add-on with the PPPM estimator) that rendered disjoint pass sets of one frame: every\n"
    "  layer (Combined, and the render passes of --passes-out or a multi-layer EXR) weighted\n"
    "  by each file's passes, written under the same names. Refuses files whose scene hash,\n"
    "  seed, settings, size or render passes differ, or whose pass ranges overlap, naming\n"
    "  the file and the field.\n";

}  // namespace

int main(int argc, char** argv) {
    std::vector<std::string> paths;
    std::string out;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "-o" || a == "--out") {
            if (i + 1 >= argc) {
                std::fprintf(stderr, "glslppm-merge: %s needs a file\n", a.c_str());
                return 2;
            }
            out = argv[++i];
        } else if (a == "-h" || a == "--help") {
            std::fputs(kUsage, stdout);
            return 0;
        } else {
            paths.push_back(a);
        }
    }
    if (paths.empty() || out.empty()) {
        std::fputs(kUsage, stderr);
        return 2;
    }
    try {
        std::map<std::string, std::string> attributes = merge_farm_files(paths, out);
        std::printf("%s: %s passes (%s) from %zu files\n", out.c_str(),
                    attributes["glslppm.passes"].c_str(), attributes["glslppm.pass_ranges"].c_str(),
                    paths.size());
        return 0;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "glslppm-merge: %s\n", e.what());
        return 1;
    }
}
