// Checkpoints (--checkpoint, --resume): a render killed with SIGKILL after any number of
// passes and resumed gives the image an uninterrupted render gives, to the bit; Ctrl-C
// leaves a checkpoint too; a checkpoint is refused by a render of other settings and when
// it is damaged, with a one-line error. Chunks (--passes A:B --film FILE, fredholm merge):
// merged, they are the bits of one render however the passes were split and rendered.
#include <gtest/gtest.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "image/image_io.h"
#include "render/checkpoint.h"
#include "render/film.h"
#include "scene/scene_loader.h"
#include "test_support.h"

namespace fh {
namespace {

const std::string kBase = "render --height 24 --spp 24";
const std::string kRender = kBase + " --width 24 --seed 3";

TEST(Checkpoint, KilledAndResumedIsTheUninterruptedImage) {
  const std::string dir = test::tempDir("checkpoint");
  ASSERT_EQ(test::runFredholm(kRender + " -o " + dir + "/straight.exr").exitCode, 0);
  const Image straight = readImage(dir + "/straight.exr");
  for (const char* passes : {"1", "7", "23"}) {
    const std::string ckpt = dir + "/c" + passes + ".fhc", out = dir + "/r" + passes + ".exr";
    // SIGKILL itself once `passes` are in a checkpoint: no image, no clean-up, as a crash.
    const auto killed = test::runFredholm(kRender + " --checkpoint " + ckpt + " --checkpoint-every 0 -o " + out,
                                          std::string("FREDHOLM_KILL_AFTER_PASSES=") + passes);
    EXPECT_NE(killed.exitCode, 0) << passes;
    EXPECT_FALSE(std::filesystem::exists(out)) << passes;
    ASSERT_TRUE(std::filesystem::exists(ckpt)) << passes << ": " << killed.output;
    const auto resumed = test::runFredholm(kRender + " --resume " + ckpt + " --checkpoint " + ckpt + " -o " + out);
    ASSERT_EQ(resumed.exitCode, 0) << resumed.output;
    EXPECT_TRUE(readImage(out).rgb == straight.rgb) << "resumed after " << passes << " passes";
  }
}

// A resumed render may go further than the first one meant to: 12 spp, then resumed to 24.
TEST(Checkpoint, ARenderCanBeExtended) {
  const std::string dir = test::tempDir("extend");
  ASSERT_EQ(test::runFredholm(kRender + " -o " + dir + "/straight.exr").exitCode, 0);
  const std::string short12 = "render --width 24 --height 24 --spp 12 --seed 3";
  ASSERT_EQ(test::runFredholm(short12 + " --checkpoint " + dir + "/c.fhc -o " + dir + "/12.exr").exitCode, 0);
  const auto r = test::runFredholm(kRender + " --resume " + dir + "/c.fhc -o " + dir + "/24.exr");
  ASSERT_EQ(r.exitCode, 0) << r.output;
  EXPECT_TRUE(readImage(dir + "/24.exr").rgb == readImage(dir + "/straight.exr").rgb);
}

// A render stopped by its noise target, resumed: nothing more to do, the same image.
TEST(Checkpoint, ARenderThatMetItsNoiseTargetStaysAsItWas) {
  const std::string dir = test::tempDir("noise-resume");
  const std::string render = "render --width 24 --height 24 --noise 3e-3 --seed 3";
  ASSERT_EQ(test::runFredholm(render + " --checkpoint " + dir + "/c.fhc -o " + dir + "/a.exr").exitCode, 0);
  const auto r = test::runFredholm(render + " --resume " + dir + "/c.fhc -o " + dir + "/b.exr");
  ASSERT_EQ(r.exitCode, 0) << r.output;
  EXPECT_TRUE(readImage(dir + "/a.exr").rgb == readImage(dir + "/b.exr").rgb);
}

TEST(Checkpoint, OtherSettingsOrADamagedFileAreRefused) {
  const std::string dir = test::tempDir("refuse");
  const std::string ckpt = dir + "/c.fhc";
  ASSERT_EQ(test::runFredholm(kRender + " --checkpoint " + ckpt + " -o " + dir + "/a.exr").exitCode, 0);
  for (const std::string& other : {kBase + " --width 24 --seed 4", kBase + " --width 32 --seed 3",
                                   kRender + " --method pt", kRender + " --max-depth 5", kRender + " --fov 20"}) {
    const auto r = test::runFredholm(other + " --resume " + ckpt + " -o " + dir + "/b.exr");
    EXPECT_EQ(r.exitCode, 1) << other;
    EXPECT_NE(r.output.find("fredholm: error: --resume '" + ckpt + "': saved by a render of another"),
              std::string::npos) << other << ": " << r.output;
  }
  // Cut short.
  const auto size = std::filesystem::file_size(ckpt);
  std::filesystem::resize_file(ckpt, size - 100);
  const auto cut = test::runFredholm(kRender + " --resume " + ckpt + " -o " + dir + "/c.exr");
  EXPECT_EQ(cut.exitCode, 1);
  EXPECT_NE(cut.output.find("cut short"), std::string::npos) << cut.output;
  // A header claiming a huge film over a small file: refused before allocating it.
  std::string header;
  std::getline(std::ifstream(ckpt), header);
  const std::string fingerprint = header.substr(header.find(' ') + 1, 16);
  test::writeFile(dir + "/huge.fhc",
                  resealFilm("fredholm-film-5 " + fingerprint + " 16384 16384 1 0 3 0 0 0 0 - - - - - - -\n0123"));
  const auto huge = test::runFredholm(kRender + " --resume " + dir + "/huge.fhc -o " + dir + "/e.exr");
  EXPECT_EQ(huge.exitCode, 1);
  EXPECT_NE(huge.output.find("cut short"), std::string::npos) << huge.output;
  test::writeFile(dir + "/junk.fhc", "not a checkpoint\n");
  const auto junk = test::runFredholm(kRender + " --resume " + dir + "/junk.fhc -o " + dir + "/d.exr");
  EXPECT_EQ(junk.exitCode, 1);
  EXPECT_NE(junk.output.find("not a fredholm film or checkpoint"), std::string::npos) << junk.output;
  for (const char* f : {"/b.exr", "/c.exr", "/d.exr"}) EXPECT_FALSE(std::filesystem::exists(dir + f)) << f;
}

// A checkpoint or chunk is refused by a render whose image would differ: every setting
// that changes the image changes the fingerprint, and none that leaves it alone does.
TEST(Checkpoint, EverySettingThatChangesTheImageChangesTheFingerprint) {
  const std::string dir = test::tempDir("fingerprint");
  const Scene scene = loadScene(test::writeFeatureScene(dir));
  const Camera camera = scene.camera;
  RenderSettings base;
  base.method = Method::VCM;
  const std::string reference = renderFingerprint(scene, camera, base);
  const std::vector<std::pair<const char*, void (*)(RenderSettings&)>> changing = {
      {"width", [](RenderSettings& s) { s.width += 1; }},
      {"height", [](RenderSettings& s) { s.height += 1; }},
      {"seed", [](RenderSettings& s) { s.seed += 1; }},
      {"method", [](RenderSettings& s) { s.method = Method::BDPT; }},
      {"max depth", [](RenderSettings& s) { s.maxDepth += 1; }},
      {"roulette depth", [](RenderSettings& s) { s.rrDepth += 1; }},
      {"merge radius", [](RenderSettings& s) { s.mergeRadius *= 2.f; }},
      {"env", [](RenderSettings& s) { s.env[1] = 0.5f; }},
      {"filter", [](RenderSettings& s) { s.filter = PixelFilter::Gaussian; }},
      {"noise target", [](RenderSettings& s) { s.noise = 1e-3; }},
      {"adaptive", [](RenderSettings& s) { s.adaptive = true; }},
      {"surface layers", [](RenderSettings& s) { s.surfaceAovs = true; }},
      {"radiance unit", [](RenderSettings& s) { s.radianceUnit = 0x1p20; }}};
  for (const auto& [what, change] : changing) {
    RenderSettings s = base;
    change(s);
    EXPECT_NE(renderFingerprint(scene, camera, s), reference) << what;
  }
  const std::vector<std::pair<const char*, void (*)(RenderSettings&)>> neutral = {
      {"spp", [](RenderSettings& s) { s.spp *= 2; }},
      {"time", [](RenderSettings& s) { s.seconds = 5; }},
      {"wavefront", [](RenderSettings& s) { s.wavefront = 4096; }},
      {"strategy", [](RenderSettings& s) { s.strategy = Strategy::Megakernel; }},
      {"all features", [](RenderSettings& s) { s.allFeatures = true; }},
      {"progress", [](RenderSettings& s) { s.progress = !s.progress; }}};
  for (const auto& [what, change] : neutral) {
    RenderSettings s = base;
    change(s);
    EXPECT_EQ(renderFingerprint(scene, camera, s), reference) << what;
  }
  Camera moved = camera;
  moved.fovYDeg += 1.f;
  EXPECT_NE(renderFingerprint(scene, moved, base), reference) << "camera";
  // The same scene in other units, both brought to the same size: the same image, but a
  // depth layer in other units.
  const std::string obj = test::writeFeatureScene(dir);
  const Scene big = loadScene(test::writeScaledCopy(obj, 40)), bigger = loadScene(test::writeScaledCopy(obj, 50));
  ASSERT_EQ(big.positions, bigger.positions);
  EXPECT_NE(renderFingerprint(big, scaledCamera(big.camera, big.worldScale), base),
            renderFingerprint(bigger, scaledCamera(bigger.camera, bigger.worldScale), base))
      << "units";
}

// A film with every section a film file has: sums, sums of squares, surface layers, the odd
// passes' sums and both adaptive pixel lists.
Film everySectionFilm() {
  constexpr int kW = 5, kH = 3, kPixels = kW * kH;
  Film film(kW, kH, true, true);
  for (int pass = 0; pass < 4; ++pass) {
    std::vector<float> samples;
    for (int p = 0; p < kPixels; ++p) samples.insert(samples.end(), {0.1f * float(p), 0.5f, 1.f + float(pass), 1.f});
    for (int p = 0; p < kPixels; ++p)
      samples.insert(samples.end(), {0.5f, 0.25f, 0.125f, 1.f, 0.f, 1.f, 0.f, 2.f + float(p)});
    film.addPass(samples);
  }
  film.roundPixels = std::make_shared<const std::vector<uint32_t>>(std::vector<uint32_t>{0, 3, 7, 14});
  film.nextRoundPixels = std::make_shared<const std::vector<uint32_t>>(std::vector<uint32_t>{1, 2, 3});
  return film;
}

std::string fileBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// A flipped byte anywhere in a film file (its header, each sum array, each pixel list), by
// one bit, the top bit or all eight: the file is refused, naming it and, past the header, the
// section that does not match its checksum.
TEST(Checkpoint, AFlippedByteInAnySectionIsRefused) {
  const std::string dir = test::tempDir("flip");
  const std::string saved = dir + "/every.film", flipped = dir + "/flipped.film";
  const Film film = everySectionFilm();
  saveFilm(saved, film, "0123456789abcdef", "--film");
  ASSERT_EQ(readFilm(saved, "merge").film.sum, film.sum);
  const std::string bytes = fileBytes(saved);
  const size_t pixels = film.pixels();
  struct Section {
    std::string message;  // what the refusal says, past the header
    size_t size;
  };
  const std::vector<Section> sections = {{"", bytes.find('\n') + 1},
                                         {"the film's sums are corrupt", 4 * pixels * 8},
                                         {"the film's sums of squares are corrupt", 4 * pixels * 8},
                                         {"the film's surface layer sums are corrupt", kAovSumsPerPixel * pixels * 8},
                                         {"the film's odd passes' sums are corrupt", kOddSumsPerPixel * pixels * 8},
                                         {"the film's round pixel list is corrupt", 4 * 4},
                                         {"the film's next round pixel list is corrupt", 3 * 4}};
  size_t begin = 0;
  for (const Section& section : sections) {
    for (const size_t at : {begin, begin + 1, begin + section.size / 3, begin + section.size / 2,
                            begin + section.size - 2, begin + section.size - 1})
      for (const unsigned char mask : {0x01, 0x80, 0xff}) {
        std::string damaged = bytes;
        damaged[at] = char(damaged[at] ^ mask);
        test::writeFile(flipped, damaged);
        const std::string where = "byte " + std::to_string(at) + " ^ " + std::to_string(mask);
        try {
          readFilm(flipped, "merge");
          ADD_FAILURE() << where << " (" << (section.message.empty() ? "header" : section.message) << "): accepted";
        } catch (const Error& e) {
          const std::string message = e.what();
          EXPECT_EQ(message.rfind("merge '" + flipped + "': ", 0), 0u) << where << ": " << message;
          EXPECT_EQ(message.find('\n'), std::string::npos) << where << ": " << message;
          if (!section.message.empty()) {
            EXPECT_NE(message.find(section.message + " (checksum mismatch)"), std::string::npos)
                << where << ": " << message;
          }
        }
      }
    begin += section.size;
  }
  EXPECT_EQ(begin, bytes.size());
}

// A value that must be finite and is not, in a film whose checksums hold (saved so): refused.
TEST(Checkpoint, ANonFiniteSumIsRefusedThoughItsChecksumHolds) {
  const std::string dir = test::tempDir("non-finite");
  for (const double bad : {-double(INFINITY), double(NAN)}) {
    for (int array = 0; array < 4; ++array) {
      Film film = everySectionFilm();
      std::vector<double>& sums = array == 0 ? film.sum : array == 1 ? film.sumSq : array == 2 ? film.aovSum : film.oddSum;
      sums[5] = bad;
      saveFilm(dir + "/bad.film", film, "0123456789abcdef", "--film");
      try {
        readFilm(dir + "/bad.film", "--resume");
        ADD_FAILURE() << "array " << array << " holding " << bad << ": accepted";
      } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("--resume '" + dir + "/bad.film': the film's "), std::string::npos)
            << e.what();
        EXPECT_NE(std::string(e.what()).find("not finite"), std::string::npos) << e.what();
      }
    }
  }
}

