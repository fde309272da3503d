// Cancelling long CPU work (the BVH build, a renderer's set-up) from another thread: the
// caller owns a CancelFlag and sets it; the work polls it every few milliseconds of work and
// throws Cancelled, so a user's cancel takes effect in a fraction of a second whatever the
// scene's size.
#pragma once

#include <atomic>
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

}  // namespace glslppm
