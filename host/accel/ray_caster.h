// The ray-casting operation on one device: the scene's BVH in device memory and the
// intersect kernels (closest hit and any hit) over queues of rays.
#pragma once
#include <string>

#include "accel/bvh.h"
#include "device/device_context.h"
#include "device/program.h"

namespace fh {

// The intersect kernels for a BVH that needs `traversalOptions` (its stack depth).
ProgramSpec intersectProgram(const std::string& traversalOptions);

// The BVH in one device's memory, for any program that traverses it.
class DeviceBvh {
 public:
  DeviceBvh(DeviceContext& dc, const Bvh& bvh);
  const cl::Buffer& nodes() const { return nodes_; }
  const cl::Buffer& blocks() const { return blocks_; }
  // Triangles in BVH order (three float4 each), for turning hits into surface points.
  const cl::Buffer& triangles() const { return triangles_; }
  // Build options every program that traverses this BVH must use.
  const std::string& traversalOptions() const { return options_; }

 private:
  std::string options_;
  cl::Buffer nodes_, blocks_, triangles_;
};

// How a batch of rays is laid out, which picks the kernels that trace it. Coherent batches
// (camera rays in pixel order, where neighbours in the batch take nearly the same path
// through the tree) are traced eight at a time as packets. Otherwise, on a CPU, closest hits
// are traced eight consecutive rays per work-item, their constants set up together in
// vector lanes, and any-hit queries as streams of FH_STREAM consecutive rays
// (kernels/intersect_stream.h: a stream's private state is too large for a GPU's
// work-items); on a GPU one ray per work-item. OneByOne traces every ray on its own, as the path tracer's stages do.
// Whichever kernels, the answers are the same, bit for bit.
enum class RayOrder { Incoherent, Coherent, OneByOne };

// Ray casting as an operation of its own: the BVH and the intersect kernels over arrays
// of rays (the bench, --aov, tests). The path tracer traverses the BVH inside its stages.
class RayCaster {
 public:
  RayCaster(DeviceContext& dc, const Bvh& bvh);

  // hits[i] = (t, b1, b2, BVH-order triangle bits or -1) for rays (org.xyz+tmin, dir.xyz+tmax).
  void intersectClosest(const cl::Buffer& org, const cl::Buffer& dir, const cl::Buffer& hits, unsigned count,
                        RayOrder order = RayOrder::Incoherent, cl::Event* event = nullptr);
  // occluded[i] = 1 if anything lies on [tmin, tmax), else 0.
  void intersectAny(const cl::Buffer& org, const cl::Buffer& dir, const cl::Buffer& occluded, unsigned count,
                    RayOrder order = RayOrder::Incoherent, cl::Event* event = nullptr);

  const cl::Buffer& nodes() const { return bvh_.nodes(); }
  const cl::Buffer& blocks() const { return bvh_.blocks(); }
  const cl::Buffer& triangles() const { return bvh_.triangles(); }
  const std::string& traversalOptions() const { return bvh_.traversalOptions(); }
  const ProgramBuildInfo& buildInfo() const { return buildInfo_; }

 private:
  // A kernel over arrays of rays, and how many rays each of its work-items takes.
  struct Choice {
    cl::Kernel* kernel;
    unsigned raysPerItem;
    const char* name;
  };
  void launchChoice(const Choice& c, const cl::Buffer& org, const cl::Buffer& dir, const cl::Buffer& out,
                    unsigned count, cl::Event* event);

  DeviceContext& dc_;
  DeviceBvh bvh_;
  ProgramBuildInfo buildInfo_;
  cl::Kernel closest_, any_, closestPackets_, anyPackets_, anyStreams_, closestLanes_;
};

}  // namespace fh
