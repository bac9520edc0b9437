// The path tracer's stages, listed once: each stage's kernel and the file under kernels/
// that holds it. The kernel's name is also its label in the timings (--stats "kernels").
// The program is assembled from these files, and the pipeline launches these kernels.
#pragma once
#include <array>
#include <cstddef>
#include <string>
#include <vector>

namespace fh {

enum class Stage { PlanIteration, Generate, Intersect, Shade, ShadowConnect, Accumulate, FinishIteration };

struct StageInfo {
  const char* kernel;
  const char* file;
};

// In the order an iteration runs them.
constexpr std::array<StageInfo, 7> kStages = {{
    {"plan_iteration", "iteration.cl"},  // the device's books: new samples, queue resets
    {"generate", "generate.cl"},         // camera rays for new samples in free path slots
    {"intersect", "intersect.cl"},       // closest hit for the current ray queue
    {"shade", "shade.cl"},               // emission, light-sample requests, BSDF sample, roulette
    {"shadow_connect", "shadow_connect.cl"},  // light sample and shadow ray per request (nee, mis)
    {"accumulate", "accumulate.cl"},     // finished paths into their pass's buffer; free slots
    {"finish_iteration", "iteration.cl"},  // the device's books: freed slots, ray totals
}};

constexpr const StageInfo& stageInfo(Stage s) { return kStages[size_t(s)]; }

// The megakernel strategy runs the books around one kernel that calls every stage between.
constexpr StageInfo kMegakernel = {"megakernel", "megakernel.cl"};

// The kernel files of every stage, each once, in stage order.
inline std::vector<std::string> stageFiles() {
  std::vector<std::string> files;
  for (const StageInfo& s : kStages) {
    bool seen = false;
    for (const auto& f : files) seen = seen || f == s.file;
    if (!seen) files.push_back(s.file);
  }
  return files;
}

}  // namespace fh
