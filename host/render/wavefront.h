// The wavefront path tracer on one device: the stages of host/render/stages.h over queues
// of path slots, with the path state in structure-of-arrays buffers declared once in
// kernels/path_state.h. It renders the passes it is granted, each into a pass buffer,
// and hands back a pass once all its pixels are in; the device keeps its own books
// (kernels/iteration.cl), so iterations are queued without waiting for the device.
#pragma once
#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "kernels/path_state.h"
#include "render/device_scene.h"
#include "render/film.h"
#include "render/pass_renderer.h"
#include "render/pass_source.h"
#include "render/render_stats.h"
#include "render/settings.h"
#include "render/stages.h"
#include "scene/camera.h"

namespace fh {

// The path state, one buffer per field of FH_PATH_FIELDS, by the field's name.
struct PathStateBuffers {
#define FH_BUFFER(type, name, bytes) cl::Buffer name;
  FH_PATH_FIELDS(FH_BUFFER)
#undef FH_BUFFER
};

// shade's light-sample requests for shadow_connect, one buffer per field of FH_SHADOW_FIELDS.
struct ShadowRequestBuffers {
#define FH_BUFFER(type, name, bytes) cl::Buffer name;
  FH_SHADOW_FIELDS(FH_BUFFER)
#undef FH_BUFFER
};

// The queues of path slots (kernels/queues.h): two ray queues (an iteration reads one and
// fills the other), the paths finished this iteration and the free slots. Their lengths
// are fields of `counters`, a gpu::WavefrontCounters.
struct SlotQueues {
  std::array<cl::Buffer, 2> rays;
  cl::Buffer finished, freeSlots, counters;
};

// The path tracer's program for a scene's features, a method and a strategy (the paths each
// work-item carries, FH_LANES; for the megakernels, the books and megakernel.cl instead of
// the stage files); with surfaceAovs, shade records the first-surface layers (FH_AOVS).
ProgramSpec pathTracerProgram(const SceneFeatures& features, Method method, const std::string& traversalOptions,
                              Strategy strategy, bool surfaceAovs = false);

// What every kernel of a render reads (kernels/types.h), and the pixel filter's inverse CDF
// that camera rays are offset by.
gpu::RenderParams renderParams(const RenderSettings& s, const Camera& camera, const DeviceScene& scene,
                               std::vector<float>& filterTable);

// The features a render's kernels are compiled with: the scene's (or all of them with
// --all-features), and the environment map if the render has one.
SceneFeatures featuresFor(const Scene& scene, const RenderSettings& s);

// The strategy a device runs: the one asked for, or for Auto, eight lanes on a CPU and
// one path per work-item elsewhere.
Strategy strategyFor(const DeviceInfo& device, Strategy asked);
// Paths per work-item in the stages written with lanes (all but intersect and the books).
unsigned lanesOf(Strategy s);
// Whether the strategy runs the stages in one kernel (kernels/megakernel.cl).
bool isMegakernel(Strategy s);

// Iterations a device worker queues between reads of the device's books
// (render/device_worker.h): enough that the device is never idle waiting for the host, few
// enough that finished passes leave soon.
constexpr int kIterationsPerBatch = 8;

// The default number of paths in flight: 512k on a GPU, fewer on a CPU, where the
// path state should stay near the caches; never more than two passes of pixels.
size_t defaultWavefront(const DeviceInfo& device, size_t pixels);

class WavefrontPipeline : public PassRenderer {
 public:
  // `scene`: prepareScene(scene, bvh, featuresFor(scene, s), s.envMap), once for all devices.
  WavefrontPipeline(DeviceContext& dc, const PreparedScene& scene, const Bvh& bvh, const Camera& camera,
                    const RenderSettings& s);

  // One iteration over every path in flight; returns at once (the device runs it later).
  void enqueueIteration() override;

  // Passes are numbered locally (0, 1, ... on this device) and mapped to global passes,
  // which seed the samples. A pass covers the pixels listed (null: every pixel, each
  // pixel's sample of pass k its sequence's point k). Passes
  // are granted while they fit: FH_MAX_PASS_SLOTS unfinished at most, their samples within
  // the pass buffers, and of two shapes at most (gpu::PassShape: runs of passes over one
  // pixel list): a pass of a new shape waits, held by the worker, until every sample of the
  // older one in flight has started.
  bool fits(const std::shared_ptr<const RoundPixels>& pixels, uint64_t granted, uint64_t returned) const override;
  void grantPass(uint64_t local, uint32_t global, std::shared_ptr<const RoundPixels> pixels) override;
  // Lets the passes granted so far start; once per batch, after its grants.
  void startGrantedPasses() override;
  uint32_t globalPass(uint64_t local) const override { return passes_[local % FH_MAX_PASS_SLOTS].table[0]; }

  // Waits for the queued iterations and reads the books back.
  void readCounters() override;
  // Whether local pass `local` is complete, as of the last readCounters().
  bool passComplete(uint64_t local) const override;
  // Reads a complete pass's samples (rgb, 1 for each pixel it covers, in the order of its
  // pixel list; then, with surface AOVs, kAovFloatsPerPixel for each) and frees its slot.
  void takePass(uint64_t local, std::vector<float>& samples) override;

