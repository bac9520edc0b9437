// The checked boundary to OpenCL: every call goes through FH_CL / FH_CL_ERR, which turn
// a failure into an fh::ClError naming the call, the source file and line, and the error.
#pragma once
#include <CL/opencl.hpp>

#include <cstddef>
#include <string>

#include "base/error.h"

namespace fh {

const char* clErrorName(cl_int code);
bool isOutOfMemory(cl_int code);
[[noreturn]] void throwClError(cl_int code, const char* call, const char* file, int line);

inline void clCheck(cl_int code, const char* call, const char* file, int line) {
  if (code != CL_SUCCESS) throwClError(code, call, file, line);
}

}  // namespace fh

// Wraps a call that returns a cl_int status.
#define FH_CL(expr) ::fh::clCheck((expr), #expr, __FILE__, __LINE__)
// Checks the status a constructor or creation call wrote to `err`; `what` names the call.
#define FH_CL_ERR(err, what) ::fh::clCheck((err), (what), __FILE__, __LINE__)

namespace fh {

// A device buffer that knows its size; allocation failures name what was being allocated.
cl::Buffer allocateBuffer(const cl::Context& context, const cl::Device& device,
                          cl_mem_flags flags, size_t bytes, const char* what,
                          const void* host = nullptr);

// Sets a kernel's arguments 0, 1, 2, ... in order, each checked.
template <typename... Args>
void setKernelArgs(cl::Kernel& kernel, const Args&... args) {
  cl_uint index = 0;
  (FH_CL(kernel.setArg(index++, args)), ...);
}

// Rounds n up to a multiple of `multiple` (global sizes must be whole work-groups).
inline size_t roundUp(size_t n, size_t multiple) { return (n + multiple - 1) / multiple * multiple; }

}  // namespace fh
