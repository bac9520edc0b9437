// The pipeline on one device: buffers and kernels set up once, then iterations that are
// nothing but the stages in order.
#include "render/wavefront.h"

#include <algorithm>
#include <cstddef>

#include "render/pixel_filter.h"

namespace fh {
namespace {

constexpr int kFilterTableSize = 256;
// Passes of every pixel in flight at most (each costs a frame of pass buffers).
constexpr size_t kMostFullPasses = 8;

// Sets a kernel's arguments in the order they are given, so no call site counts indices.
class ArgumentList {
 public:
  explicit ArgumentList(cl::Kernel& kernel) : kernel_(kernel) {}
  template <typename T>
  ArgumentList& operator<<(const T& value) {
    FH_CL(kernel_.setArg(next_++, value));
    return *this;
  }
  // Every path-state field, in FH_PATH_FIELDS order: a stage's FH_PATH_PARAMS.
  ArgumentList& operator<<(const PathStateBuffers& p) {
#define FH_ARGUMENT(type, name, bytes) *this << p.name;
    FH_PATH_FIELDS(FH_ARGUMENT)
#undef FH_ARGUMENT
    return *this;
  }
  // Every light-sample request field: FH_SHADOW_PARAMS.
  ArgumentList& operator<<(const ShadowRequestBuffers& r) {
#define FH_ARGUMENT(type, name, bytes) *this << r.name;
    FH_SHADOW_FIELDS(FH_ARGUMENT)
#undef FH_ARGUMENT
    return *this;
  }