// Through the command line: merge and --resume refuse a film with a flipped byte, in one
// line naming the file and what is corrupt, and write nothing.
TEST(Checkpoint, MergeAndResumeRefuseAFlippedByte) {
  const std::string dir = test::tempDir("flip-cli");
  ASSERT_EQ(test::runFredholm(kRender + " --checkpoint " + dir + "/c.fhc -o " + dir + "/a.exr").exitCode, 0);
  ASSERT_EQ(test::runFredholm("render --width 24 --height 24 --seed 3 --passes 0:4 --film " + dir + "/p.film").exitCode, 0);
  for (const char* name : {"/c.fhc", "/p.film"}) {
    std::string bytes = fileBytes(dir + name);
    const size_t at = bytes.find('\n') + 1 + 8 * 13 + 7;  // the top byte of a sum
    bytes[at] = char(bytes[at] ^ 0x80);
    test::writeFile(dir + name + ".bad", bytes);
  }
  const std::string damaged = "the film's sums are corrupt (checksum mismatch)";
  const auto resumed = test::runFredholm(kRender + " --resume " + dir + "/c.fhc.bad -o " + dir + "/r.exr");
  EXPECT_EQ(resumed.exitCode, 1) << resumed.output;
  EXPECT_NE(resumed.output.find("fredholm: error: --resume '" + dir + "/c.fhc.bad': " + damaged), std::string::npos)
      << resumed.output;
  const auto merged = test::runFredholm("merge " + dir + "/p.film.bad -o " + dir + "/m.exr");
  EXPECT_EQ(merged.exitCode, 1) << merged.output;
  EXPECT_NE(merged.output.find("fredholm: error: merge '" + dir + "/p.film.bad': " + damaged), std::string::npos)
      << merged.output;
  for (const auto* r : {&resumed, &merged}) {
    const size_t line = r->output.find("fredholm: error: ");
    EXPECT_TRUE(line != std::string::npos && r->output.find('\n', line) + 1 == r->output.size()) << r->output;
  }
  EXPECT_FALSE(std::filesystem::exists(dir + "/r.exr"));
  EXPECT_FALSE(std::filesystem::exists(dir + "/m.exr"));
}

