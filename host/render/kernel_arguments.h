// Binding a kernel's arguments in the order its parameter list has them, the path state,
// scene and light-request lists (declared once under kernels/) expanded in place, and
// checked against the kernel's count so no call site counts indices.
#pragma once
#include <string>

#include "device/cl_core.h"
#include "render/device_scene.h"
#include "render/wavefront.h"

namespace fh {

// Sets a kernel's arguments in the order they are given, so no call site counts indices.
class ArgumentList {
 public:
  explicit ArgumentList(cl::Kernel& kernel) : kernel_(kernel) {}
  template <typename T>
  ArgumentList& operator<<(const T& value) {
    FH_CL(kernel_.setArg(next_++, value));
    return *this;
  }
  // Every path-state field, in FH_PATH_FIELDS order: a stage's FH_PATH_PARAMS.
  ArgumentList& operator<<(const PathStateBuffers& p) {
#define FH_ARGUMENT(type, name, bytes) *this << p.name;
    FH_PATH_FIELDS(FH_ARGUMENT)
#undef FH_ARGUMENT
    return *this;
  }
  // Every scene buffer, in FH_SCENE_FIELDS order: a kernel's FH_SCENE_PARAMS.
  ArgumentList& operator<<(const SceneBuffers& b) {
#define FH_ARGUMENT(type, name) *this << b.name;
    FH_SCENE_FIELDS(FH_ARGUMENT)
#undef FH_ARGUMENT
    return *this;
  }
  // Every light-sample request field: FH_SHADOW_PARAMS.
  ArgumentList& operator<<(const ShadowRequestBuffers& r) {
#define FH_ARGUMENT(type, name, bytes) *this << r.name;
    FH_SHADOW_FIELDS(FH_ARGUMENT)
#undef FH_ARGUMENT
    return *this;
  }
  // A list that binds fewer or more arguments than the kernel has is a bug here, caught
  // before any launch.
  void expectComplete(const char* what) const {
    const cl_uint expected = kernel_.getInfo<CL_KERNEL_NUM_ARGS>();
    if (next_ != expected)
      throw Error(std::string("internal error: ") + what + " bound " + std::to_string(next_) + " arguments of " +
                  std::to_string(expected));
  }

 private:
  cl::Kernel& kernel_;
  cl_uint next_ = 0;
};

// Binds `values` to `kernel`'s parameters in order, all of them.
template <typename... T>
void bindAll(cl::Kernel& kernel, const char* what, const T&... values) {
  ArgumentList list(kernel);
  (list << ... << values);
  list.expectComplete(what);
}

}  // namespace fh
