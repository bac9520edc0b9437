// The intersect kernels' host side.
#include "accel/ray_caster.h"

namespace fh {

ProgramSpec intersectProgram(const std::string& traversalOptions) {
  return {"ray casting", {"ray_cast.cl"}, traversalOptions};
}

DeviceBvh::DeviceBvh(DeviceContext& dc, const Bvh& bvh) {
  options_ = "-DFH_TRAVERSAL_STACK=" + std::to_string(bvh.traversalStack());
  nodes_ = allocateBuffer(dc.context, dc.info.device, CL_MEM_READ_ONLY, bvh.nodes.size() * sizeof(gpu::Bvh8Node),
                          "BVH nodes", bvh.nodes.data());
  blocks_ = allocateBuffer(dc.context, dc.info.device, CL_MEM_READ_ONLY,
                           bvh.blocks.size() * sizeof(gpu::TriangleBlock8), "BVH leaf triangles", bvh.blocks.data());
  triangles_ = allocateBuffer(dc.context, dc.info.device, CL_MEM_READ_ONLY, bvh.triangles.size() * sizeof(float),
                              "triangles", bvh.triangles.data());
}

RayCaster::RayCaster(DeviceContext& dc, const Bvh& bvh) : dc_(dc), bvh_(dc, bvh) {
  const cl::Program program =
      buildProgram(dc.context, dc.info.device, intersectProgram(bvh_.traversalOptions()), &buildInfo_);
  closest_ = createKernel(program, "intersect_closest");
  any_ = createKernel(program, "intersect_any");
  closestPackets_ = createKernel(program, "intersect_closest_packets");
  closestLanes_ = createKernel(program, "intersect_closest_lanes");
  anyPackets_ = createKernel(program, "intersect_any_packets");
  anyStreams_ = createKernel(program, "intersect_any_streams");
}

namespace {
// Work-items for `count` rays, `perItem` to a work-item.
size_t workItems(unsigned count, unsigned perItem) { return (count + perItem - 1) / perItem; }
}  // namespace

void RayCaster::intersectClosest(const cl::Buffer& org, const cl::Buffer& dir, const cl::Buffer& hits,
                                 unsigned count, RayOrder order, cl::Event* event) {
  Choice c{&closest_, 1, "intersect_closest"};
  if (order == RayOrder::Coherent)
    c = {&closestPackets_, FH_PACKET, "intersect_closest_packets"};
  else if (order == RayOrder::Incoherent && dc_.info.type == "cpu")
    c = {&closestLanes_, 8, "intersect_closest_lanes"};
  launchChoice(c, org, dir, hits, count, event);
}

void RayCaster::intersectAny(const cl::Buffer& org, const cl::Buffer& dir, const cl::Buffer& occluded,
                             unsigned count, RayOrder order, cl::Event* event) {
  Choice c{&any_, 1, "intersect_any"};
  if (order == RayOrder::Coherent)
    c = {&anyPackets_, FH_PACKET, "intersect_any_packets"};
  else if (order == RayOrder::Incoherent && dc_.info.type == "cpu")
    c = {&anyStreams_, FH_STREAM, "intersect_any_streams"};
  launchChoice(c, org, dir, occluded, count, event);
}

void RayCaster::launchChoice(const Choice& c, const cl::Buffer& org, const cl::Buffer& dir, const cl::Buffer& out,
                             unsigned count, cl::Event* event) {
  setKernelArgs(*c.kernel, nodes(), blocks(), org, dir, out, count);
  launch(dc_, *c.kernel, workItems(count, c.raysPerItem), c.name, event);
}

}  // namespace fh