// Ctrl-C: the image so far and the checkpoint are written, and resuming finishes the image
// an uninterrupted render gives.
TEST(Checkpoint, CtrlCLeavesACheckpointToResumeFrom) {
  const std::string dir = test::tempDir("ctrl-c");
  const std::string size = "render --width 32 --height 32 --seed 5", render = size + " --spp 8192";
  ASSERT_EQ(test::runFredholm(size + " --spp 1 -o " + dir + "/warm.exr").exitCode, 0);  // builds the kernels
  const auto stopped = test::runCommand(std::string("timeout --foreground --preserve-status -s INT 1 ") +
                                        FREDHOLM_BINARY + " " + render + " --checkpoint " + dir +
                                        "/c.fhc -o " + dir + "/part.exr");
  ASSERT_EQ(stopped.exitCode, 130) << stopped.output;
  EXPECT_NE(stopped.output.find("and a checkpoint to " + dir + "/c.fhc"), std::string::npos) << stopped.output;
  const auto resumed = test::runFredholm(render + " --resume " + dir + "/c.fhc -o " + dir + "/resumed.exr");
  ASSERT_EQ(resumed.exitCode, 0) << resumed.output;
  ASSERT_EQ(test::runFredholm(render + " -o " + dir + "/straight.exr").exitCode, 0);
  EXPECT_TRUE(readImage(dir + "/resumed.exr").rgb == readImage(dir + "/straight.exr").rgb);
}

