// The interface through which `fredholm bench` compares against another CPU ray tracer
// (Embree, built as an optional part of bench/), tracing exactly the same ray buffers.
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "scene/scene.h"

namespace fh {

class ExternalTracer {
 public:
  virtual ~ExternalTracer() = default;
  virtual std::string name() const = 0;
  // Builds the tracer's own acceleration structure; returns seconds.
  virtual double build(const Scene& scene) = 0;
  // Memory the last build holds (its copy of the geometry and its BVH), in bytes.
  virtual size_t sceneBytes() const = 0;
  // The APIs it offers ("single", "stream", ...).
  virtual std::vector<std::string> apis() const = 0;
  // Traces rays (float4 origin.xyz+tmin, float4 direction.xyz+tmax) with `threads`
  // threads: closest hits (file-order triangle id or -1 into `triangle`) or, if
  // `occlusion`, any hit (1/0 into `triangle`). Returns seconds.
  virtual double trace(const std::string& api, const std::vector<float>& org, const std::vector<float>& dir,
                       bool occlusion, bool coherent, int threads, std::vector<int>& triangle) = 0;
};

using ExternalTracerFactory = std::unique_ptr<ExternalTracer> (*)();

}  // namespace fh
