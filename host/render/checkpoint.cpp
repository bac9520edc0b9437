// The checkpoint file: one text line (format, fingerprint, size, passes, which optional
// sums follow), then the film's sums as raw doubles, in the order Film declares them.
#include "render/checkpoint.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <cstring>
#include <fstream>
#include <iomanip>
#include <sstream>

#include "base/atomic_file.h"
#include "base/error.h"
#include "scene/environment_map.h"

namespace fh {
namespace {

// Version 2: the header lists the passes the film holds (chunks, ranks' films), and samples
// are quantized (render/film.h). Version 3: the odd passes' sums carry their sample count
// (an adaptive render's pixels have counts of their own). Version 4: an adaptive render's
// film lists the pixels of the round after its current one too.
constexpr const char* kMagic = "fredholm-film-4";

// FNV-1a, 64 bits, over whatever bytes are fed to it.
class Fingerprint {
 public:
  template <typename T>
  Fingerprint& add(const T& value) {
    static_assert(std::is_trivially_copyable<T>::value, "raw bytes");
    return bytes(&value, sizeof value);
  }
  template <typename T>
  Fingerprint& add(const std::vector<T>& values) {
    add(values.size());
    return bytes(values.data(), values.size() * sizeof(T));
  }
  Fingerprint& add(const std::string& s) {
    add(s.size());
    return bytes(s.data(), s.size());
  }
  std::string hex() const {
    std::ostringstream out;
    out << std::hex << std::setw(16) << std::setfill('0') << hash_;
    return out.str();
  }

 private:
  Fingerprint& bytes(const void* data, size_t n) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (size_t i = 0; i < n; ++i) hash_ = (hash_ ^ p[i]) * 0x100000001b3ull;
    return *this;
  }
  uint64_t hash_ = 0xcbf29ce484222325ull;
};

// The film's sums in file order.
std::vector<const std::vector<double>*> sums(const Film& f) { return {&f.sum, &f.sumSq, &f.aovSum, &f.oddSum}; }
std::vector<std::vector<double>*> sums(Film& f) { return {&f.sum, &f.sumSq, &f.aovSum, &f.oddSum}; }

}  // namespace

std::string renderFingerprint(const Scene& scene, const Camera& camera, const RenderSettings& s) {
  Fingerprint f;
  f.add(scene.positions).add(scene.indices).add(scene.triangleMaterial).add(scene.cornerNormals).add(scene.cornerUVs);
  for (const Material& m : scene.materials)
    f.add(m.kd).add(m.ks).add(m.ke).add(m.tf).add(m.ns).add(m.ni).add(m.d).add(m.illum).add(m.kdTexture);
  for (const Texture& t : scene.textures) f.add(t.path);
  f.add(camera.eye).add(camera.target).add(camera.up).add(camera.fovYDeg);
  f.add(s.width).add(s.height).add(s.seed).add(s.method).add(s.maxDepth).add(s.rrDepth).add(s.env).add(s.filter);
  f.add(s.replicates()).add(s.surfaceAovs);
  if (s.adaptive) f.add(s.adaptive);  // (renders that do not adapt keep their fingerprints)
  if (s.envMap) f.add(s.envMap->width).add(s.envMap->height).add(s.envMap->uShift()).add(s.envMap->texels);
  return f.hex();
}

std::string saveFilm(const std::string& path, const Film& film, const std::string& fingerprint, const std::string& flag) {
  std::ostringstream out;
  out << kMagic << ' ' << fingerprint << ' ' << film.width << ' ' << film.height << ' ' << film.passRanges().size();
  for (const auto& [begin, end] : film.passRanges()) out << ' ' << begin << ' ' << end;
  const auto size = [](const auto& list) { return list ? list->size() : 0; };
  out << ' ' << film.aovSum.size() << ' ' << film.oddSum.size() << ' ' << size(film.roundPixels) << ' '
      << size(film.nextRoundPixels) << '\n';
  for (const std::vector<double>* v : sums(film))
    out.write(reinterpret_cast<const char*>(v->data()), std::streamsize(v->size() * 8));
  for (const auto& list : {film.roundPixels, film.nextRoundPixels})
    if (list) out.write(reinterpret_cast<const char*>(list->data()), std::streamsize(list->size() * 4));
  return writeTextAtomically(path, flag, out.str());
}