// The ranks' checkpoint files of a base, relative or absolute, named as each rank names its
// own (so that the one rank 0 keeps on resuming is told from those it removes).
TEST(Checkpoint, RankFilesAreFoundUnderTheNamesRanksGiveThem) {
  const std::string dir = test::tempDir("rank-files");
  for (const char* name : {"ck.rank0", "ck.rank12", "ck.rankA", "ck.rank", "ck", "other.rank1"})
    test::writeFile(dir + "/" + name, "x");
  EXPECT_EQ(rankCheckpointFiles(dir + "/ck"),
            (std::vector<std::string>{rankCheckpointPath(dir + "/ck", 0), rankCheckpointPath(dir + "/ck", 12)}));
  const auto cwd = std::filesystem::current_path();
  std::filesystem::current_path(dir);
  const std::vector<std::string> relative = rankCheckpointFiles("ck");
  std::filesystem::current_path(cwd);
  EXPECT_EQ(relative, (std::vector<std::string>{rankCheckpointPath("ck", 0), rankCheckpointPath("ck", 12)}));
}

// Passes of samples over eleven decades (more than double precision adds exactly from
// float samples), added one by one and as chunks merged in another
// order: the film's sums (and so its image) are the same bits.
TEST(Chunks, FilmSumsDoNotDependOnHowPassesAreSplit) {
  constexpr int kW = 8, kH = 4, kPasses = 40;
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> exponent(-6.f, 5.f);
  std::vector<std::vector<float>> passes(kPasses);
  for (auto& pass : passes)
    for (int p = 0; p < kW * kH; ++p)
      pass.insert(pass.end(), {std::pow(10.f, exponent(rng)), std::pow(10.f, exponent(rng)), 1e-7f * float(p), 1.f});
  Film whole(kW, kH);
  for (const auto& pass : passes) whole.addPass(pass);
  for (const std::vector<int>& cuts : std::vector<std::vector<int>>{{0, 13, 40}, {0, 1, 2, 39, 40}, {0, 20, 27, 40}}) {
    std::vector<Film> chunks;
    for (size_t c = 0; c + 1 < cuts.size(); ++c) {
      chunks.emplace_back(kW, kH, false, false, uint64_t(cuts[c]));
      for (int p = cuts[c]; p < cuts[c + 1]; ++p) chunks.back().addPass(passes[size_t(p)]);
    }
    Film merged = chunks.back();  // the last first: any order
    for (size_t c = 0; c + 1 < chunks.size(); ++c) merged.merge(chunks[c]);
    EXPECT_EQ(merged.passes(), uint64_t(kPasses));
    EXPECT_EQ(merged.firstPass(), 0u);
    EXPECT_TRUE(merged.sum == whole.sum) << "split at " << cuts[1];
    EXPECT_TRUE(merged.image().rgb == whole.image().rgb) << "split at " << cuts[1];
  }
}

