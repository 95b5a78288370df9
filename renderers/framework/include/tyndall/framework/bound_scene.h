// The prepared scene that a technique's shared-header accessors read on the calling thread. In GLSL the code of
// shaders/shared reads storage buffers; compiled as C++ it calls accessors (ltsdLight(i), wvdsPlane(i), ...) whose
// definitions read the scene bound here, and traverses the BVH bound with it. One binding mechanism for every
// technique; each names its own scope (ltsd::SceneScope) after it.
#pragma once

#include "tyndall/core/error.h"
#include "tyndall/gpu/bvh.h"

namespace tyndall {

template <typename Scene>
class BoundScene {
public:
    // Binds `scene` and `bvh` to this thread for its lifetime; nested bindings restore the previous one. The scene
    // must outlive the binding.
    class Binding {
    public:
        Binding(const Scene& scene, const gpu::Bvh& bvh) : previous_(current_), bvh_(bvh) { current_ = &scene; }
        ~Binding() { current_ = previous_; }
        Binding(const Binding&) = delete;
        Binding& operator=(const Binding&) = delete;

    private:
        const Scene* previous_;
        gpu::BvhScope bvh_;
    };

    // The scene bound to this thread; a contract error naming `technique` when there is none.
    static const Scene& get(const char* technique) {
        TY_CHECK(current_ != nullptr, std::string("the ") + technique + " accessors need a SceneScope on this thread");
        return *current_;
    }

private:
    static inline thread_local const Scene* current_ = nullptr;
};

}  // namespace tyndall
