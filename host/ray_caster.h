// The ray-casting operation on one device: the scene's BVH in device memory and the
// intersect kernels (closest hit and any hit) over queues of rays.
#pragma once
#include <string>

#include "bvh.h"
#include "cl_core.h"
#include "devices.h"
#include "program.h"

namespace fh {

// One device with its context and an in-order, profiling-enabled queue.
struct DeviceContext {
  explicit DeviceContext(const DeviceInfo& info);
  DeviceInfo info;
  cl::Context context;
  cl::CommandQueue queue;
};

// Every kernel launch uses this local size and a global size padded to a multiple of it:
// PoCL compiles one variant per local size, and a NULL local size on odd queue lengths
// gives work-groups of one (see ../shared/POCL.md).
constexpr size_t kLocalSize = 64;

void launch(const DeviceContext& dc, const cl::Kernel& kernel, size_t count, const char* name,
            cl::Event* event = nullptr);

// The intersect kernels for a BVH that needs `traversalOptions` (its stack depth).
ProgramSpec intersectProgram(const std::string& traversalOptions);

class RayCaster {
 public:
  RayCaster(DeviceContext& dc, const Bvh& bvh);

  // hits[i] = (t, b1, b2, BVH-order triangle bits or -1) for rays (org.xyz+tmin, dir.xyz+tmax).
  void intersectClosest(const cl::Buffer& org, const cl::Buffer& dir, const cl::Buffer& hits, unsigned count,
                        cl::Event* event = nullptr);
  // occluded[i] = 1 if anything lies on [tmin, tmax), else 0.
  void intersectAny(const cl::Buffer& org, const cl::Buffer& dir, const cl::Buffer& occluded, unsigned count,
                    cl::Event* event = nullptr);

  const cl::Buffer& nodes() const { return nodes_; }
  const cl::Buffer& blocks() const { return blocks_; }
  // Triangles in BVH order (three float4 each), for turning hits into surface points.
  const cl::Buffer& triangles() const { return triangles_; }
  // Build options every program that traverses this BVH must use.
  const std::string& traversalOptions() const { return options_; }
  const ProgramBuildInfo& buildInfo() const { return buildInfo_; }

 private:
  DeviceContext& dc_;
  std::string options_;
  cl::Buffer nodes_, blocks_, triangles_;
  ProgramBuildInfo buildInfo_;
  cl::Kernel closest_, any_;
};

}  // namespace fh
