// The light tracer's passes: a launch each, then the splats read back and turned into the
// film's pass samples.
#include "render/light_tracer.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "base/test_hooks.h"
#include "render/kernel_arguments.h"
#include "render/merge_grid.h"
#include "render/pixel_filter.h"
#include "render/wavefront.h"

namespace fh {
namespace {

// Per pixel: three 64-bit sums as (low, high) words (kernels/light_paths.h, FH_SPLAT_WORDS).
constexpr size_t kSplatWords = 6;
// bdpt and vcm: a light vertex's bytes (kernels/bdpt.cl, FH_BDPT_VERTEX_WORDS float4s), and
// the most a launch's light vertices may take.
constexpr size_t kVertexBytes = 4 * 16;
constexpr size_t kVertexBufferBytes = size_t(64) << 20;

}  // namespace

bool mergesLightVertices(Method method, bool deltaLobes) {
  return method == Method::VCM && (deltaLobes || testHooks().vcmMergeOnly);
}

ProgramSpec lightTracerProgram(Method method, const SceneFeatures& features, const std::string& traversalOptions,
                               unsigned lanes) {
  const bool joined = bidirectional(method), vcm = method == Method::VCM;
  const int only = testHooks().bdptOnlyLightVertices;
  std::string strategy = joined && only >= 0 ? " -DFH_BDPT_ONLY_S=" + std::to_string(only) + "u" : "";
  if (vcm) strategy += testHooks().vcmMergeOnly ? " -DFH_VCM -DFH_VCM_MERGE_ONLY" : " -DFH_VCM";
  const std::string lanesOption = " -DFH_LANES=" + std::to_string(lanes);
  return {std::string(joined ? "bidirectional path tracer (" : "light tracer (") + methodName(method) +
              features.buildOptions() + strategy + lanesOption + ")",
          {joined ? "bdpt.cl" : "light_trace.cl"},
          traversalOptions + features.buildOptions() + strategy + lanesOption};
}

LightTracer::LightTracer(DeviceContext& dc, const PreparedScene& scene, const Bvh& bvh, const Camera& camera,
                         const RenderSettings& s)
    : dc_(dc),
      // lt: delta lobes (glass, and mirrors, compiled with the glossy lobes) seen directly.
      cameraPaths_(s.method == Method::LT && (scene.features.glass || scene.features.glossy)
                       ? std::make_unique<WavefrontPipeline>(dc, scene, bvh, camera, s)
                       : nullptr),
      ownScene_(cameraPaths_ ? nullptr : std::make_unique<DeviceScene>(dc, scene, bvh)),
      scene_(cameraPaths_ ? cameraPaths_->deviceScene() : *ownScene_),
      pixels_(unsigned(s.width) * unsigned(s.height)),
      method_(s.method),
      merges_(mergesLightVertices(s.method, scene.deltaLobes)),
      kernelName_(merges_                     ? "vcm_camera_subpaths"
                  : bidirectional(s.method) ? "bdpt"
                                            : "light_trace"),
      // The lanes the device's path tracer takes (eight on a CPU).
      lanes_(lanesOf(strategyFor(dc.info, s.strategy))) {
  std::vector<float> inverseCdf;
  params_ = renderParams(s, camera, scene_, inverseCdf);
  // The splats weigh by the filter's density where camera rays are offset by its inverse CDF.
  const std::vector<float> density = filterDensity(s.filter, int(params_.filter_table_size));
  density_ = allocateBuffer(dc.context, dc.info.device, CL_MEM_READ_ONLY, density.size() * 4, "filter density",
                            density.data());
  // vcm without merging is bdpt, in bdpt's program.
  const Method programMethod = merges_ || !bidirectional(method_) ? method_ : Method::BDPT;
  const cl::Program program =
      buildProgram(dc.context, dc.info.device,
                   lightTracerProgram(programMethod, scene_.features, scene_.bvh.traversalOptions(), lanes_));
  kernel_ = createKernel(program, kernelName_);
  if (bidirectional(method_)) {
    filterTable_ = allocateBuffer(dc.context, dc.info.device, CL_MEM_READ_ONLY, inverseCdf.size() * 4,
                                  "filter inverse CDF", inverseCdf.data());
    const size_t perPath = size_t(std::max(s.maxDepth, 1)) * kVertexBytes;
    pathsPerLaunch_ = unsigned(std::min<size_t>(pixels_, std::max<size_t>(kVertexBufferBytes / perPath, 64)));
    lightVertices_ = allocateBuffer(dc.context, dc.info.device, CL_MEM_READ_WRITE, pathsPerLaunch_ * perPath,
                                    "bidirectional light vertices");
    for (size_t k = 0; k < 4; ++k) sphere_.s[k] = scene.lights.boundingSphere[k];
  }
  if (merges_) {
    lightKernel_ = createKernel(program, "vcm_light_subpaths");
    gatherKernel_ = createKernel(program, "vcm_gather_positions");
    storedCounts_ = allocateBuffer(dc.context, dc.info.device, CL_MEM_READ_WRITE, size_t(pathsPerLaunch_) * 4,
                                   "light vertices per path");
    offsetsBuffer_ = allocateBuffer(dc.context, dc.info.device, CL_MEM_READ_ONLY, size_t(pathsPerLaunch_) * 4,
                                     "light vertices' offsets");
    positions_ = allocateBuffer(dc.context, dc.info.device, CL_MEM_WRITE_ONLY,
                                size_t(pathsPerLaunch_) * std::max(s.maxDepth, 1) * 16, "light vertices' positions");
    firstMergeRadius_ = s.mergeRadius * sphere_.s[3];
    maxDepth_ = unsigned(std::max(s.maxDepth, 1));
  }
  for (Slot& slot : slots_) {
    slot.splats = allocateBuffer(dc.context, dc.info.device, CL_MEM_READ_WRITE, size_t(pixels_) * kSplatWords * 4,
                                 "light tracing splats");
    slot.tallies = allocateBuffer(dc.context, dc.info.device, CL_MEM_READ_WRITE, 16, "light tracing tallies");
    slot.splatWords.resize(size_t(pixels_) * kSplatWords);
  }
  stats_.wavefront = pixels_;
}

bool LightTracer::fits(const std::shared_ptr<const RoundPixels>& pixels, uint64_t granted, uint64_t returned) const {
  if (pixels) throw Error("internal: light tracing renders every pixel in each pass (no adaptive rounds)");
  return granted - returned < kSlots && (!cameraPaths_ || cameraPaths_->fits(pixels, granted, returned));
}

void LightTracer::grantPass(uint64_t local, uint32_t global, std::shared_ptr<const RoundPixels>) {
  Slot& slot = slots_[local % kSlots];
  slot.global = global;
  slot.state = State::Granted;
  granted_ = local + 1;
  if (cameraPaths_) cameraPaths_->grantPass(local, global, nullptr);
}

void LightTracer::startGrantedPasses() {
  if (cameraPaths_) cameraPaths_->startGrantedPasses();
}

// The next granted pass, if any: its buffers cleared, its light paths traced, its splats
// read back (all queued; readCounters waits).
void LightTracer::enqueueIteration() {
  if (cameraPaths_) cameraPaths_->enqueueIteration();
  if (nextLaunch_ == granted_) return;
  Slot& slot = slots_[nextLaunch_++ % kSlots];
  static const uint32_t zero = 0;
  FH_CL(dc_.queue.enqueueFillBuffer(slot.splats, zero, 0, size_t(pixels_) * kSplatWords * 4));
  FH_CL(dc_.queue.enqueueFillBuffer(slot.tallies, zero, 0, 16));
  if (merges_) {
    for (unsigned first = 0; first < pixels_; first += pathsPerLaunch_) mergeLaunch(slot, first);
  } else if (bidirectional(method_)) {
    for (unsigned first = 0; first < pixels_; first += pathsPerLaunch_) {
      const unsigned count = std::min(pathsPerLaunch_, pixels_ - first);
      bindAll(kernel_, kernelName_, params_, slot.global, first, count, sphere_, lightVertices_, filterTable_, slot.splats,
              density_, slot.tallies, scene_.buffers);
      cl::Event event;
      launch(dc_, kernel_, (count + lanes_ - 1) / lanes_, kernelName_, &event);
      events_.push_back({kernelName_, event});
    }
  } else {
    bindAll(kernel_, kernelName_, params_, slot.global, slot.splats, density_, slot.tallies, scene_.buffers);
    cl::Event event;
    launch(dc_, kernel_, (pixels_ + lanes_ - 1) / lanes_, kernelName_, &event);
    events_.push_back({kernelName_, event});
  }
  FH_CL(dc_.queue.enqueueReadBuffer(slot.splats, CL_FALSE, 0, slot.splatWords.size() * 4, slot.splatWords.data()));
  FH_CL(dc_.queue.enqueueReadBuffer(slot.tallies, CL_FALSE, 0, 12, slot.tallyWords.data()));
  slot.state = State::Launched;
}

// vcm: a launch's light subpaths, their vertices read back and filed in the merging grid
// of the pass's radius, then its camera subpaths. The host waits for the light subpaths.
void LightTracer::mergeLaunch(Slot& slot, unsigned first) {
  const unsigned count = std::min(pathsPerLaunch_, pixels_ - first);
  const float radius = mergeRadius(firstMergeRadius_, slot.global);
  // eta = N pi r^2: merging's density against a connection's (kernels/bdpt.cl MergeFactors).
  const double eta = double(count) * M_PI * double(radius) * double(radius);
  // Kept finite in float at any scene scale (a tiny scene's eta^2 underflows).
  const auto finite = [](double x) { return float(std::clamp(x, 1e-30, 1e30)); };
  const cl_float2 factors{{finite(eta * eta), finite(1.0 / (eta * eta))}};
  bindAll(lightKernel_, "vcm_light_subpaths", params_, slot.global, first, count, sphere_, factors, lightVertices_,
          storedCounts_, slot.splats, density_, slot.tallies, scene_.buffers);
  cl::Event lightEvent;
  launch(dc_, lightKernel_, (count + lanes_ - 1) / lanes_, "vcm_light_subpaths", &lightEvent);
  events_.push_back({"vcm_light_subpaths", lightEvent});
  // Only the stored vertices' positions come back: gathered by the running sum of the counts.
  counts_.resize(count);
  FH_CL(dc_.queue.enqueueReadBuffer(storedCounts_, CL_TRUE, 0, counts_.size() * 4, counts_.data()));
  offsets_.resize(count);
  uint32_t vertices = 0;
  for (unsigned p = 0; p < count; ++p) offsets_[p] = vertices, vertices += counts_[p];
  FH_CL(dc_.queue.enqueueWriteBuffer(offsetsBuffer_, CL_FALSE, 0, size_t(count) * 4, offsets_.data()));
  bindAll(gatherKernel_, "vcm_gather_positions", count, maxDepth_, lightVertices_, storedCounts_, offsetsBuffer_,
          positions_);
  launch(dc_, gatherKernel_, count, "vcm_gather_positions");
  positionWords_.resize(size_t(vertices) * 4);
  if (vertices)
    FH_CL(dc_.queue.enqueueReadBuffer(positions_, CL_TRUE, 0, positionWords_.size() * 4, positionWords_.data()));
  // A corner below the scene, so cell indices stay small.
  const float lo[3] = {sphere_.s[0] - sphere_.s[3], sphere_.s[1] - sphere_.s[3], sphere_.s[2] - sphere_.s[3]};
  grid_ = buildMergeGrid(positionWords_.data(), counts_.data(), count, maxDepth_, radius, lo);
  gridStarts_ = allocateBuffer(dc_.context, dc_.info.device, CL_MEM_READ_ONLY,
                               grid_.starts.size() * 4, "merging grid cells", grid_.starts.data());
  gridFiled_ = allocateBuffer(dc_.context, dc_.info.device, CL_MEM_READ_ONLY, grid_.filed.size() * 4,
                              "merging grid's vertices", grid_.filed.empty() ? nullptr : grid_.filed.data());
  uint32_t mask = grid_.mask;
  float maskBits;
  std::memcpy(&maskBits, &mask, 4);
  const cl_float4 gridLo{{lo[0], lo[1], lo[2], grid_.inverseCell}};
  const cl_float4 merge{{radius, float(1.0 / eta), maskBits, 0.f}};
  bindAll(kernel_, kernelName_, params_, slot.global, first, count, sphere_, factors, gridLo, merge, lightVertices_,
          storedCounts_, gridStarts_, gridFiled_, filterTable_, slot.splats, slot.tallies, scene_.buffers);
  cl::Event event;
  launch(dc_, kernel_, (count + lanes_ - 1) / lanes_, kernelName_, &event);
  events_.push_back({kernelName_, event});
}

void LightTracer::readCounters() {
  FH_CL(dc_.queue.finish());
  if (cameraPaths_) cameraPaths_->readCounters();
  for (Slot& slot : slots_) {
    if (slot.state != State::Launched) continue;
    slot.state = State::Read;
    stats_.bounceRays += slot.tallyWords[0];
    stats_.shadowRays += slot.tallyWords[1];
    if (bidirectional(method_)) stats_.cameraRays += pixels_;
    stats_.nonfinite += slot.tallyWords[2];
    stats_.iterations += 1;
  }
  for (const auto& [name, event] : events_) {
    cl_ulong start = 0, end = 0;
    FH_CL(event.getProfilingInfo(CL_PROFILING_COMMAND_START, &start));
    FH_CL(event.getProfilingInfo(CL_PROFILING_COMMAND_END, &end));
    stats_.stageSeconds[name] += double(end - start) * 1e-9;
  }
  events_.clear();
}

bool LightTracer::passComplete(uint64_t local) const {
  return slots_[local % kSlots].state == State::Read && (!cameraPaths_ || cameraPaths_->passComplete(local));
}

// Each pixel's three sums of quanta, plus the camera paths' sample where there are any, as
// the pass's sample (rgb, 1).
void LightTracer::takePass(uint64_t local, std::vector<float>& samples) {
  Slot& slot = slots_[local % kSlots];
  if (cameraPaths_) cameraPaths_->takePass(local, samples);
  else samples.assign(size_t(pixels_) * 4, 0.f);
  const uint32_t* words = slot.splatWords.data();
  for (size_t p = 0; p < pixels_; ++p) {
    for (size_t c = 0; c < 3; ++c) {
      const uint64_t quanta = uint64_t(words[kSplatWords * p + 2 * c]) | uint64_t(words[kSplatWords * p + 2 * c + 1]) << 32;
      samples[4 * p + c] += float(double(quanta) * kFilmQuantum);
    }
    samples[4 * p + 3] = 1.f;
  }
  slot.state = State::Free;
}

RenderStats LightTracer::stats() {
  if (!cameraPaths_) return stats_;
  RenderStats st = cameraPaths_->stats();
  st.add(stats_);
  return st;
}

}  // namespace fh
