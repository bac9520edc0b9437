// The light tracer's passes: a launch each, then the splats read back and turned into the
// film's pass samples.
#include "render/light_tracer.h"

#include <algorithm>

#include "base/test_hooks.h"
#include "render/kernel_arguments.h"
#include "render/pixel_filter.h"
#include "render/wavefront.h"

namespace fh {
namespace {

// Per pixel: three 64-bit sums as (low, high) words (kernels/light_paths.h, FH_SPLAT_WORDS).
constexpr size_t kSplatWords = 6;
// bdpt: a light vertex's bytes (kernels/bdpt.cl, FH_BDPT_VERTEX_WORDS float4s), and the most
// a launch's light vertices may take.
constexpr size_t kVertexBytes = 3 * 16;
constexpr size_t kVertexBufferBytes = size_t(32) << 20;

}  // namespace

ProgramSpec lightTracerProgram(Method method, const SceneFeatures& features, const std::string& traversalOptions) {
  const bool bdpt = method == Method::BDPT;
  const int only = testHooks().bdptOnlyLightVertices;
  const std::string strategy = bdpt && only >= 0 ? " -DFH_BDPT_ONLY_S=" + std::to_string(only) + "u" : "";
  return {std::string(bdpt ? "bidirectional path tracer (" : "light tracer (") + methodName(method) +
              features.buildOptions() + strategy + ")",
          {bdpt ? "bdpt.cl" : "light_trace.cl"}, traversalOptions + features.buildOptions() + strategy + " -DFH_LANES=1"};
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
      kernelName_(s.method == Method::BDPT ? "bdpt" : "light_trace") {
  std::vector<float> inverseCdf;
  params_ = renderParams(s, camera, scene_, inverseCdf);
  // The splats weigh by the filter's density where camera rays are offset by its inverse CDF.
  const std::vector<float> density = filterDensity(s.filter, int(params_.filter_table_size));
  density_ = allocateBuffer(dc.context, dc.info.device, CL_MEM_READ_ONLY, density.size() * 4, "filter density",
                            density.data());
  const cl::Program program = buildProgram(dc.context, dc.info.device,
                                           lightTracerProgram(method_, scene_.features, scene_.bvh.traversalOptions()));
  kernel_ = createKernel(program, kernelName_);
  if (method_ == Method::BDPT) {
    filterTable_ = allocateBuffer(dc.context, dc.info.device, CL_MEM_READ_ONLY, inverseCdf.size() * 4,
                                  "filter inverse CDF", inverseCdf.data());
    const size_t perPath = size_t(std::max(s.maxDepth, 1)) * kVertexBytes;
    pathsPerLaunch_ = unsigned(std::min<size_t>(pixels_, std::max<size_t>(kVertexBufferBytes / perPath, 64)));
    lightVertices_ = allocateBuffer(dc.context, dc.info.device, CL_MEM_READ_WRITE, pathsPerLaunch_ * perPath,
                                    "bidirectional light vertices");
    for (size_t k = 0; k < 4; ++k) sphere_.s[k] = scene.lights.boundingSphere[k];
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
  if (method_ == Method::BDPT) {
    for (unsigned first = 0; first < pixels_; first += pathsPerLaunch_) {
      const unsigned count = std::min(pathsPerLaunch_, pixels_ - first);
      bindAll(kernel_, kernelName_, params_, slot.global, first, count, sphere_, lightVertices_, filterTable_, slot.splats,
              density_, slot.tallies, scene_.buffers);
      cl::Event event;
      launch(dc_, kernel_, count, kernelName_, &event);
      events_.push_back(event);
    }
  } else {
    bindAll(kernel_, kernelName_, params_, slot.global, slot.splats, density_, slot.tallies, scene_.buffers);
    cl::Event event;
    launch(dc_, kernel_, pixels_, kernelName_, &event);
    events_.push_back(event);
  }
  FH_CL(dc_.queue.enqueueReadBuffer(slot.splats, CL_FALSE, 0, slot.splatWords.size() * 4, slot.splatWords.data()));
  FH_CL(dc_.queue.enqueueReadBuffer(slot.tallies, CL_FALSE, 0, 12, slot.tallyWords.data()));
  slot.state = State::Launched;
}

void LightTracer::readCounters() {
  FH_CL(dc_.queue.finish());
  if (cameraPaths_) cameraPaths_->readCounters();
  for (Slot& slot : slots_) {
    if (slot.state != State::Launched) continue;
    slot.state = State::Read;
    stats_.bounceRays += slot.tallyWords[0];
    stats_.shadowRays += slot.tallyWords[1];
    if (method_ == Method::BDPT) stats_.cameraRays += pixels_;
    stats_.nonfinite += slot.tallyWords[2];
    stats_.iterations += 1;
  }
  for (const cl::Event& event : events_) {
    cl_ulong start = 0, end = 0;
    FH_CL(event.getProfilingInfo(CL_PROFILING_COMMAND_START, &start));
    FH_CL(event.getProfilingInfo(CL_PROFILING_COMMAND_END, &end));
    stats_.stageSeconds[kernelName_] += double(end - start) * 1e-9;
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
