// The checkpoint file: one text line (format, fingerprint, size, passes, which optional
// sums follow, a checksum of each section after it and, last, of the line itself), then the
// film's sums as raw doubles, in the order Film declares them, and its pixel lists.
#include "render/checkpoint.h"

#include <algorithm>
#include <array>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <cstring>
#include <fstream>
#include <iomanip>
#include <sstream>

#include "base/atomic_file.h"
#include "base/error.h"
#include "base/input_file.h"
#include "scene/environment_map.h"

namespace fh {
namespace {

// Version 2: the header lists the passes the film holds (chunks, ranks' films), and samples
// are quantized (render/film.h). Version 3: the odd passes' sums carry their sample count
// (an adaptive render's pixels have counts of their own). Version 4: an adaptive render's
// film lists the pixels of the round after its current one too. Version 5: a checksum of
// every section (the header line, each sum array, each pixel list), so that a byte damaged
// on disk or in transit is refused rather than merged into an image.
constexpr const char* kMagic = "fredholm-film-5";
constexpr const char* kMagicStem = "fredholm-film-";
// The header line's length at most: 4096 pass ranges of two 10-digit numbers, with room.
constexpr size_t kMaxHeaderBytes = size_t(1) << 20;

// FNV-1a, 64 bits, over whatever bytes are fed to it: render fingerprints and the checksums
// of a film file's sections.
class Fingerprint {
 public:
  Fingerprint& bytes(const void* data, size_t n) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (size_t i = 0; i < n; ++i) hash_ = (hash_ ^ p[i]) * 0x100000001b3ull;
    return *this;
  }
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
  uint64_t hash_ = 0xcbf29ce484222325ull;
};

// The film's sums in file order.
std::vector<const std::vector<double>*> sums(const Film& f) { return {&f.sum, &f.sumSq, &f.aovSum, &f.oddSum}; }
std::vector<std::vector<double>*> sums(Film& f) { return {&f.sum, &f.sumSq, &f.aovSum, &f.oddSum}; }

// A film file's sections after its header, in file order, as its errors name them: the sum
// arrays, then the pixel lists.
constexpr size_t kSections = 6;
const char* const kSectionNames[kSections] = {"sums are",          "sums of squares are",  "surface layer sums are",
                                              "odd passes' sums are", "round pixel list is", "next round pixel list is"};

const char* const kDamaged = "; the file was damaged after fredholm wrote it: render its passes again";

std::string checksum(const void* data, size_t bytes) { return Fingerprint().bytes(data, bytes).hex(); }

// The header line's fields: all it says of the film but the sections themselves.
struct FilmHeader {
  std::string fingerprint;
  int width = 0, height = 0;
  Film::PassRanges ranges;
  size_t aovs = 0, odd = 0, round = 0, nextRound = 0;
  std::array<std::string, kSections> checksums;

