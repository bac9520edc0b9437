// `fredholm merge`: the films of chunks of one render (render --passes A:B --film FILE),
// checked to come from the same render and not to overlap, added into one film and
// written as its image. The film's sums are exact (render/film.h), so the image is the
// same bits as one render of all the chunks' passes, however they were split.
#include <algorithm>
#include <iostream>

#include "base/error.h"
#include "cli/commands.h"
#include "cli/flags.h"
#include "image/image_io.h"
#include "render/checkpoint.h"

namespace fh {
namespace {

struct Part {
  std::string path;
  SavedFilm saved;
};

// The parts, read; throws fh::Error for a part of another render (or size, or layers) than
// the first.
std::vector<Part> readParts(const std::vector<std::string>& paths) {
  std::vector<Part> parts;
  for (const std::string& path : paths) parts.push_back({path, readFilm(path, "merge")});
  const Part& reference = parts.front();
  for (const Part& p : parts) {
    const Film &a = reference.saved.film, &b = p.saved.film;
    if (p.saved.fingerprint != reference.saved.fingerprint || a.width != b.width || a.height != b.height ||
        a.hasSurfaceAovs() != b.hasSurfaceAovs() || a.oddSum.size() != b.oddSum.size())
      throw Error("merge: '" + p.path + "' is a chunk of another render than '" + reference.path +
                  "' (another scene, camera or settings: size, seed, method, depths, environment, filter, --aovs)");
  }
  std::sort(parts.begin(), parts.end(),
            [](const Part& a, const Part& b) { return a.saved.film.firstPass() < b.saved.film.firstPass(); });
  return parts;
}

// The parts added into one film; throws fh::Error naming a part that shares passes with
// those before it.
Film mergeParts(const std::vector<Part>& parts) {
  Film film = parts.front().saved.film;
  for (size_t i = 1; i < parts.size(); ++i) {
    try {
      film.merge(parts[i].saved.film);
    } catch (const Error&) {
      throw Error("merge: '" + parts[i].path + "' (passes " + parts[i].saved.film.describePasses() +
                  ") shares passes with the parts before it (" + film.describePasses() +
                  "); each pass may be merged once");
    }
  }
  return film;
}

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
  checkOutputPath(o.output, o.force);
  if (!layers.empty() && extensionOf(o.output) != ".exr")
    throw Error("--aovs: layers are written into one EXR; -o '" + o.output + "' is not an .exr file");
  const std::vector<Part> parts = readParts(o.parts);
  const Film film = mergeParts(parts);
  for (const std::string& layer : layers)
    if (isSurfaceAov(layer) && !film.hasSurfaceAovs())
      throw Error("--aovs " + layer + ": the chunks were rendered without it (render them with --aovs " + layer + ")");
  const std::string missing = missingPasses(film);
  if (!missing.empty())
    std::cerr << "fredholm: warning: no part holds passes " << missing << ": the image has " << film.passes()
              << " samples per pixel, not the " << film.nextPass() << " of one render of passes 0:"
              << film.nextPass() << "\n";
  std::map<std::string, std::string> metadata = {{"spp", std::to_string(film.passes())},
                                                 {"merged_parts", std::to_string(parts.size())},
                                                 {"fingerprint", parts.front().saved.fingerprint}};
  if (!missing.empty()) metadata["missing_passes"] = missing;
  writeImage(o.output, film.imageWithLayers(layers), metadata);
  std::cout << "wrote " << o.output << " (" << film.passes() << " passes from " << parts.size() << " parts)\n";
  return 0;
}

}  // namespace fh
