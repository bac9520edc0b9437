// The subcommands behind `fredholm`: each takes its parsed options and returns the exit
// status, throwing fh::Error for anything the user should fix (main prints it as one
// `fredholm: error:` line).
#pragma once
#include <optional>
#include <string>

#include "render/settings.h"
#include "scene/scene.h"

namespace fh {

class MpiSession;

struct RenderOptions {
  std::string scene;
  std::string output;
  bool force = false;
  int width = 512, height = 512;
  std::optional<int> spp;  // unset: 64 (4 for --aov), or as many as --time allows
  double seconds = 0.0;
  double noise = 0.0;  // --noise: the estimated relMSE to stop at; 0: none
  bool adaptive = false;  // --adaptive: later passes cover the noisy pixels
  std::string method = "mis", filter = "box", env, statsFile, strategy = "auto";
  std::string envMap;  // --env-map FILE (.exr, .hdr)
  std::optional<float> envRotate, envScale;
  int maxDepth = RenderSettings{}.maxDepth;
  int rrDepth = RenderSettings{}.rrDepth;
  std::optional<float> mergeRadius;
  std::optional<size_t> wavefront;  // unset: chosen for each device
  bool allFeatures = false;
  std::string seed = "1";  // the sampler's 32-bit seed, checked by settingsFrom
  std::string cameraFile, eye, target, up;
  std::optional<float> fov;
  std::string aov;
  std::string aovs;  // --aovs: layers written beside the image in one EXR
  bool denoise = false;       // --denoise: NAME.denoised.EXT beside the image
  std::string displayServer;  // --display-server HOST:PORT: tev's live view
  std::string checkpoint, resume;  // --checkpoint FILE, --resume FILE
  std::string passes, film;        // --passes A:B (a chunk), --film FILE (the film, for fredholm merge)
  // Under mpirun (host/distributed): the job this process is a rank of; null otherwise.
  const MpiSession* mpi = nullptr;
  std::optional<double> checkpointEvery;  // unset: RenderSettings' default
  std::string device;
};
int runRender(RenderOptions o);

int runDevices(const std::string& spec);

// `fredholm merge`: films of chunks of one render (--passes, --film) into its image.
struct MergeOptions {
  std::vector<std::string> parts;
  std::string output, aovs;
  bool force = false;
};
int runMerge(const MergeOptions& o);

struct CompareOptions {
  std::string image, reference;
  int block = 1;
};
int runCompare(const CompareOptions& o);

struct ReferenceOptions {
  std::string scene, output;
  int width = 128, height = 128;
  bool force = false;
};
int runReference(const ReferenceOptions& o);

struct ExportOptions {
  std::string scene, output;
  bool force = false;
};
int runExport(const ExportOptions& o);

// An OBJ path, builtin:NAME, bench:NAME (a bench scene), or "" for the Cornell box.
Scene loadSceneSpec(const std::string& spec);
void printWarnings(const Scene& scene);

}  // namespace fh