// Chunks of passes rendered apart, on one device or two, by other strategies, merged in any
// order with their layers: the same EXR channels, to the bit, as one render.
TEST(Chunks, MergedChunksAreTheBitsOfOneRender) {
  const std::string dir = test::tempDir("chunks");
  const std::string render = "render --width 24 --height 16 --seed 9 --method mis --aovs albedo,depth,spp ";
  const auto one = test::runFredholm(render + "--spp 12 -o " + dir + "/one.exr");
  ASSERT_EQ(one.exitCode, 0) << one.output;
  struct Chunk {
    std::string passes, flags, env;
  };
  const std::vector<Chunk> chunks = {{"0:3", "", ""},
                                     {"3:7", "--device all", "POCL_DEVICES='pthread basic'"},
                                     {"7:12", "--strategy scalar --wavefront 256", ""}};
  std::string films;
  for (const Chunk& c : chunks) {
    const std::string film = dir + "/part-" + c.passes.substr(0, c.passes.find(':')) + ".film";
    const auto r = test::runFredholm(render + "--passes " + c.passes + " --film " + film + " " + c.flags, c.env);
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_NE(r.output.find("passes " + c.passes), std::string::npos) << r.output;
    films = film + " " + films;  // merged in reverse
  }
  const auto merged = test::runFredholm("merge " + films + "--aovs albedo,depth,spp -o " + dir + "/merged.exr");
  ASSERT_EQ(merged.exitCode, 0) << merged.output;
  std::vector<std::string> names, oneNames;
  const std::vector<float> a = test::exrChannels(dir + "/merged.exr", &names);
  const std::vector<float> b = test::exrChannels(dir + "/one.exr", &oneNames);
  EXPECT_EQ(names, oneNames);
  EXPECT_EQ(names.size(), 8u);  // R G B, albedo.R/G/B, depth.Z, spp.Y
  EXPECT_TRUE(a == b) << "the merged chunks differ from one render";
}

