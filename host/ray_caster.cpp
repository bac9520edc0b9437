// Device set-up, kernel launches and the intersect kernels' host side.
#include "ray_caster.h"

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

ProgramSpec intersectProgram(const std::string& traversalOptions) {
  return {"intersect", {"intersect.cl"}, traversalOptions};
}

RayCaster::RayCaster(DeviceContext& dc, const Bvh& bvh) : dc_(dc) {
  options_ = "-DFH_TRAVERSAL_STACK=" + std::to_string(bvh.traversalStack());
  nodes_ = allocateBuffer(dc.context, dc.info.device, CL_MEM_READ_ONLY, bvh.nodes.size() * sizeof(gpu::Bvh8Node),
                          "BVH nodes", bvh.nodes.data());
  blocks_ = allocateBuffer(dc.context, dc.info.device, CL_MEM_READ_ONLY,
                           bvh.blocks.size() * sizeof(gpu::TriangleBlock8), "BVH leaf triangles", bvh.blocks.data());
  triangles_ = allocateBuffer(dc.context, dc.info.device, CL_MEM_READ_ONLY, bvh.triangles.size() * sizeof(float),
                              "triangles", bvh.triangles.data());
  const cl::Program program = buildProgram(dc.context, dc.info.device, intersectProgram(options_), &buildInfo_);
  closest_ = createKernel(program, "intersect_closest");
  any_ = createKernel(program, "intersect_any");
}

void RayCaster::intersectClosest(const cl::Buffer& org, const cl::Buffer& dir, const cl::Buffer& hits,
                                 unsigned count, cl::Event* event) {
  setKernelArgs(closest_, nodes_, blocks_, org, dir, hits, count);
  launch(dc_, closest_, count, "intersect_closest", event);
}

void RayCaster::intersectAny(const cl::Buffer& org, const cl::Buffer& dir, const cl::Buffer& occluded,
                             unsigned count, cl::Event* event) {
  setKernelArgs(any_, nodes_, blocks_, org, dir, occluded, count);
  launch(dc_, any_, count, "intersect_any", event);
}

}  // namespace fh
