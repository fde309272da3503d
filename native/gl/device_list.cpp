#include "gl/device_list.h"

#include <cstdlib>
#include <sstream>
#include <stdexcept>

#include "gl/egl_context.h"

namespace glslppm::gl {

std::vector<int> parse_device_list(const std::string& text) {
    std::vector<int> devices;
    if (text == "all") {
        const std::vector<DeviceInfo> listed = list_devices();
        for (const DeviceInfo& d : listed)
            if (!d.software) devices.push_back(d.index);
        for (const DeviceInfo& d : listed)
            if (devices.empty() && d.software) devices.push_back(d.index);
        if (devices.empty())
            throw std::invalid_argument("device: 'all' found no EGL device (install libegl-mesa0 "
                                        "for llvmpipe, or a GPU driver)");
        return devices;
    }
    std::stringstream in(text);
    std::string item;
    while (std::getline(in, item, ',')) {
        char* end = nullptr;
        const long index = std::strtol(item.c_str(), &end, 10);
        if (item.empty() || *end || index < 0 || index > 1024)
            throw std::invalid_argument("device: '" + item + "' in '" + text +
                                        "' is not a device index (or use 'all')");
        devices.push_back(static_cast<int>(index));
    }
    if (devices.empty()) throw std::invalid_argument("device: '" + text + "' names no device");
    return devices;
}

}  // namespace glslppm::gl
