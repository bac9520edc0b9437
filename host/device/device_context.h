// One device ready to run kernels: its context, an in-order profiling queue, and the one
// way kernels are launched.
#pragma once
#include <cstddef>

#include "device/cl_core.h"
#include "device/devices.h"

namespace fh {

struct DeviceContext {
  explicit DeviceContext(const DeviceInfo& info);
  DeviceInfo info;
  cl::Context context;
  cl::CommandQueue queue;
};

// Every kernel launch uses this local size and a global size padded to a multiple of it:
// PoCL compiles one variant per local size, and a NULL local size lets it pick a divisor
// of the global size: work-groups of one on odd queue lengths (docs/architecture.md).
constexpr size_t kLocalSize = 64;

void launch(const DeviceContext& dc, const cl::Kernel& kernel, size_t count, const char* name,
            cl::Event* event = nullptr);

}  // namespace fh
