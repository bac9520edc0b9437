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
    std::snprintf(cost, sizeof cost, "%.2e", t.cost());
    text += (text.empty() ? "" : ", ") + std::string(methodName(t.method)) + " " + cost;
  }
  return text;
}

std::vector<Method> methodsFor(const Scene& scene, const RenderSettings& s) {
  std::vector<Method> methods = {Method::PT, Method::NEE, Method::MIS};
  const bool environment = s.env != std::array<float, 3>{0.f, 0.f, 0.f} || s.envMap;
  if (!scene.lights.empty() && !environment && !s.adaptive && !s.surfaceAovs) methods.push_back(Method::LT);
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

namespace {

// The render's settings for a pilot of `method`: the image scaled down (its aspect kept), a
// fixed pass count with two replicates for the noise estimate, nothing saved or shown.
RenderSettings pilotSettings(const RenderSettings& s, Method method) {
  RenderSettings p = s;
  const double scale = std::min(1.0, double(kPilotSide) / double(std::max(s.width, s.height)));
  p.width = std::max(1, int(std::lround(s.width * scale)));
  p.height = std::max(1, int(std::lround(s.height * scale)));
  p.method = method;
  p.spp = kPilotSpp;
  p.firstPass = 0;
  p.seconds = 0.0;
  // A target no image meets but a black one: two replicates, and every pass rendered.
  p.noise = 1e-300;
  p.progress = false;
  p.checkpointPath.clear();
  return p;
}

}  // namespace

MethodChoice chooseMethod(const std::vector<DeviceInfo>& devices, const Scene& scene, const Bvh& bvh,
                          const Camera& camera, const RenderSettings& s, const std::atomic<int>* stop) {
  const auto start = std::chrono::steady_clock::now();
  MethodChoice choice;
  RenderLinks links;
  links.stop = stop;
  for (Method method : methodsFor(scene, s)) {
    const RenderSettings p = pilotSettings(s, method);
    choice.pilotWidth = p.width;
    choice.pilotHeight = p.height;
    const RenderResult r = render(devices, scene, bvh, camera, p, links);
    if (r.stopped || !r.complete) break;
    choice.trials.push_back({method, r.stats.seconds, r.film.estimatedRelMse()});
  }
  choice.method = cheapestMethod(choice.trials);
  choice.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return choice;
}

}  // namespace fh
