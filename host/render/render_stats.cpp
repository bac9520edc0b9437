// The --stats JSON.
#include "render/render_stats.h"

#include <nlohmann/json.hpp>

namespace fh {
namespace {

nlohmann::json devicesJson(const RenderStats& st) {
  nlohmann::json list = nlohmann::json::array();
  for (const auto& d : st.devices) {
    nlohmann::json entry = {{"name", d.name},
                            {"samples", d.samples},
                            {"samples_per_second", d.busySeconds > 0 ? double(d.samples) / d.busySeconds : 0.0},
                            {"share", st.samples ? double(d.samples) / double(st.samples) : 0.0},
                            {"wavefront", d.wavefront},
                            {"strategy", d.strategy},
                            {"busy_seconds", d.busySeconds},
                            {"idle_seconds", d.idleSeconds}};
    if (!d.error.empty()) entry["error"] = d.error;
    list.push_back(entry);
  }
  return list;
}

}  // namespace

void RenderStats::add(const RenderStats& d) {
  nonfinite += d.nonfinite;
  cameraRays += d.cameraRays;
  bounceRays += d.bounceRays;
  shadowRays += d.shadowRays;
  iterations += d.iterations;
  queuedRays += d.queuedRays;
  slotIterations += d.slotIterations;
  wavefront += d.wavefront;
  for (const auto& [name, t] : d.stageSeconds) stageSeconds[name] += t;
}

std::string RenderStats::contributors() const {
  std::string names;
  for (const auto& d : devices)
    if (d.samples > 0) names += (names.empty() ? "" : ", ") + d.name;
  // A resumed render whose checkpoint held every pass asked for rendered on none.
  return names.empty() ? "no device (nothing left to render)" : names;
}

std::string statsJson(const RenderStats& st, const RenderSettings& s) {
  nlohmann::json kernels = nlohmann::json::object();
  double kernelTotal = 0.0;
  for (const auto& [name, seconds] : st.stageSeconds) kernelTotal += seconds;
  for (const auto& [name, seconds] : st.stageSeconds)
    kernels[name] = {{"seconds", seconds}, {"share", kernelTotal > 0 ? seconds / kernelTotal : 0.0}};
  const uint64_t rays = st.cameraRays + st.bounceRays + st.shadowRays;
  nlohmann::json doc = {
      {"samples", st.samples},
      {"seconds", st.seconds},
      {"samples_per_second", st.seconds > 0 ? double(st.samples) / st.seconds : 0.0},
      {"steady_samples_per_second", st.steadySamplesPerSecond},
      {"first_pass_seconds", st.firstPassSeconds},
      {"nonfinite_samples", st.nonfinite},
      {"devices", devicesJson(st)},
      {"method", methodName(s.method)},
      {"width", s.width},
      {"height", s.height},
      {"spp", s.width * s.height > 0 ? double(st.samples) / (double(s.width) * s.height) : 0.0},
      {"seed", s.seed},
      {"max_depth", s.maxDepth},
      {"rr_depth", s.rrDepth},
      {"filter", filterName(s.filter)},
      {"wavefront", st.wavefront},
      {"iterations", st.iterations},
      {"queue_occupancy", st.meanQueueOccupancy()},
      {"rays", {{"camera", st.cameraRays}, {"bounce", st.bounceRays}, {"shadow", st.shadowRays}, {"total", rays}}},
      {"rays_per_second", st.seconds > 0 ? double(rays) / st.seconds : 0.0},
      {"kernels", kernels}};
  if (s.method == Method::VCM) doc["merge_radius"] = s.mergeRadius;
  if (!st.ranks.empty()) {
    const double pixels = double(s.width) * double(s.height);
    nlohmann::json ranks = nlohmann::json::array();
    for (const auto& r : st.ranks)
      ranks.push_back({{"rank", r.rank},
                       {"passes", r.passes},
                       {"samples_per_second", r.seconds > 0 ? double(r.passes) * pixels / r.seconds : 0.0},
                       {"seconds", r.seconds},
                       {"idle_seconds", r.idleSeconds},
                       {"bytes_sent", r.bytesSent},
                       {"devices", r.devices}});
    doc["ranks"] = ranks;
  }
  return doc.dump(2);
}

}  // namespace fh
