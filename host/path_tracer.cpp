// The host side of the wavefront path tracer: it reads like the pipeline it drives.
#include "path_tracer.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include <nlohmann/json.hpp>

#include "../kernels/path_state.h"
#include "render_aov.h"

namespace fh {
namespace {

using Clock = std::chrono::steady_clock;
constexpr int kFilterTableSize = 256;

// Sets the path-state buffers as a kernel's trailing arguments, in FH_PATH_FIELDS order.
void setPathArgs(cl::Kernel& kernel, cl_uint first, const std::vector<cl::Buffer>& state) {
  for (size_t i = 0; i < state.size(); ++i) FH_CL(kernel.setArg(first + cl_uint(i), state[i]));
}

double filterValue(PixelFilter f, double x, double radius) {
  switch (f) {
    case PixelFilter::Box:
      return 1.0;
    case PixelFilter::Gaussian: {  // sigma 0.5, shifted to reach zero at the radius
      const double sigma = 0.5;
      return std::max(0.0, std::exp(-x * x / (2 * sigma * sigma)) - std::exp(-radius * radius / (2 * sigma * sigma)));
    }
    case PixelFilter::BlackmanHarris: {
      const double t = (x + radius) / (2.0 * radius);  // 0..1 over the support
      return 0.35875 - 0.48829 * std::cos(2 * M_PI * t) + 0.14128 * std::cos(4 * M_PI * t) -
             0.01168 * std::cos(6 * M_PI * t);
    }
  }
  return 1.0;
}

}  // namespace

Method parseMethod(const std::string& name) {
  if (name == "pt") return Method::PT;
  if (name == "nee") return Method::NEE;
  if (name == "mis") return Method::MIS;
  throw Error("--method '" + name + "': unknown method (use pt, nee or mis)");
}

const char* methodName(Method m) { return m == Method::PT ? "pt" : m == Method::NEE ? "nee" : "mis"; }

PixelFilter parseFilter(const std::string& name) {
  if (name == "box") return PixelFilter::Box;
  if (name == "gaussian") return PixelFilter::Gaussian;
  if (name == "blackman-harris") return PixelFilter::BlackmanHarris;
  throw Error("--filter '" + name + "': unknown filter (use box, gaussian or blackman-harris)");
}

const char* filterName(PixelFilter f) {
  return f == PixelFilter::Box ? "box" : f == PixelFilter::Gaussian ? "gaussian" : "blackman-harris";
}

std::vector<float> filterInverseCdf(PixelFilter filter, int size, float* radius) {
  const double r = filter == PixelFilter::Box ? 0.5 : filter == PixelFilter::Gaussian ? 1.5 : 2.0;
  *radius = float(r);
  // Integrate the filter finely, then invert the CDF at `size` evenly spaced values.
  const int steps = 4096;
  std::vector<double> cdf(steps + 1, 0.0);
  for (int i = 0; i < steps; ++i) {
    const double x = -r + (i + 0.5) * 2 * r / steps;
    cdf[size_t(i) + 1] = cdf[size_t(i)] + filterValue(filter, x, r);
  }
  std::vector<float> table(static_cast<size_t>(size));
  for (int j = 0; j < size; ++j) {
    const double target = cdf.back() * j / (size - 1);
    const auto it = std::lower_bound(cdf.begin(), cdf.end(), target);
    const size_t i = size_t(std::max<std::ptrdiff_t>(1, it - cdf.begin()));
    const double f = (target - cdf[i - 1]) / std::max(cdf[i] - cdf[i - 1], 1e-300);
    table[size_t(j)] = float(-r + (double(i - 1) + std::clamp(f, 0.0, 1.0)) * 2 * r / steps);
  }
  return table;
}

Image Film::image() const {
  Image img;
  img.width = width;
  img.height = height;
  img.rgb.resize(size_t(width) * size_t(height) * 3);
  for (size_t p = 0; p < size_t(width) * size_t(height); ++p)
    for (size_t c = 0; c < 3; ++c) img.rgb[3 * p + c] = sum[4 * p + 3] > 0.f ? sum[4 * p + c] / sum[4 * p + 3] : 0.f;
  return img;
}

std::array<double, 3> Film::varianceOfMean(size_t p) const {
  const double n = sum[4 * p + 3];
  std::array<double, 3> v{0, 0, 0};
  if (n < 2) return v;
  for (size_t c = 0; c < 3; ++c) {
    const double mean = sum[4 * p + c] / n;
    const double sampleVariance = std::max(0.0, (sumSq[4 * p + c] - n * mean * mean) / (n - 1));
    v[c] = sampleVariance / n;
  }
  return v;
}

nlohmann::json devicesJson(const RenderStats& st) {
  if (st.devices.empty())
    return nlohmann::json::array({{{"name", st.device},
                                   {"samples", st.samples},
                                   {"samples_per_second", st.seconds > 0 ? double(st.samples) / st.seconds : 0.0},
                                   {"share", 1.0},
                                   {"idle_seconds", 0.0}}});
  nlohmann::json list = nlohmann::json::array();
  for (const auto& d : st.devices) {
    nlohmann::json entry = {{"name", d.name},
                            {"samples", d.samples},
                            {"samples_per_second", d.busySeconds > 0 ? double(d.samples) / d.busySeconds : 0.0},
                            {"share", st.samples ? double(d.samples) / double(st.samples) : 0.0},
                            {"busy_seconds", d.busySeconds},
                            {"idle_seconds", d.idleSeconds}};
    if (!d.error.empty()) entry["error"] = d.error;
    list.push_back(entry);
  }
  return list;
}

std::string statsJson(const RenderStats& st, const RenderSettings& s) {
  nlohmann::json kernels = nlohmann::json::object();
  double kernelTotal = 0.0;
  for (const auto& [name, seconds] : st.kernelSeconds) kernelTotal += seconds;
  for (const auto& [name, seconds] : st.kernelSeconds)
    kernels[name] = {{"seconds", seconds}, {"share", kernelTotal > 0 ? seconds / kernelTotal : 0.0}};
  const uint64_t rays = st.cameraRays + st.bounceRays + st.shadowRays;
  nlohmann::json doc = {
      {"samples", st.samples},
      {"seconds", st.seconds},
      {"samples_per_second", st.seconds > 0 ? double(st.samples) / st.seconds : 0.0},
      {"nonfinite_samples", st.nonfinite},
      {"devices", devicesJson(st)},
      {"method", methodName(s.method)},
      {"width", s.width},
      {"height", s.height},
      {"spp", s.width * s.height > 0 ? double(st.samples) / (double(s.width) * s.height) : 0.0},
      {"seed", s.seed},
      {"max_depth", s.maxDepth},
      {"filter", filterName(s.filter)},
      {"wavefront", st.wavefront},
      {"iterations", st.iterations},
      {"queue_occupancy", st.meanQueueOccupancy},
      {"rays", {{"camera", st.cameraRays}, {"bounce", st.bounceRays}, {"shadow", st.shadowRays}, {"total", rays}}},
      {"rays_per_second", st.seconds > 0 ? double(rays) / st.seconds : 0.0},
      {"kernels", kernels}};
  return doc.dump(2);
}

ProgramSpec pathTracerProgram(const SceneFeatures& features, Method method, unsigned passSlots,
                              const std::string& traversalOptions) {
  const char* methodFlag = method == Method::PT ? "PT" : method == Method::NEE ? "NEE" : "MIS";
  return {std::string("path tracer (") + methodName(method) + features.buildOptions() + ")",
          {"generate.cl", "intersect.cl", "shade.cl", "shadow_connect.cl", "accumulate.cl"},
          traversalOptions + features.buildOptions() + " -DFH_PASS_SLOTS=" + std::to_string(passSlots) +
              " -DFH_METHOD_" + methodFlag};
}

size_t defaultWavefront(const DeviceInfo& device, size_t pixels) {
  // GPU: the best of the H200 sweep in bench/RESULTS.md (issue 12); larger wavefronts ran emptier.
  const size_t preferred = device.type == "gpu" ? (size_t(1) << 19) : (size_t(1) << 16);
  return std::max<size_t>(kLocalSize, std::min(preferred, 2 * pixels));
}

PathTracer::PathTracer(DeviceContext& dc, const Scene& scene, const Bvh& bvh, const Camera& camera,
                       const RenderSettings& s)
    : dc_(dc), settings_(s), scene_(dc, scene, bvh, s.allFeatures ? SceneFeatures::all() : sceneFeatures(scene)) {
  if (s.width <= 0 || s.height <= 0) throw Error("--width/--height must be positive");
  pixels_ = unsigned(s.width) * unsigned(s.height);
  wavefront_ = s.wavefront ? s.wavefront : defaultWavefront(dc.info, pixels_);

  params_.camera = makeCameraParams(camera, s.width, s.height);
  for (size_t c = 0; c < 3; ++c) params_.env[c] = s.env[c];
  params_.seed = s.seed;
  params_.pixel_count = pixels_;
  params_.max_depth = unsigned(s.maxDepth);
  params_.rr_depth = unsigned(s.rrDepth);
  params_.light_count = scene_.lightCount;
  const std::vector<float> table = filterInverseCdf(s.filter, kFilterTableSize, &params_.filter_radius);
  params_.filter_table_size = unsigned(table.size());

  // Enough passes in flight that the wavefront stays full while a pass's longest paths
  // finish: pass buffers cost a frame each, so only as many as the wavefront needs.
  passSlots_ = unsigned(std::min<size_t>(FH_MAX_PASS_SLOTS, 2 + (2 * wavefront_ + pixels_ - 1) / pixels_));
  const cl::Program program = buildProgram(
      dc.context, dc.info.device,
      pathTracerProgram(scene_.features, s.method, passSlots_, scene_.caster.traversalOptions()));
  plan_ = createKernel(program, "plan_iteration");
  generate_ = createKernel(program, "generate_paths");
  intersect_ = createKernel(program, "intersect_paths");
  shade_ = createKernel(program, "shade");
  shadowConnect_ = createKernel(program, "shadow_connect");
  accumulatePaths_ = createKernel(program, "accumulate_paths");
  finish_ = createKernel(program, "finish_iteration");
  accumulatePass_ = createKernel(program, "accumulate_pass");

  auto buffer = [&](size_t bytes, const char* what, const void* host = nullptr) {
    return allocateBuffer(dc.context, dc.info.device, CL_MEM_READ_WRITE, bytes, what, host);
  };
#define FH_ALLOCATE_FIELD(type, name, bytes) pathState_.push_back(buffer(wavefront_ * (bytes), "path state " #name));
  FH_PATH_FIELDS(FH_ALLOCATE_FIELD)
#undef FH_ALLOCATE_FIELD
#define FH_ALLOCATE_FIELD(type, name, bytes) shadowRequests_.push_back(buffer(wavefront_ * (bytes), #name));
  FH_SHADOW_FIELDS(FH_ALLOCATE_FIELD)
#undef FH_ALLOCATE_FIELD
  for (auto& q : rayQueue_) q = buffer(wavefront_ * 4, "ray queue");
  finishedQueue_ = buffer(wavefront_ * 4, "finished queue");
  std::vector<unsigned> allFree(wavefront_);
  for (size_t i = 0; i < wavefront_; ++i) allFree[i] = unsigned(i);
  freeList_ = buffer(wavefront_ * 4, "free list", allFree.data());
  counters_ = buffer(FH_COUNT_TOTAL * 4, "queue counters");
  passBuffer_ = buffer(size_t(passSlots_) * pixels_ * 16, "pass buffers");
  filmSum_ = buffer(size_t(pixels_) * 16, "film");
  filmSumSq_ = buffer(size_t(pixels_) * 16, "film squares");
  filterTable_ = allocateBuffer(dc.context, dc.info.device, CL_MEM_READ_ONLY, table.size() * 4, "filter table",
                                table.data());
  // Every pass this device may render: at most spp of them (a time budget stops earlier).
  const uint64_t maxPasses = uint64_t(std::max(1, s.spp));
  if (maxPasses * pixels_ >= (uint64_t(1) << 32))
    throw Error("--spp " + std::to_string(s.spp) + " at " + std::to_string(s.width) + "x" + std::to_string(s.height) +
                " is more than 2^32 samples in one render; render fewer");
  passTable_host_.assign(maxPasses, 0);
  passTable_ = buffer(maxPasses * 4, "pass table");
  FH_CL(dc.queue.enqueueFillBuffer(passBuffer_, 0u, 0, size_t(passSlots_) * pixels_ * 16));
  FH_CL(dc.queue.enqueueFillBuffer(filmSum_, 0u, 0, size_t(pixels_) * 16));
  FH_CL(dc.queue.enqueueFillBuffer(filmSumSq_, 0u, 0, size_t(pixels_) * 16));
  FH_CL(dc.queue.enqueueFillBuffer(counters_, 0u, 0, FH_COUNT_TOTAL * 4));
}

void PathTracer::timeKernel(const char* name, const cl::Event& event) {
  cl_ulong start = 0, end = 0;
  FH_CL(event.getProfilingInfo(CL_PROFILING_COMMAND_START, &start));
  FH_CL(event.getProfilingInfo(CL_PROFILING_COMMAND_END, &end));
  stats_.kernelSeconds[name] += double(end - start) * 1e-9;
}

// One wavefront iteration over every path in flight: the five stages in order, framed
// by the device's bookkeeping. Each stage is launched over the whole wavefront and reads
// its queue's length on the device, so nothing here waits for the device.
void PathTracer::enqueueIteration(int current) {
  const cl_uint rays = current == 0 ? FH_COUNT_RAYS_A : FH_COUNT_RAYS_B;
  const cl_uint nextRays = current == 0 ? FH_COUNT_RAYS_B : FH_COUNT_RAYS_A;
  const cl::Buffer& queue = rayQueue_[current];
  const cl::Buffer& nextQueue = rayQueue_[1 - current];
  auto run = [&](cl::Kernel& k, size_t n, const char* name) {
    cl::Event e;
    launch(dc_, k, n, name, &e);
    events_.emplace_back(name, e);
  };

  setKernelArgs(plan_, counters_, rays, nextRays);
  run(plan_, 1, "bookkeeping");

  setKernelArgs(generate_, params_, counters_, freeList_, queue, filterTable_, passTable_);
  setPathArgs(generate_, 6, pathState_);
  run(generate_, wavefront_, "generate");

  setKernelArgs(intersect_, scene_.caster.nodes(), scene_.caster.blocks(), queue, counters_, rays, pathState_[0],
          pathState_[1], pathState_[2]);
  run(intersect_, wavefront_, "intersect");

  setKernelArgs(shade_, params_, queue, nextQueue, finishedQueue_, counters_, rays, nextRays, scene_.caster.triangles(),
          scene_.triangleMaterial, scene_.materials, scene_.lightPdfArea, scene_.normals, scene_.uvs, scene_.texels,
          scene_.textureInfo);
  setPathArgs(shade_, 15, pathState_);
  setPathArgs(shade_, cl_uint(15 + pathState_.size()), shadowRequests_);
  run(shade_, wavefront_, "shade");

  if (settings_.method != Method::PT && scene_.lightCount > 0) {
    setKernelArgs(shadowConnect_, params_, counters_, scene_.caster.nodes(), scene_.caster.blocks(),
            scene_.caster.triangles(), scene_.triangleMaterial, scene_.materials, scene_.lightCdf,
            scene_.lightTriangle, scene_.lightPdfArea);
    setPathArgs(shadowConnect_, 10, pathState_);
    setPathArgs(shadowConnect_, cl_uint(10 + pathState_.size()), shadowRequests_);
    run(shadowConnect_, wavefront_, "shadow_connect");
  }

  setKernelArgs(accumulatePaths_, finishedQueue_, counters_, freeList_, pixels_, passBuffer_);
  setPathArgs(accumulatePaths_, 5, pathState_);
  run(accumulatePaths_, wavefront_, "accumulate");

  setKernelArgs(finish_, counters_, rays, nextRays);
  run(finish_, 1, "bookkeeping");
}

void PathTracer::collectKernelTimes() {
  for (const auto& [name, event] : events_) timeKernel(name, event);
  events_.clear();
}

// One render's bookkeeping on the host: which global pass each local pass is, and how
// finished passes leave the device (folded into its film, or handed to a PassSource).
struct PathTracer::Run {
  std::function<bool(uint32_t&)> take;     // the next global pass, if any
  PassSource* source = nullptr;            // null: fold into the device's film
  std::function<void(double)> onProgress;  // after each counter read: elapsed seconds
  uint64_t granted = 0, folded = 0;        // local passes
};

// Queues iterations in batches, reading the counters once per batch: finished passes are
// folded (in local order), new passes granted while fewer than passSlots_ are in flight.
void PathTracer::run(Run& r) {
  const auto start = Clock::now();
  stats_ = RenderStats{};
  stats_.device = dc_.info.name;
  stats_.wavefront = wavefront_;
  uint32_t counters[FH_COUNT_TOTAL] = {};
  counters[FH_COUNT_FREE] = unsigned(wavefront_);

  auto grant = [&] {
    uint32_t pass;
    while (r.granted - r.folded < passSlots_ && r.granted < passTable_host_.size() && r.take(pass)) {
      passTable_host_[r.granted] = pass;
      FH_CL(dc_.queue.enqueueWriteBuffer(passTable_, CL_FALSE, r.granted * 4, 4, &passTable_host_[r.granted]));
      ++r.granted;
    }
    counters[FH_COUNT_SAMPLE_LIMIT] = uint32_t(r.granted * pixels_);
  };
  grant();
  FH_CL(dc_.queue.enqueueWriteBuffer(counters_, CL_TRUE, 0, sizeof counters, counters));

  const int batch = 8;
  int current = 0;
  std::vector<float> samples;
  while (r.folded < r.granted) {
    for (int k = 0; k < batch; ++k, current = 1 - current) enqueueIteration(current);
    FH_CL(dc_.queue.enqueueReadBuffer(counters_, CL_TRUE, 0, sizeof counters, counters));
    collectKernelTimes();

    // Fold every completed pass, in local pass order.
    for (;;) {
      const unsigned slot = unsigned(r.folded % passSlots_);
      if (r.folded == r.granted || counters[FH_COUNT_PASS_DONE + slot] != pixels_) break;
      const size_t offset = size_t(slot) * pixels_ * 16;
      if (r.source) {
        samples.resize(size_t(pixels_) * 4);
        FH_CL(dc_.queue.enqueueReadBuffer(passBuffer_, CL_TRUE, offset, samples.size() * 4, samples.data()));
        FH_CL(dc_.queue.enqueueFillBuffer(passBuffer_, 0u, offset, size_t(pixels_) * 16));
        r.source->done(passTable_host_[r.folded], samples);
      } else {
        setKernelArgs(accumulatePass_, passBuffer_, unsigned(r.folded), pixels_, filmSum_, filmSumSq_);
        cl::Event e;
        launch(dc_, accumulatePass_, pixels_, "accumulate_pass", &e);
        events_.emplace_back("accumulate", e);
      }
      // Safe to reset: the next pass using this slot has not been granted yet.
      static const uint32_t zero = 0;
      FH_CL(dc_.queue.enqueueWriteBuffer(counters_, CL_FALSE, (FH_COUNT_PASS_DONE + slot) * 4, 4, &zero));
      counters[FH_COUNT_PASS_DONE + slot] = 0;
      ++r.folded;
    }
    const uint32_t before = counters[FH_COUNT_SAMPLE_LIMIT];
    grant();
    if (counters[FH_COUNT_SAMPLE_LIMIT] != before)
      FH_CL(dc_.queue.enqueueWriteBuffer(counters_, CL_FALSE, FH_COUNT_SAMPLE_LIMIT * 4, 4,
                                         &counters[FH_COUNT_SAMPLE_LIMIT]));
    if (r.onProgress) r.onProgress(std::chrono::duration<double>(Clock::now() - start).count());
  }
  FH_CL(dc_.queue.finish());
  collectKernelTimes();

  auto total64 = [&](int index) { return uint64_t(counters[index]) | uint64_t(counters[index + 1]) << 32; };
  stats_.samples = r.folded * pixels_;
  stats_.cameraRays = counters[FH_COUNT_NEXT_SAMPLE];
  stats_.bounceRays = total64(FH_COUNT_BOUNCE_RAYS);
  stats_.shadowRays = total64(FH_COUNT_SHADOW_RAYS);
  stats_.iterations = counters[FH_COUNT_ITERATIONS];
  stats_.nonfinite = counters[FH_COUNT_NONFINITE];
  stats_.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  stats_.meanQueueOccupancy =
      stats_.iterations ? double(total64(FH_COUNT_QUEUED_RAYS)) / double(stats_.iterations * wavefront_) : 0.0;
}

Film PathTracer::render() {
  const uint64_t passes = uint64_t(std::max(1, settings_.spp));
  uint32_t next = 0;
  bool outOfTime = false;
  Progress progress(settings_.progress);
  Run r;
  // With a time budget, passes stop being handed out once it is spent; those already
  // started finish, so every pixel ends with the same sample count.
  r.take = [&](uint32_t& pass) {
    if (next >= passes || outOfTime) return false;
    pass = next++;
    return true;
  };
  r.onProgress = [&](double elapsed) {
    outOfTime = settings_.seconds > 0.0 && elapsed >= settings_.seconds;
    progress.update(r.folded * pixels_, settings_.seconds > 0.0 ? 0 : passes * pixels_, elapsed,
                    settings_.seconds > 0.0 ? std::min(1.0, elapsed / settings_.seconds) : 0.0);
  };
  run(r);
  progress.finish(stats_.samples, stats_.seconds);

  Film film;
  film.width = settings_.width;
  film.height = settings_.height;
  film.sum.resize(size_t(pixels_) * 4);
  film.sumSq.resize(size_t(pixels_) * 4);
  FH_CL(dc_.queue.enqueueReadBuffer(filmSum_, CL_TRUE, 0, film.sum.size() * 4, film.sum.data()));
  FH_CL(dc_.queue.enqueueReadBuffer(filmSumSq_, CL_TRUE, 0, film.sumSq.size() * 4, film.sumSq.data()));
  return film;
}

void PathTracer::renderPasses(PassSource& source) {
  Run r;
  r.take = [&](uint32_t& pass) { return source.take(pass); };
  r.source = &source;
  run(r);
}

}  // namespace fh
