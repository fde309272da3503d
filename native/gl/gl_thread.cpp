#include "gl/gl_thread.h"

namespace glslppm::gl {

GlThread::GlThread(int device_index) {
    std::promise<void> started;
    std::future<void> ready = started.get_future();
    thread_ = std::thread([this, device_index, &started] { run(device_index, started); });
    try {
        ready.get();
    } catch (...) {
        thread_.join();  // the thread has already ended after reporting the failure
        throw;
    }
}

GlThread::~GlThread() {
    {
        std::lock_guard lock(mutex_);
        stopping_ = true;
    }
    wake_.notify_one();
    thread_.join();
}

void GlThread::post(std::function<void()> job) {
    {
        std::lock_guard lock(mutex_);
        jobs_.push_back(std::move(job));
    }
    wake_.notify_one();
}

void GlThread::run(int device_index, std::promise<void>& started) {
    try {
        context_ = std::make_unique<EglContext>(device_index);
    } catch (...) {
        // Without libEGL (the error just caught says so) any EGL call would abort.
        if (libegl_loaded()) eglReleaseThread();
        started.set_exception(std::current_exception());
        return;
    }
    started.set_value();
    for (;;) {
        std::function<void()> job;
        {
            std::unique_lock lock(mutex_);
            wake_.wait(lock, [this] { return stopping_ || !jobs_.empty(); });
            if (jobs_.empty()) break;  // stopping, and every posted job has run
            job = std::move(jobs_.front());
            jobs_.pop_front();
        }
        job();  // packaged_task: exceptions travel to the caller's future
    }
    context_.reset();
    eglReleaseThread();  // EGL's per-thread state of this thread, which ends here
}

}  // namespace glslppm::gl
