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

RayCaster::RayCaster(DeviceContext& dc, const Bvh& bvh) : dc_(dc) {
  options_ = "-DFH_TRAVERSAL_STACK=" + std::to_string(bvh.traversalStack());
  nodes_ = allocateBuffer(dc.context, dc.info.device, CL_MEM_READ_ONLY, bvh.nodes.size() * sizeof(gpu::Bvh8Node),
                          "BVH nodes", bvh.nodes.data());
  blocks_ = allocateBuffer(dc.context, dc.info.device, CL_MEM_READ_ONLY,
                           bvh.blocks.size() * sizeof(gpu::TriangleBlock8), "BVH leaf triangles", bvh.blocks.data());
  triangles_ = allocateBuffer(dc.context, dc.info.device, CL_MEM_READ_ONLY, bvh.triangles.size() * sizeof(float),
                              "triangles", bvh.triangles.data());
  const cl::Program program = buildProgram(dc.context, dc.info.device, {"intersect.cl"}, options_, &buildInfo_);
  closest_ = createKernel(program, "intersect_closest");
  any_ = createKernel(program, "intersect_any");
}

void RayCaster::intersectClosest(const cl::Buffer& org, const cl::Buffer& dir, const cl::Buffer& hits,
                                 unsigned count, cl::Event* event) {
  FH_CL(closest_.setArg(0, nodes_));
  FH_CL(closest_.setArg(1, blocks_));
  FH_CL(closest_.setArg(2, org));
  FH_CL(closest_.setArg(3, dir));
  FH_CL(closest_.setArg(4, hits));
  FH_CL(closest_.setArg(5, count));
  launch(dc_, closest_, count, "intersect_closest", event);
}

void RayCaster::intersectAny(const cl::Buffer& org, const cl::Buffer& dir, const cl::Buffer& occluded,
                             unsigned count, cl::Event* event) {
  FH_CL(any_.setArg(0, nodes_));
  FH_CL(any_.setArg(1, blocks_));
  FH_CL(any_.setArg(2, org));
  FH_CL(any_.setArg(3, dir));
  FH_CL(any_.setArg(4, occluded));
  FH_CL(any_.setArg(5, count));
  launch(dc_, any_, count, "intersect_any", event);
}

}  // namespace fh
