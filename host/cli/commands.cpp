// The small subcommands: devices, compare, reference and export, and the scene specs
// every command accepts.
#include <filesystem>
#include <iostream>

#include <nlohmann/json.hpp>

#include "base/output_plan.h"
#include "bench/bench_scenes.h"
#include "cli/commands.h"
#include "device/devices.h"
#include "image/error_metrics.h"
#include "image/image_io.h"
#include "scene/closed_form.h"
#include "scene/scene_loader.h"
#include "scene/scene_writer.h"

namespace fh {

void printWarnings(const Scene& scene) {
  for (const auto& w : scene.warnings) std::cerr << "fredholm: warning: " << w << "\n";
}

// An OBJ path, builtin:NAME, bench:NAME (a bench scene), or nothing for the Cornell box.
Scene loadSceneSpec(const std::string& spec) {
  if (spec.empty()) return loadDefaultScene();
  if (spec.rfind("bench:", 0) == 0) {
    std::string name;
    return benchScene(spec.substr(6), name);
  }
  return isBuiltinSpec(spec) ? builtinScene(spec) : loadScene(spec);
}

int runDevices(const std::string& spec) {
  const auto all = listDevices();
  std::cout << formatDeviceTable(spec.empty() ? all : selectDevices(all, spec));
  return 0;
}

int runCompare(const CompareOptions& o) {
  if (o.block < 1) throw Error("--block must be at least 1");
  Image image = readImage(o.image, "compare"), reference = readImage(o.reference, "compare");
  requireFinite(image, "compare '" + o.image + "'");
  requireFinite(reference, "compare '" + o.reference + "'");
  if (o.block > 1) {
    try {
      image = blockAverage(image, o.block);
      reference = blockAverage(reference, o.block);
    } catch (const Error& e) {
      throw Error(std::string("--block: ") + e.what());
    }
  }
  const ImageError e = imageError(image, reference);
  const nlohmann::json out = {{"relmse", e.relMse}, {"rmse", e.rmse}, {"mae", e.mae},
                              {"mean_image", e.meanImage}, {"mean_reference", e.meanReference},
                              {"block", o.block}};
  std::cout << out.dump() << "\n";
  return 0;
}

int runReference(const ReferenceOptions& o) {
  checkImageExtension(o.output, "-o");
  if (o.width <= 0 || o.height <= 0) throw Error("--width/--height must be positive");
  OutputPlan plan(o.force);
  plan.add(o.output, "-o");
  plan.reserve();
  const std::string written =
      writeImage(o.output, builtinReference(o.scene, o.width, o.height), {{"scene", o.scene}, {"method", "exact"}});
  plan.finish();
  std::cout << "wrote " << written << "\n";
  return 0;
}

int runExport(const ExportOptions& o) {
  const Scene scene = loadSceneSpec(o.scene);
  printWarnings(scene);
  for (const std::string& written : writeObjScene(scene, o.output, o.force)) std::cout << "wrote " << written << "\n";
  return 0;
}

}  // namespace fh
