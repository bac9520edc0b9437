// The fredholm command line: flags for `devices`, `render`, `bench`, `compare`,
// `reference` and `export`, parsed by CLI11 and handed to the subcommands (commands.h).
#include <CLI/CLI.hpp>

#include <iostream>

#include "bench/bench.h"
#include "cli/commands.h"
#include "cli/parse_errors.h"
#include "device/devices.h"
#include "device/program.h"
#ifdef FREDHOLM_HAVE_EMBREE
#include "embree_tracer.h"
#endif
#ifdef FREDHOLM_HAVE_MPI
#include <memory>

#include "distributed/mpi_render.h"
#endif

using namespace fh;

// --device takes the same SPEC in every command (device/devices.h).
constexpr const char* kDeviceSpec = "index (0), list (0,1), type (cpu, gpu, all) or name";

namespace {

CLI::App* addDevices(CLI::App& app, std::string& o) {
  CLI::App* devices = app.add_subcommand("devices", "List OpenCL platforms and devices");
  devices->add_option("--device", o, std::string("Show only these devices: ") + kDeviceSpec);
  return devices;
}

CLI::App* addRender(CLI::App& app, RenderOptions& o) {
  CLI::App* rendering = app.add_subcommand("render", "Render an OBJ scene (default: the built-in Cornell box)");
  rendering->add_option("scene", o.scene, "OBJ file");
  rendering->add_option("-o,--output", o.output,
                        "Output image (.exr .hdr .pfm .png .jpg); default fredholm.png, or the next free "
                        "fredholm-N.png");
  rendering->add_flag("--force", o.force, "Overwrite an existing output file");
  rendering->add_option("--width", o.width, "Image width in pixels")->capture_default_str();
  rendering->add_option("--height", o.height, "Image height in pixels")->capture_default_str();
  rendering->add_option("--spp", o.spp, "Samples per pixel (default 64; with --time, the most to take)");
  rendering->add_option("--time", o.seconds, "Time budget in seconds (finishes the pass running then)");
  rendering->add_option("--method", o.method, "pt (BRDF sampling), nee (light sampling), mis (both), lt (light tracing), bdpt (bidirectional), vcm (bdpt with vertex merging: caustics seen through glass) or auto (a pilot render with each, then the one with the least error per second)")
      ->capture_default_str();
  rendering->add_option("--noise", o.noise,
                        "Stop once the image's relMSE, estimated from two independently scrambled halves of the "
                        "samples (even and odd passes), is at most this (e.g. 1e-3); --spp and --time still cap it");
  rendering->add_flag("--adaptive", o.adaptive,
                      "Adaptive sampling: after 16 passes over every pixel, spend samples where the estimated "
                      "error falls fastest (--spp is then the image's average, a budget)");
  rendering->add_option("--max-depth", o.maxDepth, "Most bounces (Russian roulette ends most paths sooner)")
      ->capture_default_str();
  rendering->add_option("--rr-depth", o.rrDepth,
                        "Russian roulette decides whether paths go on from this bounce on (Mitsuba's rr_depth 5 "
                        "is 6 here)")
      ->capture_default_str();
  rendering->add_option("--merge-radius", o.mergeRadius,
                        "vcm: the first pass's merging radius as a fraction of the scene's bounding radius (default "
                        "0.01; it shrinks pass by pass). Larger: less noise, more blur in caustics");
  rendering->add_option("--env", o.env, "Constant environment radiance R,G,B (default black)");
  rendering->add_option("--env-map", o.envMap,
                        "HDR environment light: a latitude-longitude .exr or .hdr (+y up; the image's centre "
                        "along -z, where the default camera looks), importance-sampled like the lights");
  rendering->add_option("--env-rotate", o.envRotate,
                        "Turn --env-map about the up axis by DEG (counter-clockwise seen from above)");
  rendering->add_option("--env-scale", o.envScale, "Multiply --env-map's radiance by S");
  rendering->add_option("--filter", o.filter, "Pixel filter: box, gaussian or blackman-harris")
      ->capture_default_str();
  rendering->add_option("--wavefront", o.wavefront, "Paths in flight (default: chosen for the device)");
  rendering->add_option("--stats", o.statsFile, "Write render statistics as JSON");
  rendering->add_option("--strategy", o.strategy,
                        "How devices run the stages: auto (by device type), scalar (a kernel per stage, one path "
                        "per work-item; GPUs), simd8 (a kernel per stage, eight paths per work-item in vector "
                        "lanes), megakernel or megakernel8 (every stage in one kernel, one or eight paths per "
                        "work-item; megakernel8 for CPUs)")
      ->capture_default_str();
  rendering->add_flag("--all-features", o.allFeatures,
                      "Compile every material feature, not only the scene's (to measure specialization)");
  rendering->add_option("--seed", o.seed, "Random seed, 0 to 4294967295")->capture_default_str();
  rendering->add_option("--camera", o.cameraFile, "Camera JSON {eye,target,up,fov_y_deg}");
  rendering->add_option("--eye", o.eye, "Camera position x,y,z");
  rendering->add_option("--target", o.target, "Point the camera looks at x,y,z");
  rendering->add_option("--up", o.up, "Camera up vector x,y,z");
  rendering->add_option("--fov", o.fov, "Vertical field of view in degrees");
  rendering->add_option("--aov", o.aov, "Debug view instead of light transport: albedo, normal or depth");
  rendering->add_option("--aovs", o.aovs,
                        "Layers written beside the image in one EXR, from the same render: albedo, normal "
                        "(first non-specular surface), depth (camera ray), variance (of each pixel's mean), "
                        "spp; e.g. albedo,normal,depth");
  rendering->add_flag("--denoise", o.denoise,
                      "Also write NAME.denoised.EXT beside the image -o names: Intel Open Image Denoise's RT "
                      "filter on the radiance, guided by the first-surface albedo and normal");
  rendering->add_option("--display-server", o.displayServer,
                        "Stream the image as it converges to the tev viewer listening at HOST:PORT (tev's "
                        "default port is 14158); a viewer that is not there or goes away is a warning");
  rendering->add_option("--checkpoint", o.checkpoint,
                        "Save the render so far to FILE every --checkpoint-every seconds and when it ends "
                        "(also on Ctrl-C), to go on from with --resume");
  rendering->add_option("--checkpoint-every", o.checkpointEvery,
                        "Seconds between checkpoints (default " +
                            std::to_string(int(RenderSettings{}.checkpointSeconds)) + ")");
  rendering->add_option("--resume", o.resume,
                        "Go on from a checkpoint of the same scene and settings (--spp may be raised): the image "
                        "is the one an uninterrupted render gives");
  rendering->add_option("--passes", o.passes,
                        "Render only passes A to B-1 of the render (A:B; pass n is every pixel's sample n) into "
                        "--film, a chunk that fredholm merge combines with the others into the image of all");
  rendering->add_option("--film", o.film,
                        "Save the render's film (its sums, passes and fingerprint) to FILE for fredholm merge; "
                        "with it, an image is written only if -o is given");
  rendering->add_option("--device", o.device,
                        std::string("Devices sharing the render (--aov: one): ") + kDeviceSpec);
  return rendering;
}

CLI::App* addBench(CLI::App& app, BenchOptions& o) {
  CLI::App* benching = app.add_subcommand("bench", "Measure ray-casting throughput (Mrays/s) per scene and ray kind");
  benching->add_option("scenes", o.scenes,
                       "Scenes: cornell, bunny-box, sponza, bunnies-1m, spheres:N (about N generated triangles, e.g. "
                       "spheres:1e6), or OBJ files (default: the first four)");
  benching->add_option("--device", o.device,
                       std::string("Devices to measure, a row each: ") + kDeviceSpec);
  benching->add_option("--json", o.jsonPath, "Write the results as JSON");
  benching->add_flag("--force", o.force, "Overwrite an existing --json file");
  benching->add_option("--width", o.width, "Primary rays per batch: width x height")->capture_default_str();
  benching->add_option("--height", o.height, "Primary rays per batch: width x height")->capture_default_str();
  benching->add_option("--repeats", o.repeats, "Timed runs after a warm-up (median reported)")
      ->capture_default_str();
  benching->add_option("--threads", o.threads, "Threads for the external tracer")->capture_default_str();
#ifdef FREDHOLM_HAVE_EMBREE
  o.external = makeEmbreeTracer;
#endif
  return benching;
}

CLI::App* addMerge(CLI::App& app, MergeOptions& o) {
  CLI::App* merging = app.add_subcommand(
      "merge", "Combine the films of chunks of one render (render --passes A:B --film FILE) into its image: the "
               "same bits as one render of all their passes");
  merging->add_option("parts", o.parts, "Film files, in any order")->required();
  merging->add_option("-o,--output", o.output, "Output image (.exr .hdr .pfm .png .jpg)")->required();
  merging->add_option("--aovs", o.aovs, "Layers beside the image, as for render (the chunks must have recorded them)");
  merging->add_flag("--force", o.force, "Overwrite an existing output file");
  return merging;
}

CLI::App* addCompare(CLI::App& app, CompareOptions& o) {
  CLI::App* comparing = app.add_subcommand(
      "compare", "Error of an image against a reference as JSON: relMSE, RMSE, MAE and each image's channel means");
  comparing->add_option("image", o.image, "Rendered image (.exr .hdr .pfm ...)")->required();
  comparing->add_option("reference", o.reference, "Reference image of the same size")->required();
  comparing->add_option("--block", o.block, "Average KxK pixel blocks of both first (K divides the size)")
      ->capture_default_str();
  return comparing;
}

CLI::App* addReference(CLI::App& app, ReferenceOptions& o) {
  CLI::App* referencing = app.add_subcommand("reference", "Write the exact image of a closed-form scene (builtin:NAME)");
  referencing->add_option("scene", o.scene, "builtin:plane-under-light")->required();
  referencing->add_option("-o,--output", o.output, "Output image")->required();
  referencing->add_option("--width", o.width, "Image width")->capture_default_str();
  referencing->add_option("--height", o.height, "Image height")->capture_default_str();
  referencing->add_flag("--force", o.force, "Overwrite an existing output file");
  return referencing;
}

CLI::App* addExport(CLI::App& app, ExportOptions& o) {
  CLI::App* exporter = app.add_subcommand(
      "export", "Write a scene (an OBJ, or builtin:NAME) as OBJ + MTL + camera.json, e.g. for another renderer");
  exporter->add_option("scene", o.scene, "OBJ file or builtin:plane-under-light (default: the Cornell box)");
  exporter->add_option("-o,--output", o.output, "Output .obj (the .mtl and .camera.json go beside it)")
      ->required();
  exporter->add_flag("--force", o.force, "Overwrite existing files");
  return exporter;
}

}  // namespace

