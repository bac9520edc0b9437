// `fredholm merge`: the films of chunks of one render (render --passes A:B --film FILE),
// checked to come from the same render and not to overlap, added into one film and
// written as its image. The film's sums are exact (render/film.h), so the image is the
// same bits as one render of all the chunks' passes, however they were split.
#include <iostream>

#include "base/error.h"
#include "base/output_plan.h"
#include "cli/commands.h"
#include "cli/flags.h"
#include "image/image_io.h"
#include "render/checkpoint.h"

namespace fh {
namespace {

// The passes no part holds, from 0 to the last one held ("" if none).
std::string missingPasses(const Film& film) {
  std::string missing;
  uint64_t next = 0;
  for (const auto& [begin, end] : film.passRanges()) {
    if (begin > next) missing += (missing.empty() ? "" : ", ") + std::to_string(next) + ":" + std::to_string(begin);
    next = end;
  }
  return missing;
}

}  // namespace

int runMerge(const MergeOptions& o) {
  const std::vector<std::string> layers = o.aovs.empty() ? std::vector<std::string>{} : parseAovLayers(o.aovs);
  checkImageExtension(o.output, "-o");
  OutputPlan plan(o.force);
  plan.add(o.output, "-o");
  plan.reserve();
  if (!layers.empty() && extensionOf(o.output) != ".exr")
    throw Error("--aovs: layers are written into one EXR; -o '" + o.output + "' is not an .exr file");
  const SavedFilm merged = mergeFilms(o.parts, "", "merge");
  const Film& film = merged.film;
  plan.checkAgainstInputs();
  for (const std::string& layer : layers)
    if (isSurfaceAov(layer) && !film.hasSurfaceAovs())
      throw Error("--aovs " + layer + ": the chunks were rendered without it (render them with --aovs " + layer + ")");
  const std::string missing = missingPasses(film);
  if (!missing.empty())
    std::cerr << "fredholm: warning: no part holds passes " << missing << ": the image has " << film.passes()
              << " samples per pixel, not the " << film.nextPass() << " of one render of passes 0:"
              << film.nextPass() << "\n";
  std::map<std::string, std::string> metadata = {{"spp", std::to_string(film.passes())},
                                                 {"merged_parts", std::to_string(o.parts.size())},
                                                 {"fingerprint", merged.fingerprint}};
  if (!missing.empty()) metadata["missing_passes"] = missing;
  const std::string written = writeImage(o.output, film.imageWithLayers(layers), metadata);
  plan.finish();
  std::cout << "wrote " << written << " (" << film.passes() << " passes from " << o.parts.size() << " parts)\n";
  return 0;
}

}  // namespace fh
