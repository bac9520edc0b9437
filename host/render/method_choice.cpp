// The pilot renders of --method auto and the choice between them.
#include "render/method_choice.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>

#include "base/error.h"
#include "image/error_metrics.h"
#include "image/neighbourhood.h"
#include "render/device_scene.h"
#include "render/light_tracer.h"
#include "render/render.h"

namespace fh {

std::string MethodChoice::describeCosts() const {
  std::string text;
  for (const MethodTrial& t : trials) {
    char cost[48];
    std::snprintf(cost, sizeof cost, "%.2e / %.2e (%u spp)", t.cost(), t.crossCost(), t.passes);
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
  // vcm where it merges (glass, mirrors): bdpt's strategies and merging too, at about
  // bdpt's time a sample. Elsewhere it would be bdpt again.
  const Method joined = mergesLightVertices(Method::VCM, hasDeltaLobes(scene)) ? Method::VCM : Method::BDPT;
  if ((!scene.lights.empty() || s.envMap) && lightPaths) methods.push_back(joined);
  return methods;
}

Method cheapestMethod(const std::vector<MethodTrial>& trials) {
  const auto mis = std::find_if(trials.begin(), trials.end(), [](const MethodTrial& t) { return t.method == Method::MIS; });
  if (mis == trials.end()) return Method::MIS;
  const bool judged = std::any_of(trials.begin(), trials.end(), [](const MethodTrial& t) { return t.crossRelMse > 0; });
  const MethodTrial* best = &*mis;
  for (const MethodTrial& t : trials)
    if (t.cost() < best->cost() && (!judged || t.crossCost() < kChoiceMargin * mis->crossCost())) best = &t;
  return best->cost() < kChoiceMargin * mis->cost() ? best->method : Method::MIS;
}

std::vector<double> crossRelMse(const std::vector<Image>& pilots, const std::vector<double>& own) {
  const size_t n = pilots.size();
  std::vector<double> cross(n, 0.0);
  if (n < 2) return cross;
  const size_t values = pilots[0].rgb.size();
  for (const Image& p : pilots)
    if (p.width != pilots[0].width || p.height != pilots[0].height || p.rgb.size() != 3 * size_t(p.width) * p.height)
      throw Error("method choice: pilot images of different sizes");
  // d[i][j]: the mean squared difference of pilots i and j, relative to their mean image
  // averaged over each pixel's 3x3 neighbourhood: a pixel's own noise in the divisor would
  // raise every d (the mean of 1 / x^2 exceeds 1 / mean^2).
  std::vector<double> mean(values, 0.0);
  for (const Image& p : pilots)
    for (size_t v = 0; v < values; ++v) mean[v] += double(p.rgb[v]) / double(n);
  const std::vector<double> level = neighbourhoodMean(mean, pilots[0].width, pilots[0].height, 1, 3);
  std::vector<std::vector<double>> d(n, std::vector<double>(n, 0.0));
  for (size_t v = 0; v < values; ++v) {
    const double scale = 1.0 / (level[v] * level[v] + kRelMseEpsilon);
    for (size_t i = 0; i < n; ++i)
      for (size_t j = i + 1; j < n; ++j) {
        const double diff = double(pilots[i].rgb[v]) - double(pilots[j].rgb[v]);
        d[i][j] += diff * diff * scale;
      }
  }
  double total = 0.0;  // the sum over pairs
  for (size_t i = 0; i < n; ++i)
    for (size_t j = i + 1; j < n; ++j) {
      d[i][j] /= double(std::max<size_t>(values, 1));
      d[j][i] = d[i][j];
      total += d[i][j];
    }
  for (size_t i = 0; i < n; ++i) {
    if (n == 2) {
      cross[i] = d[0][1] - own[1 - i];
    } else {
      // Least squares of d_ij = e_i + e_j over the pairs: with S_i the sum of i's pairs and
      // T that of all, e_i = (S_i - T / (n - 1)) / (n - 2).
      double pairs = 0.0;
      for (size_t j = 0; j < n; ++j) pairs += d[i][j];
      cross[i] = (pairs - total / double(n - 1)) / double(n - 2);
    }
    cross[i] = std::max(cross[i], 0.0);
  }
  return cross;
}

void judgePilots(std::vector<MethodTrial>& trials, const std::vector<Image>& images) {
  std::vector<double> own;
  for (const MethodTrial& t : trials) own.push_back(t.relMse);
  const std::vector<double> cross = crossRelMse(images, own);
  for (size_t i = 0; i < trials.size(); ++i) trials[i].crossRelMse = cross[i];
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
    std::vector<Image> images;
    for (Method method : methods) {
      if (links.stopRequested()) break;
      RenderSettings p = pilotSettings(s, method, side, kMaxPilotSpp, choice.pilotSeconds);
      // A seed of its own: the pilots' errors independent, as judgePilots needs (mis's and
      // bdpt's camera paths would otherwise draw the same numbers).
      p.seed = s.seed + 1u + unsigned(images.size());
      choice.pilotWidth = p.width;
      choice.pilotHeight = p.height;
      const RenderResult r = render(devices, scene, bvh, camera, p, links);
      if (r.stopped || !r.complete) break;
      choice.trials.push_back({method, steadySeconds(r.stats), r.film.typicalRelMse(), unsigned(r.film.passes()), 0.0,
                               r.film.estimatedRelMse()});
      images.push_back(r.film.image());
    }
    if (choice.trials.size() == methods.size()) judgePilots(choice.trials, images);
  }
  choice.method = cheapestMethod(choice.trials);  // mis where no pilot ran
  choice.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return choice;
}

}  // namespace fh