 private:
  cl::Kernel& kernel_;
  cl_uint next_ = 0;
};

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

}  // namespace

SceneFeatures featuresFor(const Scene& scene, const RenderSettings& s) {
  SceneFeatures f = s.allFeatures ? SceneFeatures::all() : sceneFeatures(scene);
  f.environmentMap = f.environmentMap || s.envMap;
  return f;
}

ProgramSpec pathTracerProgram(const SceneFeatures& features, Method method, const std::string& traversalOptions,
                              Strategy strategy, bool surfaceAovs) {
  const char* methodFlag = method == Method::PT ? "PT" : method == Method::NEE ? "NEE" : "MIS";
  const bool mega = isMegakernel(strategy);
  return {std::string("path tracer (") + methodName(method) + features.buildOptions() + ", " + strategyName(strategy) +
              (surfaceAovs ? ", aovs" : "") + ")",
          mega ? std::vector<std::string>{stageInfo(Stage::PlanIteration).file, kMegakernel.file} : stageFiles(),
          traversalOptions + features.buildOptions() + " -DFH_METHOD_" + methodFlag +
              " -DFH_LANES=" + std::to_string(lanesOf(strategy)) + (mega ? " -DFH_MEGAKERNEL" : "") +
              (surfaceAovs ? " -DFH_AOVS" : "")};
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
  // GPU: the best of the H200 sweep in bench/RESULTS.md (issue 12); larger wavefronts ran emptier.
  const size_t preferred = device.type == "gpu" ? (size_t(1) << 19) : (size_t(1) << 16);
  return std::max<size_t>(kLocalSize, std::min(preferred, 2 * pixels));
}

WavefrontPipeline::WavefrontPipeline(DeviceContext& dc, const Scene& scene, const Bvh& bvh, const Camera& camera,
                                     const RenderSettings& s)
    : dc_(dc),
      method_(s.method),
      strategy_(strategyFor(dc.info, s.strategy)),
      scene_(dc, scene, bvh, featuresFor(scene, s), s.envMap.get()),
      pixels_(unsigned(s.width) * unsigned(s.height)),
      surfaceAovs_(s.surfaceAovs) {
  // No more paths than the passes in flight can ever hold.
  const size_t most = roundUp(size_t(kMostFullPasses) * pixels_, kLocalSize);
  wavefront_ = std::min(s.wavefront ? s.wavefront : defaultWavefront(dc.info, pixels_), most);
  std::vector<float> filterTable;
  params_ = renderParams(s, camera, scene_, filterTable);
  // Enough passes of every pixel in flight that the wavefront stays full while a pass's
  // longest paths finish: each costs a frame of pass buffers, so only as many as the
  // wavefront needs. Passes of fewer pixels (an adaptive round's) fit more times.
  const size_t fullPasses = std::min<size_t>(kMostFullPasses, 2 + (2 * wavefront_ + pixels_ - 1) / pixels_);
  passEntries_ = fullPasses * pixels_;
  // Global sample numbers are 32 bits: at most spp passes (a time budget stops earlier; an
  // adaptive render's passes cover fewer pixels, and its pool counts them).
  if (uint64_t(std::max(1, s.spp)) * pixels_ >= (uint64_t(1) << 32))
    throw Error("--spp " + std::to_string(s.spp) + " at " + std::to_string(s.width) + "x" + std::to_string(s.height) +
                " is more than 2^32 samples in one render; render fewer");
  passTable_.assign(FH_MAX_PASS_SLOTS, 0);
  everyPixel_ = everyPixel(pixels_);
  passShape_ = {pixels_, 0, 0, uint32_t(fullPasses)};
  counters_.pass_pixels = pixels_;
  counters_.pass_ring = uint32_t(fullPasses);

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
  passTableBuffer_ = buffer(passTable_.size() * 4, "pass table");
  pixelListBuffer_ = buffer(size_t(pixels_) * 4, "pixel list", everyPixel_.data());
}

// Every argument of every stage, for one parity. The argument lists follow the kernels'
// parameter lists in kernels/<stage>.cl.
void WavefrontPipeline::bindArguments(unsigned parity) {
  auto& k = kernels_[parity];
  auto args = [&](Stage s) { return ArgumentList(k[size_t(s)]); };
  const cl::Buffer& rays = queues_.rays[parity];
  const cl::Buffer& nextRays = queues_.rays[1 - parity];
  const DeviceScene& sc = scene_;

  args(Stage::PlanIteration) << queues_.counters << parity;
  args(Stage::FinishIteration) << queues_.counters << parity;
  if (isMegakernel(strategy_)) {
    ArgumentList(megakernels_[parity])
        << params_ << queues_.counters << parity << queues_.freeSlots << filterTable_ << passTableBuffer_
        << pixelListBuffer_ << sc.bvh.nodes() << sc.bvh.blocks() << sc.bvh.triangles() << sc.triangleMaterial
        << sc.materials << sc.lightCdf << sc.lightTriangle << sc.lightPdfArea << sc.normals << sc.uvs << sc.texels
        << sc.textureInfo << sc.environment << passBuffers_ << aovBuffers_ << paths_;
    return;
  }
  args(Stage::Generate) << params_ << queues_.counters << queues_.freeSlots << rays << filterTable_
                        << passTableBuffer_ << pixelListBuffer_ << paths_;
  args(Stage::Intersect) << sc.bvh.nodes() << sc.bvh.blocks() << rays << queues_.counters << parity
                         << paths_.ray_org << paths_.ray_dir << paths_.hit;
  args(Stage::Shade) << params_ << rays << nextRays << queues_.finished << queues_.counters << parity
                     << sc.bvh.triangles() << sc.triangleMaterial << sc.materials << sc.lightPdfArea << sc.normals
                     << sc.uvs << sc.texels << sc.textureInfo << sc.environment << aovBuffers_ << paths_
                     << shadowRequests_;
  args(Stage::ShadowConnect) << params_ << queues_.counters << sc.bvh.nodes() << sc.bvh.blocks()
                             << sc.bvh.triangles() << sc.triangleMaterial << sc.materials << sc.lightCdf
                             << sc.lightTriangle << sc.lightPdfArea << sc.environment << paths_ << shadowRequests_;
  args(Stage::Accumulate) << queues_.finished << queues_.counters << queues_.freeSlots << passBuffers_ << paths_;
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

void WavefrontPipeline::grantPass(uint64_t local, uint32_t global) {
  const size_t entry = size_t(local % passSlots());  // free: its last pass was returned
  passTable_[entry] = global;                       // stable storage: the write is asynchronous
  FH_CL(dc_.queue.enqueueWriteBuffer(passTableBuffer_, CL_FALSE, entry * 4, 4, &passTable_[entry]));
}

void WavefrontPipeline::setPassPixels(std::shared_ptr<const PixelList> pixels, uint64_t granted) {
  passPixels_ = std::move(pixels);
  const std::vector<uint32_t>& list = passPixels_ ? *passPixels_ : everyPixel_;
  if (list.empty() || list.size() > pixels_) throw Error("internal: a pass of no pixels, or of too many");
  // Nothing is in flight: every sample granted so far has started (sampleLimit_).
  const size_t ring = std::min<size_t>(FH_MAX_PASS_SLOTS, passEntries_ / list.size());
  passShape_ = {uint32_t(list.size()), sampleLimit_, uint32_t(granted), uint32_t(ring)};
  FH_CL(dc_.queue.enqueueWriteBuffer(pixelListBuffer_, CL_FALSE, 0, list.size() * 4, list.data()));
  FH_CL(dc_.queue.enqueueWriteBuffer(queues_.counters, CL_FALSE, offsetof(gpu::WavefrontCounters, pass_pixels),
                                     sizeof passShape_, passShape_.data()));
}

void WavefrontPipeline::startGrantedPasses(uint64_t granted) {
  // sampleLimit_ is the source of an asynchronous write: it is set once per batch, after the
  // previous batch's write has completed (readCounters waits for the queue).
  sampleLimit_ = passShape_[1] + uint32_t(granted - passShape_[2]) * passShape_[0];
  writeCounter(offsetof(gpu::WavefrontCounters, sample_limit), sampleLimit_);
}

const gpu::WavefrontCounters& WavefrontPipeline::readCounters() {
  FH_CL(dc_.queue.enqueueReadBuffer(queues_.counters, CL_TRUE, 0, sizeof counters_, &counters_));
  for (const auto& [kernel, event] : events_) {
    cl_ulong start = 0, end = 0;
    FH_CL(event.getProfilingInfo(CL_PROFILING_COMMAND_START, &start));
    FH_CL(event.getProfilingInfo(CL_PROFILING_COMMAND_END, &end));
    stageSeconds_[kernel] += double(end - start) * 1e-9;
  }
  events_.clear();
  return counters_;
}

bool WavefrontPipeline::passComplete(uint64_t local) const {
  return counters_.pass_done[local % passSlots()] == passShape_[0];
}

void WavefrontPipeline::takePass(uint64_t local, std::vector<float>& samples) {
  const size_t slot = size_t(local % passSlots()), count = passShape_[0];
  const size_t aovFloats = surfaceAovs_ ? kAovFloatsPerPixel : 0;
  samples.resize(count * (4 + aovFloats));
  if (aovFloats)
    FH_CL(dc_.queue.enqueueReadBuffer(aovBuffers_, CL_FALSE, slot * count * aovFloats * 4, count * aovFloats * 4,
                                      samples.data() + count * 4));
  FH_CL(dc_.queue.enqueueReadBuffer(passBuffers_, CL_TRUE, slot * count * 16, count * 16, samples.data()));
  // Safe to reset: the next pass using this slot has not been granted yet.
  static const uint32_t zero = 0;
  writeCounter(offsetof(gpu::WavefrontCounters, pass_done) + slot * 4, zero);
  counters_.pass_done[slot] = 0;
}

RenderStats WavefrontPipeline::stats() {
  auto total64 = [](const uint32_t* pair) { return uint64_t(pair[0]) | uint64_t(pair[1]) << 32; };
  RenderStats st;
  st.cameraRays = counters_.next_sample;
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
