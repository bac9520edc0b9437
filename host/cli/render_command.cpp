// `fredholm render`: flags checked before any work, then scene, camera, BVH, one render on
// every device --device selects, and the image with its metadata.
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <sstream>

#include <nlohmann/json.hpp>

#include "base/atomic_file.h"
#include "base/output_plan.h"
#include "base/vec.h"
#include "cli/commands.h"
#include "cli/flags.h"
#include "cli/interrupt.h"
#include "device/devices.h"
#include "display/live_view.h"
#include "image/denoiser.h"
#include "image/error_metrics.h"
#include "image/image_io.h"
#include "render/checkpoint.h"
#include "render/method_choice.h"
#include "render/radiance_unit.h"
#include "render/render.h"
#include "render/render_aov.h"
#include "render/wavefront.h"
#include "scene/environment_map.h"
#ifdef FREDHOLM_HAVE_MPI
#include "distributed/mpi_render.h"
#endif

namespace fh {
namespace {

std::string formatScientific(double v) {
  std::ostringstream out;
  out << std::scientific << std::setprecision(3) << v;
  return out.str();
}

std::string formatSeconds(double s) {
  std::ostringstream out;
  out << std::fixed << std::setprecision(2) << s;
  return out.str();
}

// --camera FILE, else the scene's sidecar, else framing; then --eye/--target/--up/--fov
// override. Given in the scene file's units, returned in the renderer's (Scene::worldScale).
Camera chooseCamera(const RenderOptions& o, const Scene& scene) {
  const float toWorld = scene.worldScale;
  Camera camera;
  bool framed = false;
  if (!o.cameraFile.empty()) {
    camera = scaledCamera(loadCameraJson(o.cameraFile), toWorld);
  } else if (scene.hasCamera) {
    camera = scaledCamera(scene.camera, toWorld);
  } else {
    Vec3f lo, hi;
    scene.bounds(lo, hi);
    camera = frameBounds(lo, hi);
    framed = true;
    if (o.eye.empty() || o.target.empty())
      std::cerr << "fredholm: no camera given (--camera, --eye/--target, or a .camera.json beside the OBJ): "
                   "framing the scene's bounds\n";
  }
  if (!o.eye.empty()) camera.eye = parseVec3Flag("--eye", o.eye) * toWorld;
  if (!o.target.empty()) camera.target = parseVec3Flag("--target", o.target) * toWorld;
  if (!o.up.empty()) camera.up = parseVec3Flag("--up", o.up);
  if (o.fov) camera.fovYDeg = *o.fov;
  if (framed && (!isFinite(camera.eye) || !isFinite(camera.target)))
    throw Error(scene.sourcePath + ": the scene's bounds are too large to frame a camera; give --camera or "
                                   "--eye/--target");
  validateCamera(camera, o.fov ? "--fov" : "camera");
  return camera;
}

// --env-map with its --env-rotate and --env-scale, read and checked; null without a map.
std::shared_ptr<const EnvironmentMap> environmentMapFrom(const RenderOptions& o) {
  if (o.envMap.empty()) {
    if (o.envRotate || o.envScale) throw Error(std::string(o.envRotate ? "--env-rotate" : "--env-scale") +
                                               " applies to --env-map, and none is given");
    return nullptr;
  }
  if (!o.env.empty())
    throw Error("--env (constant radiance) and --env-map: pick one (--env-scale scales the map)");
  return std::make_shared<const EnvironmentMap>(
      loadEnvironmentMap(o.envMap, o.envRotate.value_or(0.f), o.envScale.value_or(1.f)));
}

// --passes A:B: the chunk's first pass and its end (the render's spp), checked against the
// flags a chunk cannot go with.
void chunkOf(const RenderOptions& o, RenderSettings& s) {
  unsigned long long first = 0, end = 0;
  char colon = 0, rest = 0;
  std::istringstream in(o.passes);
  if (!(in >> first >> colon >> end) || colon != ':' || in >> rest || o.passes[0] == '-' ||
      o.passes.find(":-") != std::string::npos || first >= end || end > 0x7fffffffull)
    throw Error("--passes '" + o.passes + "': give A:B, passes A to B-1 with 0 <= A < B (e.g. 0:64)");
  const std::pair<bool, const char*> clashes[] = {{o.spp.has_value(), "--spp (the chunk's end is its spp)"},
                                                  {o.noise > 0, "--noise"},
                                                  {o.adaptive, "--adaptive"},
                                                  {!o.resume.empty(), "--resume"},
                                                  {!o.checkpoint.empty(), "--checkpoint (the chunk is the unit to rerun)"},
                                                  {!o.aov.empty(), "--aov"}};
  for (const auto& [given, flag] : clashes)
    if (given) throw Error(std::string("--passes renders a chunk for fredholm merge and does not go with ") + flag);
  if (o.film.empty()) throw Error("--passes renders a chunk for fredholm merge: give --film FILE to save it to");
  s.firstPass = uint32_t(first);
  s.spp = int(end);
}

// Light tracing starts its paths on the scene's emitting triangles (bdpt also on the map) and
// splats them wherever the camera sees them: what it cannot do yet is an error before any work.
void lightTracingFits(const RenderOptions& o, const RenderSettings& s) {
  // bdpt's and vcm's camera subpaths find --env, and their light subpaths start on the map too.
  const bool environments = bidirectional(s.method);
  const char* why = nullptr;
  if (!environments && s.env != std::array<float, 3>{0.f, 0.f, 0.f}) why = "--env";
  else if (!environments && !o.envMap.empty()) why = "--env-map";
  else if (o.adaptive) why = "--adaptive (its passes cover chosen pixels; a light path lands anywhere)";
  if (why)
    throw Error(std::string("--method ") + methodName(s.method) +
                (environments ? "" : " traces light paths from the emitting triangles only and") + " does not go with " +
                why + "; use mis");
}

// --method auto pilots each method in this process, on this process's devices: what must
// share one method with another process, or has none, is an error before any work.
void autoFits(const RenderOptions& o) {
  const std::pair<bool, const char*> clashes[] = {
      {!o.passes.empty(), "--passes (every chunk must have the method of the others)"},
      {!o.resume.empty(), "--resume (the checkpoint's render chose its method already; auto printed it)"},
      {!o.aov.empty(), "--aov (a debug view has no method)"}};
  for (const auto& [given, flag] : clashes)
    if (given) throw Error(std::string("--method auto chooses a method per render and does not go with ") + flag +
                           "; give the method (pt, nee, mis, lt, bdpt or vcm)");
}

// --seed: the sampler's seed is 32 bits.
unsigned parseSeed(const std::string& text) {
  const bool digits = !text.empty() && text.size() <= 10 && text.find_first_not_of("0123456789") == std::string::npos;
  if (!digits || std::stoull(text) > 0xFFFFFFFFull)
    throw Error("--seed '" + text + "': expected a whole number from 0 to 4294967295");
  return unsigned(std::stoull(text));
}

// Every flag that does not need the scene, checked; 64 spp by default (4 for --aov), or
// with --time or --noise and no --spp as many as they take (up to 2^20, whatever the image).
RenderSettings settingsFrom(const RenderOptions& o) {
  RenderSettings s;
  // auto: mis until the pilot chooses (choosePilotedMethod).
  s.method = o.method == "auto" ? Method::MIS : parseMethod(o.method);
  if (o.method == "auto") autoFits(o);
  s.strategy = parseStrategy(o.strategy);
  s.filter = parseFilter(o.filter);
  if (!o.env.empty()) s.env = parseVec3Flag("--env", o.env);
  if (s.env[0] < 0 || s.env[1] < 0 || s.env[2] < 0) throw Error("--env '" + o.env + "': radiance cannot be negative");
  if (tracesLightPaths(s.method)) lightTracingFits(o, s);  // before a map is read
  s.envMap = environmentMapFrom(o);
  if (o.width <= 0 || o.height <= 0) throw Error("--width/--height must be positive");
  // Pixels are indexed in 32 bits on the device, with room for several pass buffers.
  if (uint64_t(o.width) * uint64_t(o.height) > (uint64_t(1) << 28))
    throw Error("--width/--height: " + std::to_string(o.width) + "x" + std::to_string(o.height) +
                " is more than the 268 million pixels fredholm renders in one image");
  if (o.spp && *o.spp < 1) throw Error("--spp must be at least 1");
  if (!std::isfinite(o.seconds) || o.seconds < 0) throw Error("--time must be a finite number of seconds");
  if (!std::isfinite(o.noise) || o.noise < 0) throw Error("--noise must be a finite, non-negative relMSE (e.g. 1e-3; 0: no target)");
  if (o.maxDepth < 1) throw Error("--max-depth must be at least 1");
  if (o.rrDepth < 1) throw Error("--rr-depth must be at least 1");
  if (o.mergeRadius && !(*o.mergeRadius >= 1e-4f && *o.mergeRadius <= 1.f))
    throw Error("--merge-radius must be a fraction of the scene's radius, from 1e-4 to 1");
  if (o.mergeRadius && o.method != "vcm" && o.method != "auto")  // auto: should it choose vcm
    throw Error("--merge-radius is vcm's (vertex merging); --method " + o.method + " merges nothing");
  if (o.wavefront && *o.wavefront < kLocalSize) throw Error("--wavefront must be at least 64");
  s.width = o.width;
  s.height = o.height;
  s.spp = o.spp ? *o.spp : (o.seconds > 0 || o.noise > 0 ? 1 << 20 : (o.aov.empty() ? 64 : 4));
  if (!o.passes.empty()) chunkOf(o, s);
  s.seconds = o.seconds;
  s.noise = o.noise;
  s.adaptive = o.adaptive;
  if (o.adaptive && !o.aov.empty()) throw Error("--adaptive samples a render's noise; --aov renders a debug view");
  s.maxDepth = o.maxDepth;
  s.rrDepth = o.rrDepth;
  s.mergeRadius = o.mergeRadius.value_or(s.mergeRadius);
  s.seed = parseSeed(o.seed);
  s.wavefront = o.wavefront.value_or(0);
  s.allFeatures = o.allFeatures;
  s.progress = true;
  return s;
}

// --aov: first-hit albedo, normal or depth, on one device (runRender checks there is one).
RenderResult renderDebugView(Aov mode, const std::vector<DeviceInfo>& devices, const Scene& scene,
                             const Bvh& bvh, const Camera& camera, const RenderSettings& s,
                             const RenderLinks& links) {
  AovSettings a;
  a.width = s.width;
  a.height = s.height;
  a.spp = s.spp;
  a.seed = s.seed;
  a.mode = mode;
  DeviceContext dc(devices[0]);
  const Image image = renderAov(dc, scene, bvh, camera, a);
  RenderResult r;
  r.film = Film(s.width, s.height);
  for (size_t p = 0; p < r.film.pixels(); ++p) {
    for (size_t c = 0; c < 3; ++c) r.film.sum[4 * p + c] = image.rgb[3 * p + c];
    r.film.sum[4 * p + 3] = 1.0;
  }
  r.stats.samples = uint64_t(s.spp) * r.film.pixels();
  RenderStats::DeviceShare share;
  share.name = devices[0].name;
  share.samples = r.stats.samples;
  r.stats.devices.push_back(share);
  r.stopped = links.stopRequested();  // a debug view finishes once started
  return r;
}

void reportDevices(const RenderResult& r) {
  for (const auto& w : r.warnings) std::cerr << "fredholm: warning: " << w << "\n";
  for (const auto& d : r.stats.devices)
    if (!d.error.empty())
      std::cerr << "fredholm: warning: device " << d.name << " failed: " << d.error
                << (r.complete ? "; the other devices rendered its passes" : "") << "\n";
  if (r.stats.nonfinite)
    std::cerr << "fredholm: warning: " << r.stats.nonfinite << " samples were NaN or infinite and dropped\n";
}

// Where --denoise writes: out.exr -> out.denoised.exr, beside the image, never instead of it.
std::string denoisedName(const std::string& output) {
  const std::filesystem::path p(output);
  return (p.parent_path() / p.stem()).string() + ".denoised" + p.extension().string();
}

// The --aovs layers, parsed and checked against the other flags and the output; picks the
// default output name (PNG, or EXR with layers) and plans every file the render writes.
std::vector<std::string> planOutputs(RenderOptions& o, RenderSettings& settings, int rank, OutputPlan& plan) {
  const std::vector<std::string> layers = o.aovs.empty() ? std::vector<std::string>{} : parseAovLayers(o.aovs);
  if (!o.aov.empty() && !layers.empty()) throw Error("--aov (a debug view) and --aovs (layers beside the image): pick one");
  for (const auto& layer : layers) settings.surfaceAovs |= isSurfaceAov(layer);
  if (tracesLightPaths(settings.method) && (settings.surfaceAovs || o.denoise))
    throw Error(std::string("--method ") + methodName(settings.method) + " records no first surfaces, which " +
                (settings.surfaceAovs ? "--aovs '" + o.aovs + "' asks for" : std::string("--denoise needs")) +
                (settings.method == Method::LT ? " (camera paths see them, light paths do not)"
                                               : " (its camera paths record no layers)") +
                "; use mis");
  // An explicit -o is never overwritten without --force; the default name steps aside.
  // With --film the film is the output, and an image is written only where -o asks.
  const bool defaultName = o.output.empty() && o.film.empty();
  if (defaultName) o.output = firstFreeName(layers.empty() ? "fredholm.png" : "fredholm.exr");
  if (!o.film.empty() && !o.aov.empty()) throw Error("--film saves a render's passes; --aov renders none");
  const double every = o.checkpointEvery.value_or(settings.checkpointSeconds);
  if (!std::isfinite(every) || every < 0)
    throw Error("--checkpoint-every must be a finite number of seconds, 0 or more");
  if (o.checkpointEvery && o.checkpoint.empty())
    throw Error("--checkpoint-every sets how often --checkpoint saves, and no --checkpoint FILE is given");
  settings.checkpointSeconds = every;
  // Under mpirun every rank saves its own film, FILE.rank<r>. The checkpoint a render
  // resumes from is its own to overwrite.
  if (!o.checkpoint.empty()) {
    settings.checkpointPath = o.mpi ? rankCheckpointPath(o.checkpoint, rank) : o.checkpoint;
    plan.add(settings.checkpointPath, "--checkpoint", OutputKind::Owned,
             o.checkpoint == o.resume ? settings.checkpointPath : "");
  }
  if (rank == 0) {  // rank 0 writes the image and the rest
    if (!o.film.empty()) plan.add(o.film, "--film");
    if (!o.output.empty()) {
      checkImageExtension(o.output, "-o");
      plan.add(o.output, "-o", defaultName ? OutputKind::Default : OutputKind::Named);
    }
    if (!layers.empty() && !o.output.empty() && extensionOf(o.output) != ".exr")
      throw Error("--aovs: layers are written into one EXR; -o '" + o.output + "' is not an .exr file");
    if (!o.statsFile.empty()) plan.add(o.statsFile, "--stats");
  }
  if (o.denoise) {
    if (!o.aov.empty()) throw Error("--denoise works on a render's radiance; --aov renders a debug view");
    if (o.output.empty())
      throw Error("--denoise writes NAME.denoised.EXT beside the image: give -o (with --film, no image is written "
                  "without it)");
    settings.surfaceAovs = true;  // the denoiser's albedo and normal
    if (rank == 0) plan.add(denoisedName(o.output), "--denoise", defaultName ? OutputKind::Default : OutputKind::Named);
  }
  plan.reserve();
  return layers;
}

// A resumed render says what it starts from, and when the checkpoint holds every pass asked for.
void reportResume(const RenderOptions& o, const RenderSettings& settings, const Film& film) {
  const uint64_t held = film.nextPass(), asked = uint64_t(settings.spp);
  std::cerr << "fredholm: resuming from '" << o.resume << "': passes " << film.describePasses() << " rendered";
  if (settings.adaptive || held < asked)
    std::cerr << "; rendering from pass " << held << "\n";
  else if (held == asked)
    std::cerr << ", as many as --spp " << asked << " asks: nothing left to render\n";
  else  // the image keeps every pass the checkpoint holds: samples are never thrown away
    std::cerr << ", more than the " << asked << " --spp asks: nothing left to render, and the image holds all "
              << held << "\n";
}

// This process's rank when it is one of several sharing the render (mpirun), else 0.
int mpiRank(const RenderOptions& o) {
#ifdef FREDHOLM_HAVE_MPI
  if (o.mpi) return o.mpi->rank();
#endif
  (void)o;
  return 0;
}

// Under mpirun: what a render shared by ranks cannot do (yet), refused on every rank alike;
// and one progress display, rank 0's (every rank's stderr reaches the terminal).
void checkSharedRender(const RenderOptions& o, RenderSettings& settings, int rank) {
  const std::pair<bool, const char*> clashes[] = {{o.noise > 0, "--noise"},
                                                  {o.adaptive, "--adaptive"},
                                                  {!o.aov.empty(), "--aov"},
                                                  {o.method == "auto", "--method auto (each rank would pilot alone)"}};
  for (const auto& [given, flag] : clashes)
    if (given) throw Error(std::string("under mpirun, ranks share a render without ") + flag + " (not yet supported)");
  settings.progress = rank == 0;
}

// Under mpirun, --resume FILE: rank 0 starts from every rank's checkpoint (FILE.rank<r>,
// whatever the rank count that wrote them) added into one film; the others start empty.
// Where the render checkpoints to the same FILE, rank 0 saves that film as its own
// checkpoint and removes the other ranks' files it holds, before any rank renders (the
// ranks ask rank 0 for passes first), so no pass is ever in two of them.
std::shared_ptr<const Film> resumeRanks(const RenderOptions& o, int rank, const std::string& fingerprint) {
  if (rank != 0) return nullptr;
  auto film = std::make_shared<Film>(loadRankCheckpoints(o.resume, fingerprint, "--resume"));
  if (o.checkpoint == o.resume) {
    saveCheckpoint(rankCheckpointPath(o.checkpoint, 0), *film, fingerprint);
    for (const std::string& file : rankCheckpointFiles(o.checkpoint))
      if (file != rankCheckpointPath(o.checkpoint, 0)) std::filesystem::remove(file);
  }
  return film;
}

RenderResult renderOnEveryRank(const RenderOptions& o, const std::vector<DeviceInfo>& devices, const Scene& scene,
                               const Bvh& bvh, const Camera& camera, const RenderSettings& settings,
                               const RenderLinks& links) {
#ifdef FREDHOLM_HAVE_MPI
  if (o.mpi) return renderAcrossRanks(*o.mpi, devices, scene, bvh, camera, settings, links);
#endif
  (void)o;
  return render(devices, scene, bvh, camera, settings, links);
}

// --method auto: the pilots, then the settings for the method chosen. A time budget is the
// whole render's: what the pilots took comes off it (at least a pass is rendered).
MethodChoice choosePilotedMethod(const std::vector<DeviceInfo>& devices, const Scene& scene, const Bvh& bvh,
                                 const Camera& camera, RenderSettings& settings, const RenderLinks& links) {
  if (const std::vector<Method> candidates = methodsFor(scene, settings); candidates.size() > 1) {
    std::string names;
    for (Method m : candidates) names += (names.empty() ? "" : ", ") + std::string(methodName(m));
    std::cerr << "fredholm: --method auto: a pilot render with each of " << names << "\n";
  }
  const MethodChoice choice = chooseMethod(devices, scene, bvh, camera, settings, links.stop);
  if (links.stopRequested()) throw Interrupted("during --method auto's pilot renders; nothing written", links.stop->load());
  settings.method = choice.method;
  settings.fingerprint = renderFingerprint(scene, camera, settings);
  if (settings.seconds > 0) settings.seconds = std::max(settings.seconds - choice.seconds, 1e-6);
  if (choice.alone()) {
    std::cerr << "fredholm: --method auto chose mis without pilots: the only method for these settings (lt and "
              << "bdpt do not go with " << (settings.adaptive ? "--adaptive" : "first-surface layers") << ")\n";
    return choice;
  }
  if (!choice.piloted()) {
    std::cerr << "fredholm: --method auto chose mis without pilots: the smallest would take about "
              << formatSeconds(choice.leastPilotSeconds) << " s of the render's " << formatSeconds(choice.renderSeconds)
              << " s, more than a fifth\n";
    return choice;
  }
  std::cerr << "fredholm: --method auto chose " << methodName(choice.method)
            << " (relMSE x seconds, by its own and by the other pilots' estimates, of " << choice.pilotWidth << "x"
            << choice.pilotHeight << " pilots of " << formatSeconds(choice.pilotSeconds)
            << " s each: " << choice.describeCosts() << "; pilots took " << formatSeconds(choice.seconds) << " s)\n";
  return choice;
}

// What --method auto chose, as the image's metadata says it.
std::string choiceMetadata(const MethodChoice& c) {
  if (c.alone()) return "auto: mis, the only method for these settings";
  if (!c.piloted()) return "auto: mis without pilots (the render too short for them)";
  return "auto: relMSE x seconds (own / the others' estimate) of " + std::to_string(c.pilotWidth) + "x" +
         std::to_string(c.pilotHeight) + " pilots: " + c.describeCosts();
}

// The choice and its figures, for --stats.
nlohmann::json choiceJson(const MethodChoice& c) {
  nlohmann::json methods = nlohmann::json::object();
  for (const MethodTrial& t : c.trials)
    methods[methodName(t.method)] = {
        {"seconds", t.seconds},          {"relmse", t.relMse},     {"mean_relmse", t.meanRelMse}, {"cost", t.cost()},
        {"cross_relmse", t.crossRelMse}, {"cross_cost", t.crossCost()}, {"passes", t.passes}};
  nlohmann::json candidates = nlohmann::json::array();
  for (Method m : c.candidates) candidates.push_back(methodName(m));
  return {{"chosen", methodName(c.method)},
          {"candidates", candidates},
          {"margin", kChoiceMargin},
          {"piloted", c.piloted()},
          {"render_seconds", c.renderSeconds},
          {"least_pilot_seconds", c.leastPilotSeconds},
          {"pilot_width", c.pilotWidth},
          {"pilot_height", c.pilotHeight},
          {"pilot_seconds", c.pilotSeconds},
          {"seconds", c.seconds},
          {"methods", methods}};
}

// The image's radiance denoised, written with the render's metadata and what denoised it.
std::string writeDenoised(const std::string& output, const Denoiser& denoiser, const Film& film, const Image& image,
                          std::map<std::string, std::string> metadata) {
  const auto start = std::chrono::steady_clock::now();
  const Image denoised = denoiser.denoise(image, film.albedo(), film.normal());
  metadata["denoised"] = denoiser.describe();
  const std::string written = writeImage(denoisedName(output), denoised, metadata);
  std::cerr << "fredholm: denoised in "
            << formatSeconds(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count())
            << " s\n";
  return written;
}

// Writes the image where -o names one (and its denoised twin with --denoise) and the film for
// --film; returns what was written.
std::string writeOutputs(const RenderOptions& o, const RenderSettings& s, const Film& film, const Image& image,
                         const std::map<std::string, std::string>& metadata, const Denoiser* denoiser) {
  std::string written;
  if (!o.output.empty()) written = writeImage(o.output, image, metadata);
  if (denoiser) written += " and " + writeDenoised(o.output, *denoiser, film, image, metadata);
  if (!o.film.empty() && film.passes() > 0)
    written += (written.empty() ? "" : " and ") + saveFilm(o.film, film, s.fingerprint, "--film") + " (passes " +
               film.describePasses() + ")";
  return written;
}

// The render's facts in the image file's metadata.
std::map<std::string, std::string> imageMetadata(const RenderOptions& o, const Scene& scene, const RenderResult& r,
                                                 const std::string& method, double spp, double seconds,
                                                 double estimatedRelMse) {
  std::map<std::string, std::string> metadata = {
      {"scene", scene.sourcePath},       {"spp", formatSeconds(spp)},          {"method", method},
      {"device", r.stats.contributors()}, {"seed", o.seed},     {"seconds", formatSeconds(seconds)},
      {"filter", o.filter},              {"max_depth", std::to_string(o.maxDepth)}};
  if (!o.aovs.empty()) metadata["aovs"] = o.aovs;
  if (method == "vcm")
    metadata["merge_radius"] = formatScientific(o.mergeRadius.value_or(RenderSettings{}.mergeRadius));
  if (!o.envMap.empty()) {
    metadata["env_map"] = o.envMap;
    metadata["env_rotate"] = formatSeconds(o.envRotate.value_or(0.f));
    metadata["env_scale"] = formatScientific(o.envScale.value_or(1.f));
  }
  // The estimate compares a pixel's samples with each other: with one sample there is none.
  if (o.aov.empty() && r.film.passes() >= 2) metadata["estimated_relmse"] = formatScientific(estimatedRelMse);
  return metadata;
}

// relMSE divides each pixel's squared error by its value squared plus kRelMseEpsilon, the
// literature's for images whose pixels are about one. Where the image's mean is below a tenth
// of the epsilon's square root, a typical pixel's square is a hundredth of the epsilon: the
// estimate then measures absolute error, and --noise is met after few passes however noisy
// the image looks once exposed. Said, not changed: relMSE stays the measure `compare` and
// the benchmarks use.
constexpr double kDimImageMean = 0.01;

void warnIfDim(const Image& image, uint64_t passes, double target) {
  double total = 0.0;
  for (float v : image.rgb) total += double(v);
  const double mean = image.rgb.empty() ? 0.0 : total / double(image.rgb.size());
  if (mean >= kDimImageMean || mean <= 0.0) return;
  std::cerr << "fredholm: warning: the image is dim (mean " << formatScientific(mean) << "): relMSE's epsilon of "
            << kRelMseEpsilon << " outweighs its pixels' squares, so --noise " << formatScientific(target)
            << " measured absolute error (met after " << passes
            << " passes); brighter emitters (Ke) or a smaller --noise give the noise an exposed image shows\n";
}

// Radiance past the float range has no value to write: a pixel summed to infinity would
// pass for a bright one in a PNG and for the scene's answer in an EXR. No file is written.
void refuseNonFiniteImage(const Image& image) {
  const NonFiniteValues found = nonFiniteValues(image);
  if (found.count == 0) return;
  const size_t first = found.firstPixel;
  throw Error(std::to_string(found.count) + " pixel values of the image are past the float range (first at pixel (" +
              std::to_string(first % size_t(image.width)) + ", " + std::to_string(first / size_t(image.width)) +
              ")): the emitters (Ke, --env, --env-map times --env-scale) are too bright for 32-bit floats; "
              "nothing written");
}

void printSummary(const RenderOptions& o, const RenderSettings& settings, const Scene& scene, const RenderResult& r,
                  const Image& image, const std::string& method, double spp, double seconds, double noise) {
  std::cerr << "fredholm: rendered " << scene.sourcePath << " (" << scene.triangleCount() << " triangles, "
            << scene.lights.size() << " emissive; "
            << (o.allFeatures ? "all features" : featuresFor(scene, settings).describe())
            << ") with " << method << ", " << o.width << "x" << o.height << ", " << spp << " spp on "
            << (r.stats.ranks.empty() ? "" : std::to_string(r.stats.ranks.size()) + " ranks, rank 0 on ")
            << r.stats.contributors() << " in " << formatSeconds(seconds) << " s\n";
  if (settings.noise > 0) {
    const bool met = noise <= settings.noise;
    std::cerr << "fredholm: estimated relMSE " << formatScientific(noise) << (met ? " meets" : " has not reached")
              << " --noise " << formatScientific(settings.noise) << (met ? "" : " (stopped by --spp or --time)") << "\n";
    if (met) warnIfDim(image, r.film.passes(), settings.noise);
  }
}

}  // namespace

int runRender(RenderOptions o) {
  RenderSettings settings = settingsFrom(o);
  // Without --spp a time budget is the only bound: the 64-spp default does not apply.
  if (o.seconds > 0 && !o.spp && o.noise == 0 && o.passes.empty())
    std::cerr << "fredholm: --time " << o.seconds << " without --spp: as many samples per pixel as the time allows "
                 "(--spp caps them)\n";
  RenderLinks links;
  links.stop = &installInterruptHandlers();
  const bool debugView = !o.aov.empty();
  const Aov aov = debugView ? parseAov(o.aov) : Aov::Albedo;
  const int rank = mpiRank(o);
  if (o.mpi) checkSharedRender(o, settings, rank);
  const std::optional<DisplayAddress> display =
      o.displayServer.empty() ? std::nullopt : std::optional<DisplayAddress>(parseDisplayAddress(o.displayServer));
  OutputPlan plan(o.force);
  const std::vector<std::string> layers = planOutputs(o, settings, rank, plan);
  const std::unique_ptr<Denoiser> denoiser = o.denoise && rank == 0 ? Denoiser::load() : nullptr;
  const auto devices = selectDevices(listDevices(), o.device);
  if (debugView && devices.size() > 1)
    throw Error("--aov renders on one device, and --device '" + o.device + "' selects " +
                std::to_string(devices.size()) + "; pick one (e.g. --device " + std::to_string(devices[0].index) +
                ")");

  Scene scene = loadSceneSpec(o.scene);
  printWarnings(scene);
  const Camera camera = chooseCamera(o, scene);
  settings.radianceUnit = toRadianceUnit(scene, settings);
  settings.depthUnit = 1.0 / double(scene.worldScale);
  settings.fingerprint = renderFingerprint(scene, camera, settings);
  if (!o.resume.empty()) {
    if (debugView) throw Error("--resume goes on with a render's passes; --aov renders none");
    links.resume = o.mpi ? resumeRanks(o, rank, settings.fingerprint)
                         : std::make_shared<Film>(loadCheckpoint(o.resume, settings.fingerprint, "--resume"));
  }
  if (links.resume && rank == 0) reportResume(o, settings, *links.resume);
  plan.checkAgainstInputs();
  // rank 0's view: its own passes as they merge, then the image of all.
  std::unique_ptr<LiveView> view;
  if (display && rank == 0) {
    view = std::make_unique<LiveView>(*display, o.output.empty() ? o.film : o.output, layers);
    links.watcher = view.get();
  }
  const auto start = std::chrono::steady_clock::now();
  const Bvh bvh = buildBvh(scene);
  const std::optional<MethodChoice> choice =
      o.method == "auto" && !debugView
          ? std::optional<MethodChoice>(choosePilotedMethod(devices, scene, bvh, camera, settings, links))
          : std::nullopt;
  const RenderResult r = debugView ? renderDebugView(aov, devices, scene, bvh, camera, settings, links)
                                   : renderOnEveryRank(o, devices, scene, bvh, camera, settings, links);
  if (rank != 0) return 0;  // rank 0 holds the film, and writes
  const std::string method = debugView ? "aov:" + o.aov : methodName(settings.method);
  reportDevices(r);
  if (!o.statsFile.empty() && !debugView) {
    nlohmann::json stats = nlohmann::json::parse(statsJson(r.stats, settings));
    if (choice) stats["method_choice"] = choiceJson(*choice);
    writeTextAtomically(o.statsFile, "--stats", stats.dump(2) + "\n");
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  // The film's samples per pixel (a noise target drops the passes finished past it), over
  // the image: an adaptive render's pixels have counts of their own.
  const double spp = debugView ? double(r.stats.samples) / double(r.film.pixels())
                               : r.film.samples() / double(r.film.pixels());
  const double estimatedRelMse = debugView ? 0.0 : r.film.estimatedRelMse();
  std::map<std::string, std::string> metadata = imageMetadata(o, scene, r, method, spp, seconds, estimatedRelMse);
  if (settings.adaptive) metadata["adaptive"] = "1";
  if (choice) metadata["method_choice"] = choiceMetadata(*choice);
  const Image image = r.film.imageWithLayers(layers);
  refuseNonFiniteImage(image);
  const std::string passes = std::to_string(r.film.passes()) + " passes";
  // The files, and the live view's last frame: the image as written.
  const auto deliver = [&](const std::map<std::string, std::string>& facts) {
    if (view) view->showFinal(image);
    return writeOutputs(o, settings, r.film, image, facts, denoiser.get());
  };
  if (r.stopped) {
    const int signal = links.stop->load();
    if (r.film.samples() == 0) throw Interrupted("before any pass was finished; nothing written", signal);
    metadata["incomplete"] = "interrupted by signal " + std::to_string(signal);
    throw Interrupted("wrote the " + passes + " finished so far to " + deliver(metadata) +
                          (o.checkpoint.empty() ? "" : " and a checkpoint to " + o.checkpoint +
                                                           " (go on with --resume " + o.checkpoint + ")"),
                      signal);
  }
  if (!r.complete) {
    metadata["incomplete"] = "every device failed";
    throw Error("every device failed before the render was complete; wrote the " + passes + " finished so far to " +
                deliver(metadata));
  }
  const std::string written = deliver(metadata);
  printSummary(o, settings, scene, r, image, method, spp, seconds, estimatedRelMse);
  plan.finish();
  std::cout << "wrote " << written << "\n";
  return 0;
}

}  // namespace fh
