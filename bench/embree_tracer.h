// Embree 3 as the reference CPU tracer for `fredholm bench`.
#pragma once
#include "bench/external_tracer.h"

namespace fh {
std::unique_ptr<ExternalTracer> makeEmbreeTracer();
}