int main(int argc, char** argv) {
  pinCpuWorkersWhereSafe();
  CLI::App app{"fredholm: an OpenCL wavefront path tracer"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "fredholm " FREDHOLM_VERSION);
  std::string devicesSpec;
  RenderOptions render;
  BenchOptions bench;
  CompareOptions compare;
  ReferenceOptions reference;
  ExportOptions exporting;
  MergeOptions merge;
  CLI::App* devices = addDevices(app, devicesSpec);
  CLI::App* rendering = addRender(app, render);
  CLI::App* benching = addBench(app, bench);
  CLI::App* comparing = addCompare(app, compare);
  CLI::App* referencing = addReference(app, reference);
  CLI::App* exporter = addExport(app, exporting);
  CLI::App* merging = addMerge(app, merge);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help, --version
    std::cerr << "fredholm: error: " << explainParseError(app, e, argc, argv) << "\n";
    return 1;
  }
#ifdef FREDHOLM_HAVE_MPI
  // Under mpirun a render is shared by the job's ranks (host/distributed); an error on one
  // rank ends the job, as the others would wait for it.
  std::unique_ptr<MpiSession> mpi;
  if (*rendering && startedByMpirun()) {
    mpi = std::make_unique<MpiSession>(&argc, &argv);
    render.mpi = mpi.get();
  }
  const auto failed = [&](int code) {
    if (mpi && mpi->size() > 1) mpi->abort(code);
    return code;
  };
#else
  const auto failed = [](int code) { return code; };
#endif
  try {
    if (*devices) return runDevices(devicesSpec);
    if (*rendering) return runRender(render);
    if (*benching) return runBench(bench);
    if (*referencing) return runReference(reference);
    if (*comparing) return runCompare(compare);
    if (*exporter) return runExport(exporting);
    if (*merging) return runMerge(merge);
  } catch (const Interrupted& e) {
    // Every rank has stopped and handed its film over by now: the job ends as it is.
    std::cerr << "fredholm: interrupted: " << e.what() << "\n";
    return e.exitCode();
  } catch (const BuildError& e) {
    std::cerr << "fredholm: error: " << e.what() << "\n";
    return failed(1);
  } catch (const Error& e) {
    std::cerr << "fredholm: error: " << e.what() << "\n";
    return failed(1);
  } catch (const std::exception& e) {
    std::cerr << "fredholm: internal error: " << e.what() << "\n";
    return failed(3);
  }
  return 0;
}
