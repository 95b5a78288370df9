// GPU renderers kept for the whole process (issue 31). The studio and the CLI make a technique object per render job,
// but what its GPU renderer builds is the same from one edit to the next: kernels compiled by glslang and the driver,
// graphics pipelines, output buffers whose pages were touched once (gpu::keptBuffer). Rebuilt for every render they
// cost an LTSD frame of 512 x 512 on lavapipe 174 ms against 44.5 ms with them kept (docs/testing.md, "Where a frame
// goes"). A render leases a renderer of its type for its duration; renders on several threads at once each get their
// own, and every renderer goes back to the pool when its lease ends.
#pragma once

#include "tyndall/gpu/context.h"

#include <memory>
#include <mutex>
#include <utility>
#include <vector>

namespace tyndall {

template <typename Renderer>
class RendererPool {
public:
    class Lease {
    public:
        Lease() = default;
        Lease(Lease&& other) noexcept : renderer_(std::move(other.renderer_)) {}
        Lease& operator=(Lease&& other) noexcept {
            if (this != &other) {
                giveBack();
                renderer_ = std::move(other.renderer_);
            }
            return *this;
        }
        Lease(const Lease&) = delete;
        Lease& operator=(const Lease&) = delete;
        ~Lease() { giveBack(); }

        Renderer* operator->() const { return renderer_.get(); }
        Renderer& operator*() const { return *renderer_; }
        explicit operator bool() const { return renderer_ != nullptr; }

    private:
        friend class RendererPool;
        explicit Lease(std::unique_ptr<Renderer> renderer) : renderer_(std::move(renderer)) {}
        void giveBack() {
            if (!renderer_) return;
            State& s = state();
            std::lock_guard lock(s.mutex);
            s.idle.push_back(std::move(renderer_));
        }
        std::unique_ptr<Renderer> renderer_;
    };

    // An idle renderer, else a new one (whose constructor may throw: gpu::GpuError without Vulkan).
    static Lease lease() {
        // The shared context first, so that the pool, made after it, is destroyed before it at exit.
        (void)gpu::sharedContext();
        State& s = state();
        {
            std::lock_guard lock(s.mutex);
            if (!s.idle.empty()) {
                std::unique_ptr<Renderer> renderer = std::move(s.idle.back());
                s.idle.pop_back();
                return Lease(std::move(renderer));
            }
        }
        return Lease(std::make_unique<Renderer>());
    }

    // Renderers waiting for a lease (tests).
    static std::size_t idle() {
        State& s = state();
        std::lock_guard lock(s.mutex);
        return s.idle.size();
    }

private:
    struct State {
        std::mutex mutex;
        std::vector<std::unique_ptr<Renderer>> idle;
    };
    static State& state() {
        static State s;
        return s;
    }
};

}  // namespace tyndall
