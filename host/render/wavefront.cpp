// The pipeline on one device: buffers and kernels set up once, then iterations that are
// nothing but the stages in order.
#include "render/wavefront.h"

#include <algorithm>
#include <cstddef>

#include "base/test_hooks.h"
#include "render/kernel_arguments.h"
#include "render/pixel_filter.h"

namespace fh {
namespace {

constexpr int kFilterTableSize = 256;
// Passes of every pixel in flight at most (each costs a frame of pass buffers).
constexpr size_t kMostFullPasses = 8;

}  // namespace

gpu::RenderParams renderParams(const RenderSettings& s, const Camera& camera, const DeviceScene& scene,
                               std::vector<float>& filterTable) {
  gpu::RenderParams p{};
  p.camera = makeCameraParams(camera, s.width, s.height);
  for (size_t c = 0; c < 3; ++c) p.env[c] = s.env[c];
  p.seed = s.seed;
  p.pixel_count = unsigned(s.width) * unsigned(s.height);
  p.max_depth = unsigned(s.maxDepth);
  p.rr_depth = unsigned(s.rrDepth);
  p.light_count = scene.lightCount;
  p.replicates = s.replicates();
  p.env_width = unsigned(scene.environmentWidth);
  p.env_height = unsigned(scene.environmentHeight);
  p.env_u_shift = scene.environmentUShift;
  p.env_pick = scene.environmentPick;
  filterTable = filterInverseCdf(s.filter, kFilterTableSize, &p.filter_radius);
  p.filter_table_size = unsigned(filterTable.size());
  return p;
}

SceneFeatures featuresFor(const Scene& scene, const RenderSettings& s) {
  SceneFeatures f = s.allFeatures ? SceneFeatures::all() : sceneFeatures(scene);
  f.environmentMap = f.environmentMap || s.envMap;
  return f;
}

ProgramSpec pathTracerProgram(const SceneFeatures& features, Method method, const std::string& traversalOptions,
                              Strategy strategy, bool surfaceAovs) {
  // Light tracing's camera paths are mis paths that leave their first vertex by a delta lobe.
  const char* methodFlag = method == Method::PT    ? "PT"
                           : method == Method::NEE ? "NEE"
                           : method == Method::LT  ? "MIS -DFH_LIGHT_TRACED_FIRST_VERTEX"
                                                   : "MIS";
  const bool mega = isMegakernel(strategy);
  return {std::string("path tracer (") + methodName(method) + features.buildOptions() + ", " + strategyName(strategy) +
              (surfaceAovs ? ", aovs" : "") + ")",
          mega ? std::vector<std::string>{stageInfo(Stage::PlanIteration).file, kMegakernel.file} : stageFiles(),
          traversalOptions + features.buildOptions() + " -DFH_METHOD_" + methodFlag +
              " -DFH_LANES=" + std::to_string(lanesOf(strategy)) + (mega ? " -DFH_MEGAKERNEL" : "") +
              (surfaceAovs ? " -DFH_AOVS" : "") + (testHooks().everyShareNarrow ? " -DFH_NARROW_SHARE=2.0f" : "")};
}

Strategy strategyFor(const DeviceInfo& device, Strategy asked) {
  if (asked != Strategy::Auto) return asked;
  // A CPU's caches favour one kernel that keeps each path's state close from stage to stage;
  // a GPU hides memory latency with many paths and favours short, uniform kernels.
  return device.type == "cpu" ? Strategy::Megakernel8 : Strategy::Scalar;
}

unsigned lanesOf(Strategy s) { return s == Strategy::Simd8 || s == Strategy::Megakernel8 ? 8 : 1; }

bool isMegakernel(Strategy s) { return s == Strategy::Megakernel || s == Strategy::Megakernel8; }

// The books (plan, finish) run under every strategy; the megakernel calls the other stages.
bool WavefrontPipeline::launches(Stage s) const {
  return !isMegakernel(strategy_) || s == Stage::PlanIteration || s == Stage::FinishIteration;
}

size_t defaultWavefront(const DeviceInfo& device, size_t pixels) {
  // GPU: the best of the H200 sweep (bench/history/gpu.md); larger wavefronts ran emptier.
  const size_t preferred = device.type == "gpu" ? (size_t(1) << 19) : (size_t(1) << 16);
  return std::max<size_t>(kLocalSize, std::min(preferred, 2 * pixels));
}

WavefrontPipeline::WavefrontPipeline(DeviceContext& dc, const PreparedScene& scene, const Bvh& bvh,
                                     const Camera& camera, const RenderSettings& s)
    : dc_(dc),
      method_(s.method),
      strategy_(strategyFor(dc.info, s.strategy)),
      scene_(dc, scene, bvh),
      pixels_(unsigned(s.width) * unsigned(s.height)),
      surfaceAovs_(s.surfaceAovs),
      listsPixels_(s.adaptive) {
  // No more paths than the passes in flight can ever hold.
  const size_t most = roundUp(size_t(kMostFullPasses) * pixels_, kLocalSize);
  wavefront_ = std::min(s.wavefront ? s.wavefront : defaultWavefront(dc.info, pixels_), most);
  std::vector<float> filterTable;
  params_ = renderParams(s, camera, scene_, filterTable);
  // Enough passes of every pixel in flight that the wavefront stays full while a pass's
  // longest paths finish: each costs a frame of pass buffers, so only as many as the
  // wavefront needs. Passes of fewer pixels (an adaptive round's) fit more times.
  size_t fullPasses = std::min<size_t>(kMostFullPasses, 2 + (2 * wavefront_ + pixels_ - 1) / pixels_);
  // A megakernel launch ends every path it starts: no long paths outlive it, and a pass is
  // returned at the end of the batch that starts its last samples. Where a pass outlasts a
  // batch of launches, the pass after it keeps the device fed until then, and two passes
  // of entries do (a 4K frame of pass buffers less, 133 MB).
  if (isMegakernel(strategy_) &&
      pixels_ >= size_t(kIterationsPerBatch) * FH_MEGAKERNEL_SAMPLES_PER_SLOT * wavefront_)
    fullPasses = 2;
  // A path's pass_entry holds its entry times FH_MAX_PASS_SLOTS in 32 bits.
  const size_t mostEntries = (size_t(1) << 32) / FH_MAX_PASS_SLOTS;
  if (pixels_ > mostEntries)
    throw Error(std::to_string(s.width) + "x" + std::to_string(s.height) + " is more than " +
                std::to_string(mostEntries) + " pixels; render a smaller image");
  passEntries_ = std::min(fullPasses * pixels_, mostEntries / pixels_ * pixels_);
  // A few rings of pass entries: far below 2^31 (passEntries_ is at most 2^26), and far
  // above the samples in flight, so that every sample of the older shape has started by the
  // time the newer one outgrows its span (no wait for a new shape of the same pixels).
  shapeSpan_ = 4 * uint64_t(passEntries_);
  passes_.assign(FH_MAX_PASS_SLOTS, {});
  shapes_[0] = shapes_[1] = {pixels_, uint32_t(kFirstLocalSample), 0, FH_EVERY_PIXEL};
  std::copy(shapes_.begin(), shapes_.end(), counters_.shapes);
  counters_.next_sample = counters_.sample_limit = uint32_t(kFirstLocalSample);
  counters_.pass_entries = uint32_t(passEntries_);

  const cl::Program program = buildProgram(
      dc.context, dc.info.device, pathTracerProgram(scene_.features, s.method, scene_.bvh.traversalOptions(),
                                                         strategy_, surfaceAovs_));
  // The megakernel's program holds only the books' kernels besides its own: its stages are
  // functions it calls (a kernel per stage would double PoCL's compile time for nothing).
  for (auto& kernels : kernels_)
    for (size_t i = 0; i < kStages.size(); ++i)
      if (launches(Stage(i))) kernels[i] = createKernel(program, kStages[i].kernel);
  if (isMegakernel(strategy_))
    for (auto& k : megakernels_) k = createKernel(program, kMegakernel.kernel);
  allocateBuffers(filterTable);
  bindArguments(0);
  bindArguments(1);
}

void WavefrontPipeline::allocateBuffers(const std::vector<float>& filterTable) {
  auto buffer = [&](size_t bytes, const char* what, const void* host = nullptr) {
    return allocateBuffer(dc_.context, dc_.info.device, CL_MEM_READ_WRITE, bytes, what, host);
  };
#define FH_ALLOCATE(type, name, bytes) paths_.name = buffer(wavefront_ * (bytes), "path state " #name);
  FH_PATH_FIELDS(FH_ALLOCATE)
#undef FH_ALLOCATE
#define FH_ALLOCATE(type, name, bytes) shadowRequests_.name = buffer(wavefront_ * (bytes), #name);
  FH_SHADOW_FIELDS(FH_ALLOCATE)
#undef FH_ALLOCATE
  for (auto& q : queues_.rays) q = buffer(wavefront_ * 4, "ray queue");
  queues_.finished = buffer(wavefront_ * 4, "finished queue");
  std::vector<unsigned> allFree(wavefront_);
  for (size_t i = 0; i < wavefront_; ++i) allFree[i] = unsigned(i);
  queues_.freeSlots = buffer(wavefront_ * 4, "free list", allFree.data());
  counters_.free_length = unsigned(wavefront_);
  queues_.counters = buffer(sizeof counters_, "queue counters", &counters_);
  // Every sample of a pass writes its entries (radiance; first-surface layers at its first
  // vertex): no clearing needed.
  passBuffers_ = buffer(passEntries_ * 16, "pass buffers");
  aovBuffers_ = buffer(surfaceAovs_ ? passEntries_ * kAovFloatsPerPixel * 4 : 16, "AOV buffers");
  filterTable_ = allocateBuffer(dc_.context, dc_.info.device, CL_MEM_READ_ONLY, filterTable.size() * 4,
                                "filter table", filterTable.data());
  passTableBuffer_ = buffer(FH_MAX_PASS_SLOTS * sizeof(PassInFlight::table), "pass table");
  // Two shapes' lists in a half each, then their sequence offsets (written by newShape).
  pixelListBuffer_ = buffer(listsPixels_ ? 4 * size_t(pixels_) * 4 : 16, "pixel lists");
}

// Every argument of every stage, for one parity. The argument lists follow the kernels'
// parameter lists in kernels/<stage>.cl.
void WavefrontPipeline::bindArguments(unsigned parity) {
  auto& k = kernels_[parity];
  const cl::Buffer& rays = queues_.rays[parity];
  const cl::Buffer& nextRays = queues_.rays[1 - parity];
  const SceneBuffers& scene = scene_.buffers;

  auto bind = [&](Stage stage, const auto&... values) {
    bindAll(k[size_t(stage)], stageInfo(stage).kernel, values...);
  };
  bind(Stage::PlanIteration, queues_.counters, parity);
  bind(Stage::FinishIteration, queues_.counters, parity);
  if (isMegakernel(strategy_)) {
    bindAll(megakernels_[parity], kMegakernel.kernel, params_, queues_.counters, parity, queues_.freeSlots,
            filterTable_, passTableBuffer_, pixelListBuffer_, scene, passBuffers_, aovBuffers_, paths_);
    return;
  }
  bind(Stage::Generate, params_, queues_.counters, queues_.freeSlots, rays, filterTable_, passTableBuffer_,
       pixelListBuffer_, paths_);
  bind(Stage::Intersect, scene.nodes, scene.blocks, rays, queues_.counters, parity, paths_.ray_org, paths_.ray_dir,
       paths_.hit);
  bind(Stage::Shade, params_, rays, nextRays, queues_.finished, queues_.counters, parity, scene, aovBuffers_, paths_,
       shadowRequests_);
  bind(Stage::ShadowConnect, params_, queues_.counters, scene, paths_, shadowRequests_);
  bind(Stage::Accumulate, queues_.finished, queues_.counters, queues_.freeSlots, passBuffers_, paths_);
}

// Each stage is launched over the whole wavefront and reads its queue's length on the
// device, so nothing here waits for the device.
void WavefrontPipeline::enqueueIteration() {
  planIteration();
  if (isMegakernel(strategy_)) {
    megakernel();
  } else {
    generate();
    intersect();
    shade();
    if (method_ != Method::PT && scene_.hasLights()) shadowConnect();
    accumulate();
  }
  finishIteration();
  parity_ = 1 - parity_;
}

void WavefrontPipeline::megakernel() {
  cl::Event event;
  launch(dc_, megakernels_[parity_], laneItems(), kMegakernel.kernel, &event);
  events_.emplace_back(kMegakernel.kernel, event);
}

void WavefrontPipeline::run(Stage stage, size_t items) {
  cl::Event event;
  launch(dc_, kernels_[parity_][size_t(stage)], items, stageInfo(stage).kernel, &event);
  events_.emplace_back(stageInfo(stage).kernel, event);
}

void WavefrontPipeline::writeCounter(size_t offset, const uint32_t& value) {
  FH_CL(dc_.queue.enqueueWriteBuffer(queues_.counters, CL_FALSE, offset, 4, &value));
}

bool WavefrontPipeline::fits(const std::shared_ptr<const RoundPixels>& pixels, uint64_t granted,
                             uint64_t returned) const {
  if (granted - returned >= FH_MAX_PASS_SLOTS) return false;
  const uint32_t size = pixels ? uint32_t(pixels->pixels.size()) : pixels_;
  // The pass buffers are a ring of entries in local sample order, from the oldest pass's.
  const uint64_t oldest = granted == returned ? grantedSamples_ : passes_[returned % FH_MAX_PASS_SLOTS].firstSample;
  if (grantedSamples_ - oldest + size > passEntries_) return false;
  // A new shape (of other pixels, or of the same ones once the newer shape outgrows its
  // span) replaces the older one: all its samples must have started (as of the last
  // readCounters).
  return (pixels == shapePixels_[1] && !outgrowsShape(size)) || startedSamples_ >= shapeStart_;
}

void WavefrontPipeline::grantPass(uint64_t local, uint32_t global, std::shared_ptr<const RoundPixels> pixels) {
  const uint32_t size = pixels ? uint32_t(pixels->pixels.size()) : pixels_;
  if (pixels != shapePixels_[1] || outgrowsShape(size)) newShape(std::move(pixels), local);
  const size_t slot = size_t(local % FH_MAX_PASS_SLOTS);  // free: its last pass was returned
  passes_[slot] = {grantedSamples_, shapes_[1].pixels, {global, uint32_t(grantedSamples_ % passEntries_)}};
  grantedSamples_ += shapes_[1].pixels;
  FH_CL(dc_.queue.enqueueWriteBuffer(passTableBuffer_, CL_FALSE, slot * sizeof passes_[slot].table,
                                     sizeof passes_[slot].table, passes_[slot].table));
}

// The newer shape becomes the older, and local pass `local` on is of the new one, whose
// pixel list (if it lists pixels) takes the half of the pixel-list buffer the newer does not
// have (the older's, whose samples have all started); or, for a new shape of the newer's own
// pixels (it outgrew its span), the newer's.
void WavefrontPipeline::newShape(std::shared_ptr<const RoundPixels> pixels, uint64_t local) {
  uint32_t size = pixels_, list = FH_EVERY_PIXEL;
  if (pixels) {
    size = uint32_t(pixels->pixels.size());
    if (!listsPixels_ || size == 0 || size > pixels_ || pixels->offsets.size() != size)
      throw Error("internal: a pass of no pixels, of too many, without an offset for each, or not adaptive");
    if (pixels == shapePixels_[1]) {
      list = shapes_[1].list;
    } else {
      const size_t half = shapes_[1].list == pixels_ ? 0 : 1;
      lists_[half] = pixels->pixels;  // stable storage for the writes
      offsets_[half] = pixels->offsets;
      FH_CL(dc_.queue.enqueueWriteBuffer(pixelListBuffer_, CL_FALSE, half * pixels_ * 4, size_t(size) * 4,
                                         lists_[half].data()));
      FH_CL(dc_.queue.enqueueWriteBuffer(pixelListBuffer_, CL_FALSE, (2 + half) * pixels_ * 4, size_t(size) * 4,
                                         offsets_[half].data()));
      list = uint32_t(half * pixels_);
    }
  }
  shapes_[0] = shapes_[1];
  shapes_[1] = {size, uint32_t(grantedSamples_), uint32_t(local), list};
  shapeStart_ = grantedSamples_;
  shapePixels_[0] = std::move(shapePixels_[1]);
  shapePixels_[1] = std::move(pixels);
  FH_CL(dc_.queue.enqueueWriteBuffer(queues_.counters, CL_FALSE, offsetof(gpu::WavefrontCounters, shapes),
                                     sizeof shapes_, shapes_.data()));
}

void WavefrontPipeline::startGrantedPasses() {
  // sampleLimit_ is the source of an asynchronous write: it is set once per batch, after the
  // previous batch's write has completed (readCounters waits for the queue).
  sampleLimit_ = uint32_t(grantedSamples_);
  writeCounter(offsetof(gpu::WavefrontCounters, sample_limit), sampleLimit_);
}

void WavefrontPipeline::readCounters() {
  FH_CL(dc_.queue.enqueueReadBuffer(queues_.counters, CL_TRUE, 0, sizeof counters_, &counters_));
  startedSamples_ += uint32_t(counters_.next_sample - uint32_t(startedSamples_));  // its low 32 bits, which wrap
  for (const auto& [kernel, event] : events_) {
    cl_ulong start = 0, end = 0;
    FH_CL(event.getProfilingInfo(CL_PROFILING_COMMAND_START, &start));
    FH_CL(event.getProfilingInfo(CL_PROFILING_COMMAND_END, &end));
    stageSeconds_[kernel] += double(end - start) * 1e-9;
  }
  events_.clear();
}

bool WavefrontPipeline::passComplete(uint64_t local) const {
  const PassInFlight& pass = passes_[local % FH_MAX_PASS_SLOTS];
  return counters_.pass_done[local % FH_MAX_PASS_SLOTS] == pass.pixels;
}

void WavefrontPipeline::takePass(uint64_t local, std::vector<float>& samples) {
  const size_t slot = size_t(local % FH_MAX_PASS_SLOTS), count = passes_[slot].pixels;
  const size_t aovFloats = surfaceAovs_ ? kAovFloatsPerPixel : 0;
  samples.resize(count * (4 + aovFloats));
  // Its entries, from its first sample's on, in two runs where the ring wraps.
  const size_t first = passes_[slot].table[1], before = std::min(count, passEntries_ - first);
  const std::array<std::array<size_t, 3>, 2> runs{{{first, 0, before}, {0, before, count - before}}};
  for (const auto& [entry, index, length] : runs) {
    if (length == 0) continue;
    if (aovFloats)
      FH_CL(dc_.queue.enqueueReadBuffer(aovBuffers_, CL_FALSE, entry * aovFloats * 4, length * aovFloats * 4,
                                        samples.data() + (count * 4 + index * aovFloats)));
    FH_CL(dc_.queue.enqueueReadBuffer(passBuffers_, CL_FALSE, entry * 16, length * 16, samples.data() + index * 4));
  }
  FH_CL(dc_.queue.finish());
  // Safe to reset: the next pass using this slot has not been granted yet.
  static const uint32_t zero = 0;
  writeCounter(offsetof(gpu::WavefrontCounters, pass_done) + slot * 4, zero);
  counters_.pass_done[slot] = 0;
}

RenderStats WavefrontPipeline::stats() {
  auto total64 = [](const uint32_t* pair) { return uint64_t(pair[0]) | uint64_t(pair[1]) << 32; };
  RenderStats st;
  st.cameraRays = startedSamples_ - kFirstLocalSample;
  st.bounceRays = total64(counters_.bounce_rays);
  st.shadowRays = total64(counters_.shadow_rays);
  st.iterations = counters_.iterations;
  st.nonfinite = counters_.nonfinite;
  st.wavefront = wavefront_;
  st.queuedRays = total64(counters_.queued_rays);
  st.slotIterations = st.iterations * wavefront_;
  st.stageSeconds = stageSeconds_;
  return st;
}

}  // namespace fh
