// Device set-up and kernel launches.
#include "device/device_context.h"

#include <string>

namespace fh {

DeviceContext::DeviceContext(const DeviceInfo& di) : info(di) {
  cl_int err = CL_SUCCESS;
  context = cl::Context(info.device, nullptr, nullptr, nullptr, &err);
  FH_CL_ERR(err, "clCreateContext");
  queue = cl::CommandQueue(context, info.device, CL_QUEUE_PROFILING_ENABLE, &err);
  FH_CL_ERR(err, "clCreateCommandQueue");
}

void launch(const DeviceContext& dc, const cl::Kernel& kernel, size_t count, const char* name, cl::Event* event) {
  if (count == 0) return;
  const cl_int err = dc.queue.enqueueNDRangeKernel(kernel, cl::NullRange, cl::NDRange(roundUp(count, kLocalSize)),
                                                   cl::NDRange(kLocalSize), nullptr, event);
  FH_CL_ERR(err, (std::string("clEnqueueNDRangeKernel(") + name + ")").c_str());
}

}  // namespace fh