void saveCheckpoint(const std::string& path, const Film& film, const std::string& fingerprint) {
  saveFilm(path, film, fingerprint, "--checkpoint");
}

SavedFilm readFilm(const std::string& path, const std::string& flag) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(flag + " '" + path + "': cannot read the file");
  std::string magic, saved;
  int width = 0, height = 0;
  size_t rangeCount = 0, aovs = 0, odd = 0, round = 0, nextRound = 0;
  const std::string notAFilm = flag + " '" + path + "': not a fredholm film or checkpoint";
  in >> magic >> saved >> width >> height >> rangeCount;
  if (!in || magic != kMagic || rangeCount > 4096) throw Error(notAFilm);
  // Passes are numbered in 32 bits; the ranges ascend without touching.
  Film::PassRanges ranges(rangeCount);
  uint64_t passes = 0;
  for (size_t i = 0; i < rangeCount; ++i) {
    in >> ranges[i].first >> ranges[i].second;
    if (!in || ranges[i].first >= ranges[i].second || ranges[i].second > (uint64_t(1) << 32) ||
        (i > 0 && ranges[i].first <= ranges[i - 1].second))
      throw Error(notAFilm);
    passes += ranges[i].second - ranges[i].first;
  }
  in >> aovs >> odd >> round >> nextRound;
  if (!in || in.get() != '\n' || width <= 0 || height <= 0 || uint64_t(width) * uint64_t(height) > (uint64_t(1) << 28))
    throw Error(notAFilm);
  // The sums' sizes follow from the header: checked against the file before allocating.
  const uint64_t pixels = uint64_t(width) * uint64_t(height);
  if ((aovs != 0 && aovs != pixels * kAovSumsPerPixel) || (odd != 0 && odd != pixels * kOddSumsPerPixel) ||
      round > pixels || nextRound > pixels || (nextRound && !round))
    throw Error(notAFilm);
  const auto body = in.tellg();
  in.seekg(0, std::ios::end);
  const uint64_t bytes = uint64_t(in.tellg() - body);
  in.seekg(body);
  if (bytes != (8 * pixels + aovs + odd) * 8 + (round + nextRound) * 4) throw Error(flag + " '" + path + "': the file is cut short");
  SavedFilm f{Film(width, height, aovs > 0, odd > 0, ranges.empty() ? 0 : ranges.front().first), saved};
  for (std::vector<double>* v : sums(f.film))
    if (!in.read(reinterpret_cast<char*>(v->data()), std::streamsize(v->size() * 8)))
      throw Error(flag + " '" + path + "': the file is cut short");
  // A pixel list: ascending pixel indices.
  const auto readList = [&](size_t length) -> std::shared_ptr<const std::vector<uint32_t>> {
    if (!length) return nullptr;
    auto list = std::make_shared<std::vector<uint32_t>>(length);
    if (!in.read(reinterpret_cast<char*>(list->data()), std::streamsize(length * 4)))
      throw Error(flag + " '" + path + "': the file is cut short");
    for (size_t i = 0; i < length; ++i)
      if ((*list)[i] >= pixels || (i > 0 && (*list)[i] <= (*list)[i - 1])) throw Error(notAFilm);
    return list;
  };
  f.film.roundPixels = readList(round);
  f.film.nextRoundPixels = readList(nextRound);
  if (in.peek() != std::char_traits<char>::eof()) throw Error(notAFilm);
  // Every pass adds one sample to each pixel it covers: every pixel, but in an adaptive
  // render's film (one that lists its round's pixels), whose pixels have counts of their own.
  for (size_t p = 0; p < f.film.pixels(); ++p) {
    const double n = f.film.count(p);
    if (round ? !(n >= 0 && n <= double(passes) && n == std::floor(n)) : n != double(passes))
      throw Error(flag + " '" + path + "': the film's sample counts do not add up");
  }
  f.film.setPassRanges(ranges);
  return f;
}

