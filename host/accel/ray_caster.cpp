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
  anyPackets_ = createKernel(program, "intersect_any_packets");
}

namespace {
constexpr unsigned kPacket = FH_PACKET;  // rays per work-item in the *_packets kernels
}

void RayCaster::intersectClosest(const cl::Buffer& org, const cl::Buffer& dir, const cl::Buffer& hits,
                                 unsigned count, RayOrder order, cl::Event* event) {
  if (order == RayOrder::Coherent) {
    setKernelArgs(closestPackets_, nodes(), blocks(), org, dir, hits, count);
    launch(dc_, closestPackets_, (count + kPacket - 1) / kPacket, "intersect_closest_packets", event);
  } else {
    setKernelArgs(closest_, nodes(), blocks(), org, dir, hits, count);
    launch(dc_, closest_, count, "intersect_closest", event);
  }
}

void RayCaster::intersectAny(const cl::Buffer& org, const cl::Buffer& dir, const cl::Buffer& occluded,
                             unsigned count, RayOrder order, cl::Event* event) {
  if (order == RayOrder::Coherent) {
    setKernelArgs(anyPackets_, nodes(), blocks(), org, dir, occluded, count);
    launch(dc_, anyPackets_, (count + kPacket - 1) / kPacket, "intersect_any_packets", event);
  } else {
    setKernelArgs(any_, nodes(), blocks(), org, dir, occluded, count);
    launch(dc_, any_, count, "intersect_any", event);
  }
}

}  // namespace fh
