// Cancelling long CPU work (the BVH build, a renderer's set-up) from another thread: the
// caller owns a CancelFlag and sets it; the work polls it every few milliseconds of work and
// throws Cancelled, so a user's cancel takes effect in a fraction of a second whatever the
// scene's size.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <stdexcept>

namespace glslppm {

using CancelFlag = std::atomic<bool>;

struct Cancelled : std::runtime_error {
    Cancelled() : std::runtime_error("cancelled") {}
};

inline bool cancel_requested(const CancelFlag* flag) {
    return flag != nullptr && flag->load(std::memory_order_relaxed);
}

inline void throw_if_cancelled(const CancelFlag* flag) {
    if (cancel_requested(flag)) throw Cancelled();
}

// v.resize(n), 8 MiB at a time with a poll between: first touching a few hundred MiB of new
// pages takes most of a second on a loaded virtual machine.
template <class Vector>
void resize_polling(Vector& v, std::size_t n, const CancelFlag* flag) {
    constexpr std::size_t kStep =
        std::max<std::size_t>(1, (std::size_t(8) << 20) / sizeof(typename Vector::value_type));
    v.reserve(n);
    while (v.size() < n) {
        throw_if_cancelled(flag);
        v.resize(std::min(n, v.size() + kStep));
    }
}

}  // namespace glslppm