Film loadCheckpoint(const std::string& path, const std::string& fingerprint, const std::string& flag) {
  SavedFilm f = readFilm(path, flag);
  if (f.fingerprint != fingerprint)
    throw Error(flag + " '" + path + "': saved by a render of another scene, camera or settings (size, seed, "
                "method, depths, environment, filter, --noise, --aovs); resume with the same ones");
  if (f.film.firstPass() != 0 || !f.film.consecutive())
    throw Error(flag + " '" + path + "': holds passes " + f.film.describePasses() +
                ", not a checkpoint of passes from 0 on; merge chunks with fredholm merge");
  return std::move(f.film);
}

std::string rankCheckpointPath(const std::string& base, int rank) { return base + ".rank" + std::to_string(rank); }

std::vector<std::string> rankCheckpointFiles(const std::string& base) {
  namespace fs = std::filesystem;
  const fs::path path(base);
  const fs::path dir = path.has_parent_path() ? path.parent_path() : fs::path(".");
  const std::string prefix = path.filename().string() + ".rank";
  std::vector<std::string> files;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    const std::string name = entry.path().filename().string();
    // Named as rankCheckpointPath names them (base + suffix), so the two compare equal.
    if (name.size() > prefix.size() && name.compare(0, prefix.size(), prefix) == 0 &&
        name.find_first_not_of("0123456789", prefix.size()) == std::string::npos)
      files.push_back(base + name.substr(path.filename().string().size()));
  }
  std::sort(files.begin(), files.end());
  return files;
}

SavedFilm mergeFilms(const std::vector<std::string>& paths, const std::string& fingerprint, const std::string& flag) {
  std::vector<std::pair<std::string, SavedFilm>> films;
  for (const std::string& path : paths) films.emplace_back(path, readFilm(path, flag));
  const std::string expected = fingerprint.empty() ? films.front().second.fingerprint : fingerprint;
  for (const auto& [path, saved] : films)
    if (saved.fingerprint != expected)
      throw Error(flag + " '" + path + "': is a chunk of another render than " +
                  (fingerprint.empty() ? "'" + films.front().first + "'" : std::string("this one")) +
                  " (another scene, camera or settings: size, seed, method, depths, environment, filter, --noise, "
                  "--aovs)");
  // In the order of their first passes: the sums of squares, not exact, then add up alike.
  std::stable_sort(films.begin(), films.end(), [](const auto& a, const auto& b) {
    return a.second.film.firstPass() < b.second.film.firstPass();
  });
  SavedFilm merged{films.front().second.film, expected};
  for (size_t i = 1; i < films.size(); ++i) {
    try {
      merged.film.merge(films[i].second.film);
    } catch (const Error& e) {
      throw Error(flag + " '" + films[i].first + "' (passes " + films[i].second.film.describePasses() +
                  ", joining " + merged.film.describePasses() + "): " + e.what());
    }
  }
  return merged;
}

Film loadRankCheckpoints(const std::string& base, const std::string& fingerprint, const std::string& flag) {
  std::vector<std::string> files = rankCheckpointFiles(base);
  // A render of one process goes on under mpirun from its own checkpoint.
  if (files.empty() && std::filesystem::exists(base)) files.push_back(base);
  if (files.empty())
    throw Error(flag + " '" + base + "': no checkpoint there, of ranks (" + base + ".rank0, ...) or of one process");
  return mergeFilms(files, fingerprint, flag).film;
}

}  // namespace fh
