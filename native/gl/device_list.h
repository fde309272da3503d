// Which EGL devices a render uses, from the command line's --device: "2", "0,1" or "all".
#pragma once

#include <string>
#include <vector>

namespace glslppm::gl {

// "all": every hardware device, or the first software one (llvmpipe) where there is none.
// A list names device indices (repeats allowed: two workers on one device). Throws
// std::invalid_argument naming the bad item.
std::vector<int> parse_device_list(const std::string& text);

}  // namespace glslppm::gl
