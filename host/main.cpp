// The fredholm command line: `devices`, `render`, `bench`, `compare`, `reference` and `export`.
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <chrono>
#include <optional>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "bench.h"
#include "bvh.h"
#include "devices.h"
#include "error.h"
#include "image_io.h"
#include "closed_form.h"
#include "device_scene.h"
#include "error_metrics.h"
#include "multi_device.h"
#include "path_tracer.h"
#include "render_aov.h"
#include "scene_loader.h"
#include "scene_writer.h"
#include "vec.h"
#ifdef FREDHOLM_HAVE_EMBREE
#include "embree_tracer.h"
#endif

namespace {

using namespace fh;

struct RenderOptions {
  std::string scene;
  std::string output;
  bool force = false;
  int width = 512, height = 512, spp = 0;
  double seconds = 0.0;
  std::string method = "mis", filter = "box", env, statsFile;
  int maxDepth = 64;
  size_t wavefront = 0;
  bool allFeatures = false;
  unsigned seed = 1;
  std::string cameraFile, eye, target, up;
  std::optional<float> fov;
  std::string aov;
  std::string device;
};

void printWarnings(const Scene& scene) {
  for (const auto& w : scene.warnings) std::cerr << "fredholm: warning: " << w << "\n";
}

// --camera FILE, else the scene's sidecar, else framing; then --eye/--target/--up/--fov override.
Camera chooseCamera(const RenderOptions& o, const Scene& scene) {
  Camera camera;
  bool framed = false;
  if (!o.cameraFile.empty()) {
    camera = loadCameraJson(o.cameraFile);
  } else if (scene.hasCamera) {
    camera = scene.camera;
  } else {
    Vec3f lo, hi;
    scene.bounds(lo, hi);
    camera = frameBounds(lo, hi);
    framed = true;
    if (o.eye.empty() || o.target.empty())
      std::cerr << "fredholm: no camera given (--camera, --eye/--target, or a .camera.json beside the OBJ): "
                   "framing the scene's bounds\n";
  }
  if (!o.eye.empty()) camera.eye = parseVec3Flag("--eye", o.eye);
  if (!o.target.empty()) camera.target = parseVec3Flag("--target", o.target);
  if (!o.up.empty()) camera.up = parseVec3Flag("--up", o.up);
  if (o.fov) camera.fovYDeg = *o.fov;
  if (framed && (!isFinite(camera.eye) || !isFinite(camera.target)))
    throw Error(scene.sourcePath + ": the scene's bounds are too large to frame a camera; give --camera or "
                                   "--eye/--target");
  validateCamera(camera, o.fov ? "--fov" : "camera");
  return camera;
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

std::string formatSeconds(double s) {
  std::ostringstream out;
  out << std::fixed << std::setprecision(2) << s;
  return out.str();
}

int runRender(RenderOptions o) {
  // Every flag is checked before any work starts.
  const bool debugView = !o.aov.empty();
  const Aov aov = debugView ? parseAov(o.aov) : Aov::Albedo;
  RenderSettings settings;
  settings.method = parseMethod(o.method);
  settings.filter = parseFilter(o.filter);
  if (!o.env.empty()) settings.env = parseVec3Flag("--env", o.env);
  if (o.width <= 0 || o.height <= 0) throw Error("--width/--height must be positive");
  // Pixels are indexed in 32 bits on the device, with room for several pass buffers.
  if (uint64_t(o.width) * uint64_t(o.height) > (uint64_t(1) << 28))
    throw Error("--width/--height: " + std::to_string(o.width) + "x" + std::to_string(o.height) +
                " is more than the 268 million pixels fredholm renders in one image");
  if (o.spp < 0) throw Error("--spp must be positive");
  if (o.seconds < 0) throw Error("--time must be positive");
  if (o.maxDepth < 1) throw Error("--max-depth must be at least 1");
  if (o.wavefront != 0 && o.wavefront < kLocalSize) throw Error("--wavefront must be at least 64");
  // With --time and no --spp, the time decides; otherwise 64 spp by default.
  // (A render numbers its samples in 32 bits: a time budget may take at most that many.)
  const uint64_t pixels = uint64_t(o.width) * uint64_t(o.height);
  const int spp = o.spp > 0 ? o.spp
                            : (o.seconds > 0 ? int(std::min<uint64_t>(1 << 20, 0xFFFFFFFFull / pixels))
                                             : (debugView ? 4 : 64));
  // An explicit -o is never overwritten without --force; the default name steps aside.
  if (o.output.empty()) o.output = firstFreeName("fredholm.png");
  checkOutputPath(o.output, o.force);
  if (!o.statsFile.empty()) checkOutputFile(o.statsFile, o.force, "--stats");

  const auto devices = selectDevices(listDevices(), o.device);

  const Scene scene = loadSceneSpec(o.scene);
  printWarnings(scene);
  const Camera camera = chooseCamera(o, scene);
  const auto start = std::chrono::steady_clock::now();
  const Bvh bvh = buildBvh(scene);
  Image image;
  std::string method;
  uint64_t samples = 0;
  if (debugView) {
    AovSettings a;
    a.width = o.width;
    a.height = o.height;
    a.spp = spp;
    a.seed = o.seed;
    a.mode = aov;
    DeviceContext dc(devices[0]);
    image = renderAov(dc, scene, bvh, camera, a);
    method = "aov:" + o.aov;
    samples = uint64_t(spp) * uint64_t(o.width) * uint64_t(o.height);
  } else {
    settings.width = o.width;
    settings.height = o.height;
    settings.spp = spp;
    settings.seconds = o.seconds;
    settings.maxDepth = o.maxDepth;
    settings.seed = o.seed;
    settings.wavefront = o.wavefront;
    settings.allFeatures = o.allFeatures;
    settings.progress = true;
    RenderStats stats;
    bool complete = true;
    if (devices.size() == 1) {
      DeviceContext dc(devices[0]);
      PathTracer tracer(dc, scene, bvh, camera, settings);
      image = tracer.render().image();
      stats = tracer.stats();
    } else {
      MultiDeviceResult r = renderOnDevices(devices, scene, bvh, camera, settings);
      image = r.film.image();
      stats = r.stats;
      complete = r.complete;
      for (const auto& d : stats.devices)
        if (!d.error.empty())
          std::cerr << "fredholm: warning: device " << d.name << " failed: " << d.error
                    << (complete ? "; the other devices rendered its passes" : "") << "\n";
    }
    method = methodName(settings.method);
    samples = stats.samples;
    if (stats.nonfinite)
      std::cerr << "fredholm: warning: " << stats.nonfinite << " samples were NaN or infinite and dropped\n";
    if (!o.statsFile.empty()) {
      std::ofstream out(o.statsFile);
      out << statsJson(stats, settings) << "\n";
      if (!out) throw Error("--stats '" + o.statsFile + "': cannot write");
    }
    if (!complete) {
      writeImage(o.output, image, {{"scene", scene.sourcePath}, {"method", methodName(settings.method)},
                                   {"incomplete", "every device failed"}});
      throw Error("every device failed before the render was complete; wrote the " +
                  std::to_string(samples / (uint64_t(o.width) * o.height)) + " passes finished so far to " +
                  o.output);
    }
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const double spp_done = double(samples) / (double(o.width) * o.height);
  writeImage(o.output, image,
             {{"scene", scene.sourcePath}, {"spp", formatSeconds(spp_done)}, {"method", method},
              {"device", devices[0].name}, {"seed", std::to_string(o.seed)}, {"seconds", formatSeconds(seconds)},
              {"filter", o.filter}, {"max_depth", std::to_string(o.maxDepth)}});
  std::cerr << "fredholm: rendered " << scene.sourcePath << " (" << scene.triangleCount() << " triangles, "
            << scene.lights.size() << " emissive; " << (o.allFeatures ? "all features" : sceneFeatures(scene).describe())
            << ") with " << method << ", " << o.width << "x" << o.height << ", "
            << spp_done << " spp on " << devices[0].name << " in " << formatSeconds(seconds) << " s\n";
  std::cout << "wrote " << o.output << "\n";
  return 0;
}

struct CompareOptions {
  std::string image, reference;
  int block = 1;
};

int runCompare(const CompareOptions& o) {
  for (const std::string* path : {&o.image, &o.reference})
    if (!std::filesystem::is_regular_file(*path)) throw Error(*path + ": image not found");
  if (o.block < 1) throw Error("--block must be at least 1");
  Image image = readImage(o.image), reference = readImage(o.reference);
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

struct ReferenceOptions {
  std::string scene, output;
  int width = 128, height = 128;
  bool force = false;
};

int runReference(const ReferenceOptions& o) {
  checkOutputPath(o.output, o.force);
  if (o.width <= 0 || o.height <= 0) throw Error("--width/--height must be positive");
  writeImage(o.output, builtinReference(o.scene, o.width, o.height), {{"scene", o.scene}, {"method", "exact"}});
  std::cout << "wrote " << o.output << "\n";
  return 0;
}

struct ExportOptions {
  std::string scene, output;
  bool force = false;
};

int runExport(const ExportOptions& o) {
  const Scene scene = loadSceneSpec(o.scene);
  printWarnings(scene);
  for (const std::string& written : writeObjScene(scene, o.output, o.force)) std::cout << "wrote " << written << "\n";
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"fredholm: an OpenCL wavefront path tracer"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "fredholm " FREDHOLM_VERSION);

  std::string devicesSpec;
  auto* devices = app.add_subcommand("devices", "List OpenCL platforms and devices");
  devices->add_option("--device", devicesSpec, "Show only the devices SPEC selects");

  RenderOptions render;
  auto* rendering = app.add_subcommand("render", "Render an OBJ scene (default: the built-in Cornell box)");
  rendering->add_option("scene", render.scene, "OBJ file");
  rendering->add_option("-o,--output", render.output,
                        "Output image (.exr .hdr .pfm .png .jpg); default fredholm.png, or the next free "
                        "fredholm-N.png");
  rendering->add_flag("--force", render.force, "Overwrite an existing output file");
  rendering->add_option("--width", render.width, "Image width in pixels")->capture_default_str();
  rendering->add_option("--height", render.height, "Image height in pixels")->capture_default_str();
  rendering->add_option("--spp", render.spp, "Samples per pixel (default 64; with --time, the most to take)");
  rendering->add_option("--time", render.seconds, "Time budget in seconds (finishes the pass running then)");
  rendering->add_option("--method", render.method, "pt (BRDF sampling), nee (light sampling) or mis (both)")
      ->capture_default_str();
  rendering->add_option("--max-depth", render.maxDepth, "Most bounces (Russian roulette ends most paths sooner)")
      ->capture_default_str();
  rendering->add_option("--env", render.env, "Constant environment radiance R,G,B (default black)");
  rendering->add_option("--filter", render.filter, "Pixel filter: box, gaussian or blackman-harris")
      ->capture_default_str();
  rendering->add_option("--wavefront", render.wavefront, "Paths in flight (default: chosen for the device)");
  rendering->add_option("--stats", render.statsFile, "Write render statistics as JSON");
  rendering->add_flag("--all-features", render.allFeatures,
                      "Compile every material feature, not only the scene's (to measure specialization)");
  rendering->add_option("--seed", render.seed, "Random seed")->capture_default_str();
  rendering->add_option("--camera", render.cameraFile, "Camera JSON {eye,target,up,fov_y_deg}");
  rendering->add_option("--eye", render.eye, "Camera position x,y,z");
  rendering->add_option("--target", render.target, "Point the camera looks at x,y,z");
  rendering->add_option("--up", render.up, "Camera up vector x,y,z");
  rendering->add_option("--fov", render.fov, "Vertical field of view in degrees");
  rendering->add_option("--aov", render.aov, "Debug view instead of light transport: albedo, normal or depth");
  rendering->add_option("--device", render.device, "Device: index, list (0,1), type (cpu, gpu, all) or name");

  BenchOptions bench;
  auto* benching = app.add_subcommand("bench", "Measure ray-casting throughput (Mrays/s) per scene and ray kind");
  benching->add_option("scenes", bench.scenes,
                       "Scenes: cornell, bunny-box, sponza, bunnies-1m, or OBJ files (default: all four)");
  benching->add_option("--device", bench.device, "Device: index, type or name (the first match is used)");
  benching->add_option("--json", bench.jsonPath, "Write the results as JSON");
  benching->add_flag("--force", bench.force, "Overwrite an existing --json file");
  benching->add_option("--width", bench.width, "Primary rays per batch: width x height")->capture_default_str();
  benching->add_option("--height", bench.height, "Primary rays per batch: width x height")->capture_default_str();
  benching->add_option("--repeats", bench.repeats, "Timed runs after a warm-up (median reported)")
      ->capture_default_str();
  benching->add_option("--threads", bench.threads, "Threads for the external tracer")->capture_default_str();
#ifdef FREDHOLM_HAVE_EMBREE
  bench.external = makeEmbreeTracer;
#endif

  CompareOptions compare;
  auto* comparing = app.add_subcommand(
      "compare", "Error of an image against a reference as JSON: relMSE, RMSE, MAE and each image's channel means");
  comparing->add_option("image", compare.image, "Rendered image (.exr .hdr .pfm ...)")->required();
  comparing->add_option("reference", compare.reference, "Reference image of the same size")->required();
  comparing->add_option("--block", compare.block, "Average KxK pixel blocks of both first (K divides the size)")
      ->capture_default_str();

  ReferenceOptions reference;
  auto* referencing = app.add_subcommand("reference", "Write the exact image of a closed-form scene (builtin:NAME)");
  referencing->add_option("scene", reference.scene, "builtin:plane-under-light")->required();
  referencing->add_option("-o,--output", reference.output, "Output image")->required();
  referencing->add_option("--width", reference.width, "Image width")->capture_default_str();
  referencing->add_option("--height", reference.height, "Image height")->capture_default_str();
  referencing->add_flag("--force", reference.force, "Overwrite an existing output file");

  ExportOptions exporting;
  auto* exporter = app.add_subcommand(
      "export", "Write a scene (an OBJ, or builtin:NAME) as OBJ + MTL + camera.json, e.g. for another renderer");
  exporter->add_option("scene", exporting.scene, "OBJ file or builtin:plane-under-light (default: the Cornell box)");
  exporter->add_option("-o,--output", exporting.output, "Output .obj (the .mtl and .camera.json go beside it)")
      ->required();
  exporter->add_flag("--force", exporting.force, "Overwrite existing files");

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  try {
    if (*devices) return runDevices(devicesSpec);
    if (*rendering) return runRender(render);
    if (*benching) return runBench(bench);
    if (*referencing) return runReference(reference);
    if (*comparing) return runCompare(compare);
    if (*exporter) return runExport(exporting);
  } catch (const BuildError& e) {
    std::cerr << "fredholm: error: " << e.what() << "\n";
    return 1;
  } catch (const Error& e) {
    std::cerr << "fredholm: error: " << e.what() << "\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "fredholm: internal error: " << e.what() << "\n";
    return 3;
  }
  return 0;
}
