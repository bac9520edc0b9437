// The pilot renders of --method auto and the choice between them.
#include "render/method_choice.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>

#include "render/render.h"

namespace fh {

std::string MethodChoice::describeCosts() const {
  std::string text;
  for (const MethodTrial& t : trials) {
    char cost[32];
    std::snprintf(cost, sizeof cost, "%.2e (%u spp)", t.cost(), t.passes);
    text += (text.empty() ? "" : ", ") + std::string(methodName(t.method)) + " " + cost;
  }
  return text;
}

std::vector<Method> methodsFor(const Scene& scene, const RenderSettings& s) {
  std::vector<Method> methods;
  if (scene.lights.empty() && !s.envMap) methods.push_back(Method::PT);
  methods.push_back(Method::MIS);
  const bool environment = s.env != std::array<float, 3>{0.f, 0.f, 0.f} || s.envMap;
  const bool lightPaths = !s.adaptive && !s.surfaceAovs;  // what neither lt nor bdpt can do
  if (!scene.lights.empty() && !environment && lightPaths) methods.push_back(Method::LT);
  if ((!scene.lights.empty() || s.envMap) && lightPaths) methods.push_back(Method::BDPT);
  return methods;
}

Method cheapestMethod(const std::vector<MethodTrial>& trials) {
  const auto mis = std::find_if(trials.begin(), trials.end(), [](const MethodTrial& t) { return t.method == Method::MIS; });
  if (mis == trials.end()) return Method::MIS;
  const MethodTrial* best = &*mis;
  for (const MethodTrial& t : trials)
    if (t.cost() < best->cost()) best = &t;
  return best->cost() < kChoiceMargin * mis->cost() ? best->method : Method::MIS;
}

int pilotSide(double samples, int imageSide) {
  const int largest = std::max(1, std::min(kMaxPilotSide, imageSide));
  // Square pixels count: the side's square bounds the pixels whatever the aspect.
  const double side = std::sqrt(std::max(samples, 0.0) / kMinPilotSpp);
  return std::clamp(int(side), std::min(kMinPilotSide, largest), largest);
}

namespace {

// The render's settings for a pilot of `method`: the image scaled to `side` pixels on its
// longer side (its aspect kept), `passes` passes or as many as `seconds` allow (0: no time
// budget), two replicates for the noise estimate, nothing saved or shown.
RenderSettings pilotSettings(const RenderSettings& s, Method method, int side, int passes, double seconds) {
  RenderSettings p = s;
  const double scale = std::min(1.0, double(side) / double(std::max(s.width, s.height)));
  p.width = std::max(1, int(std::lround(s.width * scale)));
  p.height = std::max(1, int(std::lround(s.height * scale)));
  p.method = method;
  p.spp = passes;
  p.firstPass = 0;
  p.seconds = seconds;
  // The least a pilot's estimate is worth: kMinPilotSpp passes of the smallest pilot's
  // pixels, in passes of this image (kNoiseMinPasses at least).
  p.minPasses = std::max(kNoiseMinPasses, unsigned(std::ceil(kLeastPilotSamples / (double(p.width) * p.height))));
  // A target no image meets but a black one: two replicates, and every pass rendered.
  p.noise = 1e-300;
  p.progress = false;
  p.checkpointPath.clear();
  return p;
}

// The seconds a render's samples take at its steady rate: its first pass, which compiles the
// method's kernels (or finds them cached) and waits for the devices to start, not counted, so
// that a pilot's cost does not depend on what an earlier run left in the program cache.
double steadySeconds(const RenderStats& st) {
  return st.steadySamplesPerSecond > 0 ? double(st.samples) / st.steadySamplesPerSecond : st.seconds;
}

}  // namespace

MethodChoice chooseMethod(const std::vector<DeviceInfo>& devices, const Scene& scene, const Bvh& bvh,
                          const Camera& camera, const RenderSettings& s, const std::atomic<int>* stop) {
  const auto start = std::chrono::steady_clock::now();
  MethodChoice choice;
  RenderLinks links;
  links.stop = stop;
  choice.candidates = methodsFor(scene, s);
  const std::vector<Method>& methods = choice.candidates;
  double perSecond = 0.0;
  if (!choice.alone()) {
    // mis's samples per second, from a short render, and so the render's expected time and
    // the pilots' samples.
    const RenderSettings timing = pilotSettings(s, Method::MIS, kMaxPilotSide / 2, int(kNoiseMinPasses), 0.0);
    const RenderResult timed = render(devices, scene, bvh, camera, timing, links);
    perSecond = double(timed.stats.samples) / steadySeconds(timed.stats);
    const double atMisSpeed = double(s.width) * s.height * s.spp / perSecond;
    choice.renderSeconds = s.seconds > 0 ? std::min(s.seconds, atMisSpeed) : atMisSpeed;
    // The smallest pilots at mis's steady speed: an estimate from below (slower methods take
    // longer, and each pilot sets up), so that pilots are left out only where they cannot pay.
    choice.leastPilotSeconds = double(methods.size()) * kLeastPilotSamples / perSecond;
  }
  if (choice.piloted()) {
    choice.pilotSeconds = kPilotShare * choice.renderSeconds / double(methods.size());
    const int side = pilotSide(choice.pilotSeconds * perSecond, std::max(s.width, s.height));
    for (Method method : methods) {
      if (links.stopRequested()) break;
      const RenderSettings p = pilotSettings(s, method, side, kMaxPilotSpp, choice.pilotSeconds);
      choice.pilotWidth = p.width;
      choice.pilotHeight = p.height;
      const RenderResult r = render(devices, scene, bvh, camera, p, links);
      if (r.stopped || !r.complete) break;
      choice.trials.push_back({method, steadySeconds(r.stats), r.film.estimatedRelMse(), unsigned(r.film.passes())});
    }
  }
  choice.method = cheapestMethod(choice.trials);  // mis where no pilot ran
  choice.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return choice;
}

}  // namespace fh