  // This device's counts so far (samples are the film's to count) and stage times.
  RenderStats stats() override;
  size_t wavefront() const override { return wavefront_; }
  // The scene's buffers on this device (the light tracer's camera paths share them).
  const DeviceScene& deviceScene() const { return scene_; }
  Strategy strategy() const override { return strategy_; }

 private:
  // The stages; each launches its kernel, bound for the current parity.
  void planIteration() { run(Stage::PlanIteration, 1); }
  // Stages with lanes take lanesOf(strategy_) paths per work-item; intersect one ray each.
  void generate() { run(Stage::Generate, laneItems()); }
  void megakernel();
  void intersect() { run(Stage::Intersect, wavefront_); }
  void shade() { run(Stage::Shade, laneItems()); }
  void shadowConnect() { run(Stage::ShadowConnect, laneItems()); }
  void accumulate() { run(Stage::Accumulate, laneItems()); }
  size_t laneItems() const { return (wavefront_ + lanesOf(strategy_) - 1) / lanesOf(strategy_); }
  void finishIteration() { run(Stage::FinishIteration, 1); }
  void run(Stage stage, size_t items);

  void allocateBuffers(const std::vector<float>& filterTable);
  void bindArguments(unsigned parity);
  bool launches(Stage s) const;  // whether this strategy launches the stage's own kernel
  void writeCounter(size_t offset, const uint32_t& value);
  void newShape(std::shared_ptr<const RoundPixels> pixels, uint64_t local);
  // Whether a pass of `size` pixels would take the newer shape past shapeSpan_ samples.
  bool outgrowsShape(uint32_t size) const { return grantedSamples_ + size - shapeStart_ > shapeSpan_; }

  DeviceContext& dc_;
  Method method_;
  Strategy strategy_;
  DeviceScene scene_;
  gpu::RenderParams params_{};
  size_t wavefront_;
  unsigned pixels_;
  size_t passEntries_;  // the pass buffers' entries: enough for a few passes of every pixel
  unsigned parity_ = 0;  // which ray queue is current
  PathStateBuffers paths_;
  ShadowRequestBuffers shadowRequests_;
  SlotQueues queues_;
  cl::Buffer passBuffers_, filterTable_, passTableBuffer_, pixelListBuffer_;
  bool surfaceAovs_;
  cl::Buffer aovBuffers_;  // per pass entry, kernels/aovs.h (a placeholder without AOVs)
  // Each local pass in flight, by local pass % FH_MAX_PASS_SLOTS: its first local sample,
  // its pixel count, and its pass-table entry (stable storage for writes): its global pass
  // and its first entry in the pass buffers.
  struct PassInFlight {
    uint64_t firstSample = 0;
    uint32_t pixels = 0;
    uint32_t table[2] = {0, 0};
  };
  std::vector<PassInFlight> passes_;
  // Local samples are counted here in 64 bits and numbered on the device by the low 32 bits
  // of the count, which wrap (a device renders more than 2^32 samples of a large image):
  // the kernels only take differences of numbers less than 2^31 apart. The count starts
  // just short of 2^32, so that every render of more than 256 samples crosses the wrap (as
  // Linux's jiffies start just short of theirs), and the tests see it.
  static constexpr uint64_t kFirstLocalSample = (uint64_t(1) << 32) - 256;
  uint64_t grantedSamples_ = kFirstLocalSample;  // local samples of the passes granted so far
  uint64_t startedSamples_ = kFirstLocalSample;  // local samples started, as of readCounters()
  uint32_t sampleLimit_ = 0;                     // what the device may start: stable storage for writes
  // The newer shape's first local sample, and the most samples a shape's passes span: a
  // longer run of passes over the same pixels is a new shape of them (the sample's place in
  // its shape, kernels/generate.cl, stays far below 2^32).
  uint64_t shapeStart_ = kFirstLocalSample, shapeSpan_ = 0;
  // The two shapes of WavefrontCounters (stable storage for writes) and the pixels they
  // cover (null: every pixel, offsets 0, listed nowhere: FH_EVERY_PIXEL); a listed shape's
  // list is in the half of the pixel-list buffer at its `list`, its sequence offsets two
  // halves on. Only an adaptive render lists pixels (listsPixels_): the buffer is a
  // placeholder in the others (16 bytes a pixel saved).
  std::array<gpu::PassShape, 2> shapes_{};
  std::array<std::shared_ptr<const RoundPixels>, 2> shapePixels_;
  std::array<std::vector<uint32_t>, 2> lists_, offsets_;  // each half's (stable storage for writes)
  bool listsPixels_;
  gpu::WavefrontCounters counters_{};
  // Every stage's kernel twice, bound once for each parity: an iteration sets nothing.
  std::array<std::array<cl::Kernel, kStages.size()>, 2> kernels_;
  std::array<cl::Kernel, 2> megakernels_;  // the Megakernel strategy's, for each parity
  std::vector<std::pair<const char*, cl::Event>> events_;  // by kernel name, to be timed
  std::map<std::string, double> stageSeconds_;
};

}  // namespace fh