  uint64_t pixels() const { return uint64_t(width) * uint64_t(height); }
  // Each section's length in bytes, in file order.
  std::array<uint64_t, kSections> sectionBytes() const {
    return {32 * pixels(), 32 * pixels(), 8 * aovs, 8 * odd, 4 * round, 4 * nextRound};
  }
};

// The header line, its own checksum last (over everything before it), and its newline.
std::string formatHeader(const FilmHeader& h) {
  std::ostringstream out;
  out << kMagic << ' ' << h.fingerprint << ' ' << h.width << ' ' << h.height << ' ' << h.ranges.size();
  for (const auto& [begin, end] : h.ranges) out << ' ' << begin << ' ' << end;
  out << ' ' << h.aovs << ' ' << h.odd << ' ' << h.round << ' ' << h.nextRound;
  for (const std::string& c : h.checksums) out << ' ' << c;
  const std::string line = out.str();
  return line + ' ' + checksum(line.data(), line.size()) + '\n';
}

// The header line (without its newline) read back: its format and checksum checked, then its
// fields, consistent with one another. Throws fh::Error naming `flag` and the file.
FilmHeader parseHeader(const std::string& line, const std::string& path, const std::string& flag) {
  const std::string named = flag + " '" + path + "': ", notAFilm = named + "not a fredholm film or checkpoint";
  const std::string magic = line.substr(0, line.find(' '));
  if (magic != kMagic) {
    const std::string version = magic.rfind(kMagicStem, 0) == 0 ? magic.substr(std::strlen(kMagicStem)) : "";
    if (version.size() == 1 && version[0] >= '1' && version[0] < kMagic[std::strlen(kMagicStem)])
      throw Error(named + "an older film format (" + magic + "); render it again");
    throw Error(notAFilm);
  }
  const size_t last = line.rfind(' ');
  if (last == std::string::npos) throw Error(notAFilm);
  if (line.compare(last + 1, std::string::npos, checksum(line.data(), last)) != 0)
    throw Error(named + "the film's header is corrupt (checksum mismatch)" + kDamaged);
  std::istringstream in(line.substr(0, last));
  FilmHeader h;
  std::string ignored;
  size_t rangeCount = 0;
  in >> ignored >> h.fingerprint >> h.width >> h.height >> rangeCount;
  if (!in || rangeCount > 4096) throw Error(notAFilm);
  // Passes are numbered in 32 bits; the ranges ascend without touching.
  h.ranges.resize(rangeCount);
  for (size_t i = 0; i < rangeCount; ++i) {
    in >> h.ranges[i].first >> h.ranges[i].second;
    if (!in || h.ranges[i].first >= h.ranges[i].second || h.ranges[i].second > (uint64_t(1) << 32) ||
        (i > 0 && h.ranges[i].first <= h.ranges[i - 1].second))
      throw Error(notAFilm);
  }
  in >> h.aovs >> h.odd >> h.round >> h.nextRound;
  for (std::string& c : h.checksums) in >> c;
  if (!in || !(in >> std::ws).eof() || h.width <= 0 || h.height <= 0 || h.pixels() > (uint64_t(1) << 28))
    throw Error(notAFilm);
  // The sections' sizes follow from the header: checked against the file before allocating.
  const uint64_t pixels = h.pixels();
  if ((h.aovs != 0 && h.aovs != pixels * kAovSumsPerPixel) || (h.odd != 0 && h.odd != pixels * kOddSumsPerPixel) ||
      h.round > pixels || h.nextRound > pixels || (h.nextRound && !h.round))
    throw Error(notAFilm);
  return h;
}

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
  // Added only where they apply, so that other renders keep their fingerprints.
  if (s.adaptive) f.add(s.adaptive);
  if (s.method == Method::VCM) f.add(s.mergeRadius);
  if (scene.worldScale != 1.f) f.add(scene.worldScale);  // the depth layer's units
  if (s.radianceUnit != 1.0) f.add(s.radianceUnit);     // the image's, its emission scaled to it
  if (s.envMap) f.add(s.envMap->width).add(s.envMap->height).add(s.envMap->uShift()).add(s.envMap->texels);
  return f.hex();
}

std::string saveFilm(const std::string& path, const Film& film, const std::string& fingerprint, const std::string& flag) {
  FilmHeader h;
  h.fingerprint = fingerprint;
  h.width = film.width;
  h.height = film.height;
  h.ranges = film.passRanges();
  const auto size = [](const auto& list) { return list ? list->size() : 0; };
  h.aovs = film.aovSum.size();
  h.odd = film.oddSum.size();
  h.round = size(film.roundPixels);
  h.nextRound = size(film.nextRoundPixels);
  std::string body;
  size_t section = 0;
  const auto add = [&](const void* data, size_t bytes) {
    body.append(static_cast<const char*>(data), bytes);
    h.checksums[section++] = checksum(data, bytes);
  };
  for (const std::vector<double>* v : sums(film)) add(v->data(), v->size() * 8);
  for (const auto& list : {film.roundPixels, film.nextRoundPixels})
    add(list ? list->data() : nullptr, list ? list->size() * 4 : 0);
  return writeTextAtomically(path, flag, formatHeader(h) + body);
}

void saveCheckpoint(const std::string& path, const Film& film, const std::string& fingerprint) {
  saveFilm(path, film, fingerprint, "--checkpoint");
}

