// `fredholm bench`: ray-casting throughput (Mrays/s) per scene and ray kind (primary,
// bounce, shadow), BVH build time and memory, kernel compile time, and, when an external
// tracer (Embree) is built in, its throughput on exactly the same rays.
#pragma once
#include <string>
#include <vector>

#include "bench/external_tracer.h"

namespace fh {

struct BenchOptions {
  std::vector<std::string> scenes;  // names (cornell, bunny-box, sponza, bunnies-1m) or OBJ paths
  std::string device;
  std::string jsonPath;
  bool force = false;
  int width = 512, height = 512;  // primary rays per batch = width * height
  int repeats = 5;                // timed runs after one warm-up; the median is reported
  int threads = 2;                // external tracer threads (PoCL uses every core)
  ExternalTracerFactory external = nullptr;
};

int runBench(const BenchOptions& options);

}  // namespace fh
