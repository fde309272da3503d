// A dedicated thread that owns an EglContext and runs GL work on it.
//
// The caller may be Blender's render or main thread with its own GL context current (GLX or
// EGL). EGL's current context and bound API are per thread, so doing all our GL work on a
// thread of our own never touches the caller's state.
#pragma once

#include <condition_variable>
#include <deque>
#include <functional>
#include <future>
#include <memory>
#include <mutex>
#include <thread>
#include <type_traits>

#include "gl/egl_context.h"

namespace glslppm::gl {

class GlThread {
  public:
    // Starts the thread and creates the context on it (device_index as EglContext's). A
    // GlError from the context's creation is rethrown here.
    explicit GlThread(int device_index = -1);
    // Destroys the context on its thread, then joins it.
    ~GlThread();
    GlThread(const GlThread&) = delete;
    GlThread& operator=(const GlThread&) = delete;

    // Runs f on the GL thread with the context current; blocks until it has run, returns its
    // value and rethrows its exception. Called from the GL thread itself, runs f inline.
    template <class F>
    auto call(F&& f) -> decltype(f()) {
        using R = decltype(f());
        if (std::this_thread::get_id() == thread_.get_id()) return f();
        std::packaged_task<R()> task(std::forward<F>(f));
        std::future<R> result = task.get_future();
        post([&task] { task(); });  // `task` outlives the wait below
        return result.get();
    }

    const ContextInfo& info() const { return context_->info(); }
    // The context; use it (and its programs()) only inside call().
    EglContext& context() { return *context_; }

  private:
    void post(std::function<void()> job);
    void run(int device_index, std::promise<void>& started);

    std::mutex mutex_;
    std::condition_variable wake_;
    std::deque<std::function<void()>> jobs_;
    bool stopping_ = false;
    std::unique_ptr<EglContext> context_;
    std::thread thread_;
};

}  // namespace glslppm::gl