SavedFilm readFilm(const std::string& path, const std::string& flag) {
  const std::string named = flag + " '" + path + "': ", notAFilm = named + "not a fredholm film or checkpoint";
  checkInputFile(path, flag);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(named + "cannot read the file");
  std::string line;
  for (char c; in.get(c) && c != '\n';) {
    if (line.size() == kMaxHeaderBytes) throw Error(notAFilm);
    line += c;
  }
  if (!in) throw Error(notAFilm);  // no line ends
  const FilmHeader h = parseHeader(line, path, flag);
  const uint64_t pixels = h.pixels();
  const auto body = in.tellg();
  in.seekg(0, std::ios::end);
  const uint64_t bytes = uint64_t(in.tellg() - body);
  in.seekg(body);
  const std::array<uint64_t, kSections> sectionBytes = h.sectionBytes();
  uint64_t expected = 0;
  for (uint64_t b : sectionBytes) expected += b;
  if (bytes < expected) throw Error(named + "the file is cut short");
  if (bytes > expected) throw Error(named + "the file is longer than its header says");
  SavedFilm f{Film(h.width, h.height, h.aovs > 0, h.odd > 0, h.ranges.empty() ? 0 : h.ranges.front().first),
              h.fingerprint};
  // Each section read whole, then checked against its checksum before anything looks at it.
  size_t section = 0;
  const auto read = [&](void* data) {
    const size_t n = size_t(sectionBytes[section]);
    if (!in.read(static_cast<char*>(data), std::streamsize(n))) throw Error(named + "the file is cut short");
    if (checksum(data, n) != h.checksums[section])
      throw Error(named + "the film's " + kSectionNames[section] + " corrupt (checksum mismatch)" + kDamaged);
    ++section;
  };
  for (std::vector<double>* v : sums(f.film)) read(v->data());
  // A pixel list: ascending pixel indices.
  const auto readList = [&](size_t length) -> std::shared_ptr<const std::vector<uint32_t>> {
    auto list = std::make_shared<std::vector<uint32_t>>(length);
    read(list->data());
    for (size_t i = 0; i < length; ++i)
      if ((*list)[i] >= pixels || (i > 0 && (*list)[i] <= (*list)[i - 1])) throw Error(notAFilm);
    return length ? list : nullptr;
  };
  f.film.roundPixels = readList(h.round);
  f.film.nextRoundPixels = readList(h.nextRound);
  // Sums of samples are finite, sums of squares are not negative, and a pixel's mean
  // radiance is a float, as its samples are.
  for (size_t s = 0; s < 4; ++s) {
    const std::vector<double>& v = *sums(f.film)[s];
    for (size_t i = 0; i < v.size(); ++i) {
      const size_t perPixel = v.size() / f.film.pixels(), p = i / perPixel;
      const bool fits = std::isfinite(v[i]) && (s != 1 || v[i] >= 0) &&
                        (s != 0 || i % 4 == 3 || std::fabs(v[i]) <= f.film.count(p) * double(FLT_MAX));
      if (!fits)
        throw Error(named + "the film's " + kSectionNames[s] + " out of range at pixel (" +
                    std::to_string(p % size_t(h.width)) + ", " + std::to_string(p / size_t(h.width)) +
                    "): " + std::to_string(v[i]) + (std::isfinite(v[i]) ? "" : " (not finite)"));
    }
  }
  // Every pass adds one sample to each pixel it covers: every pixel, but in an adaptive
  // render's film (one that lists its round's pixels), whose pixels have counts of their own.
  uint64_t passes = 0;
  for (const auto& [begin, end] : h.ranges) passes += end - begin;
  for (size_t p = 0; p < f.film.pixels(); ++p) {
    const double n = f.film.count(p);
    if (h.round ? !(n >= 0 && n <= double(passes) && n == std::floor(n)) : n != double(passes))
      throw Error(named + "the film's sample counts do not add up");
  }
  f.film.setPassRanges(h.ranges);
  return f;
}

std::string resealFilm(const std::string& bytes) {
  const size_t end = bytes.find('\n');
  if (end == std::string::npos || bytes.compare(0, std::strlen(kMagic) + 1, std::string(kMagic) + ' ') != 0)
    return bytes;
  std::string line = bytes.substr(0, end);
  FilmHeader h;
  try {
    // With the checksum the line has, to parse it: its own is made anew below.
    const size_t last = line.rfind(' ');
    h = parseHeader(line.substr(0, last) + ' ' + checksum(line.data(), last), "", "");
  } catch (const Error&) {
    return bytes;
  }
  uint64_t at = end + 1;
  const std::array<uint64_t, kSections> sectionBytes = h.sectionBytes();
  for (size_t s = 0; s < kSections; ++s) {
    const uint64_t begin = std::min<uint64_t>(at, bytes.size()), n = std::min<uint64_t>(sectionBytes[s], bytes.size() - begin);
    h.checksums[s] = checksum(bytes.data() + begin, size_t(n));
    at = begin + n;
  }
  return formatHeader(h) + bytes.substr(end + 1);
}

Film loadCheckpoint(const std::string& path, const std::string& fingerprint, const std::string& flag) {
  SavedFilm f = readFilm(path, flag);
  if (f.fingerprint != fingerprint)
    throw Error(flag + " '" + path + "': saved by a render of another scene, camera or settings (size, seed, "
                "method, depths, --merge-radius, environment, filter, --noise, --aovs); resume with the same ones");
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
                  " (another scene, camera or settings: size, seed, method, depths, --merge-radius, environment, "
                  "filter, --noise, --aovs)");
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