// Chunks that overlap, come from another render or leave passes out; flags a chunk does not
// go with; a chunk offered as a checkpoint.
TEST(Chunks, OverlapsOtherRendersGapsAndBadFlagsAreCaught) {
  const std::string dir = test::tempDir("chunk-errors");
  const std::string render = "render --width 8 --height 8 --seed 2 ";
  for (const char* passes : {"0:4", "2:6", "6:9"})
    ASSERT_EQ(test::runFredholm(render + "--passes " + passes + " --film " + dir + "/p" + passes[0] + ".film").exitCode,
              0);
  ASSERT_EQ(test::runFredholm("render --width 8 --height 8 --seed 3 --passes 4:6 --film " + dir + "/other.film").exitCode,
            0);
  struct Case {
    std::string args, message;
  };
  for (const Case& c : std::vector<Case>{
           {"merge " + dir + "/p0.film " + dir + "/p2.film -o " + dir + "/x.exr", "shares passes"},
           {"merge " + dir + "/p0.film " + dir + "/other.film -o " + dir + "/x.exr", "a chunk of another render"},
           {"merge " + dir + "/p0.film " + dir + "/missing.film -o " + dir + "/x.exr", "missing.film': file not found"},
           {"merge " + dir + "/p0.film", "missing --output (Output image"},
           {render + "--passes 4:4 --film " + dir + "/e.film", "0 <= A < B"},
           {render + "--passes -1:4 --film " + dir + "/e.film", "0 <= A < B"},
           {render + "--passes 0:4", "give --film"},
           {render + "--passes 0:4 --film " + dir + "/e.film --spp 4", "does not go with --spp"},
           {render + "--passes 0:4 --film " + dir + "/e.film --noise 1e-2", "does not go with --noise"},
           {render + "--passes 0:4 --film " + dir + "/e.film --checkpoint " + dir + "/c.fhc", "--checkpoint"},
           {render + "--passes 0:4 --film " + dir + "/p0.film", "file exists"},
           {render + "--spp 9 --resume " + dir + "/p6.film -o " + dir + "/x.exr", "holds passes 6:9, not a checkpoint"}}) {
    const auto r = test::runFredholm(c.args);
    EXPECT_NE(r.exitCode, 0) << c.args;
    EXPECT_NE(r.output.find(c.message), std::string::npos) << c.args << "\n" << r.output;
  }
  EXPECT_FALSE(std::filesystem::exists(dir + "/x.exr"));
  // A gap is said, and the image holds the passes there are.
  const auto gap = test::runFredholm("merge " + dir + "/p6.film " + dir + "/p0.film -o " + dir + "/gap.exr");
  ASSERT_EQ(gap.exitCode, 0) << gap.output;
  EXPECT_NE(gap.output.find("no part holds passes 4:6"), std::string::npos) << gap.output;
  EXPECT_NE(gap.output.find("7 passes from 2 parts"), std::string::npos) << gap.output;
}

}  // namespace
}  // namespace fh
