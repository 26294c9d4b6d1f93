// Move-only owners of OpenCL objects: each releases its handle exactly once.
#pragma once

#include <CL/cl.h>

#include <utility>

namespace mq::cl {

// Owns one reference to an OpenCL object; Release is the matching clRelease* function.
template <typename T, cl_int (*Release)(T)>
class Handle {
 public:
  Handle() = default;
  // Takes ownership of an already retained handle (as returned by clCreate*).
  explicit Handle(T h) : h_(h) {}
  ~Handle() { reset(); }
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  Handle(Handle&& o) noexcept : h_(std::exchange(o.h_, nullptr)) {}
  Handle& operator=(Handle&& o) noexcept {
    if (this != &o) {
      reset();
      h_ = std::exchange(o.h_, nullptr);
    }
    return *this;
  }

  T get() const { return h_; }
  explicit operator bool() const { return h_ != nullptr; }
  // Releases the handle; errors are ignored since this runs in destructors.
  void reset() {
    if (h_) Release(h_);
    h_ = nullptr;
  }

 private:
  T h_ = nullptr;
};

using Context = Handle<cl_context, clReleaseContext>;
using CommandQueue = Handle<cl_command_queue, clReleaseCommandQueue>;
using Program = Handle<cl_program, clReleaseProgram>;
using Kernel = Handle<cl_kernel, clReleaseKernel>;
using Buffer = Handle<cl_mem, clReleaseMemObject>;

}  // namespace mq::cl
