// Passes handed out by rank 0, films summed onto it.
#include "distributed/mpi_render.h"

#include <mpi.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <string>
#include <thread>

#include "base/test_hooks.h"
#include "render/pass_ledger.h"

namespace fh {
namespace {

using Clock = std::chrono::steady_clock;

// Messages to rank 0: a request for a pass (answered with kTagPass: the pass, or -1 for
// none left), a pass finished (for rank 0's progress display), or a rank's goodbye once its
// render is over.
constexpr int kTagRequest = 1, kTagPass = 2, kTagBye = 3, kTagFinished = 4;

// FREDHOLM_SLOW_RANK=r (base/test_hooks.h): rank r is slowed on purpose, as a rank on a slower machine.
void slowDownIfAsked(int rank) {
  if (testHooks().slowRank == rank) std::this_thread::sleep_for(std::chrono::milliseconds(200));
}

// Rank 0's ledger: the render's pass count and time budget, for its own pool (next) and,
// on the server thread, for every other rank's requests.
class RootLedger : public PassLedger {
 public:
  // `done`: passes a resumed film holds already (none if null), never handed out again.
  RootLedger(uint32_t total, double seconds, const Film* done) : total_(total), seconds_(seconds), done_(done) {}

  bool next(uint32_t& pass) override {
    slowDownIfAsked(0);
    return take(pass);
  }

  // Answers the other ranks until each has said goodbye.
  void serve(int ranks) {
    for (int byes = 0; byes < ranks - 1;) {
      int64_t message = 0;
      MPI_Status status;
      MPI_Recv(&message, 1, MPI_INT64_T, MPI_ANY_SOURCE, MPI_ANY_TAG, MPI_COMM_WORLD, &status);
      if (status.MPI_TAG == kTagBye) {
        ++byes;
        continue;
      }
      if (status.MPI_TAG == kTagFinished) {
        ++finishedElsewhere_;
        continue;
      }
      uint32_t pass = 0;
      int64_t reply = take(pass) ? int64_t(pass) : -1;
      MPI_Send(&reply, 1, MPI_INT64_T, status.MPI_SOURCE, kTagPass, MPI_COMM_WORLD);
      bytes += sizeof reply;
    }
  }

  uint64_t finishedElsewhere() const override { return finishedElsewhere_; }

  uint64_t bytes = 0;  // sent: the answers
 private:
  bool take(uint32_t& pass) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!started_) {  // the time budget counts from the first pass handed out, as a pool's
      start_ = Clock::now();
      started_ = true;
    }
    while (done_ && next_ < total_ && done_->holds(next_)) ++next_;
    if (next_ >= total_) return false;
    if (seconds_ > 0.0 && std::chrono::duration<double>(Clock::now() - start_).count() >= seconds_) return false;
    pass = next_++;
    return true;
  }

  std::mutex mutex_;
  const uint32_t total_;
  const double seconds_;
  const Film* done_;
  std::atomic<uint64_t> finishedElsewhere_{0};
  uint32_t next_ = 0;
  bool started_ = false;
  Clock::time_point start_;
};

// Another rank's ledger: each pass is a question to rank 0.
class RemoteLedger : public PassLedger {
 public:
  explicit RemoteLedger(int rank) : rank_(rank) {}

  bool next(uint32_t& pass) override {
    slowDownIfAsked(rank_);
    tellRoot(kTagRequest, 0);
    int64_t reply = -1;
    MPI_Recv(&reply, 1, MPI_INT64_T, 0, kTagPass, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    if (reply < 0) return false;
    pass = uint32_t(reply);
    return true;
  }

  void finished(uint32_t pass) override { tellRoot(kTagFinished, pass); }
  void bye() { tellRoot(kTagBye, 0); }

  uint64_t bytes = 0;  // sent: requests, reports, goodbye

 private:
  void tellRoot(int tag, int64_t value) {
    MPI_Send(&value, 1, MPI_INT64_T, 0, tag, MPI_COMM_WORLD);
    bytes += sizeof value;
  }

  int rank_;
};

// Sums every rank's film onto rank 0's (in place there). Returns the bytes this rank sent.
uint64_t reduceFilm(Film& film, const MpiSession& mpi) {
  const int rank = mpi.rank();
  uint64_t bytes = 0;
  for (std::vector<double>* v : {&film.sum, &film.sumSq, &film.aovSum, &film.oddSum}) {
    if (v->empty()) continue;
    MPI_Reduce(rank == 0 ? MPI_IN_PLACE : v->data(), v->data(), int(v->size()), MPI_DOUBLE, MPI_SUM, 0,
               MPI_COMM_WORLD);
    if (rank != 0) bytes += v->size() * sizeof(double);  // the root receives
  }
  // Which passes the sums hold: every rank's ranges, gathered.
  std::vector<uint64_t> mine;
  for (const auto& [begin, end] : film.passRanges()) mine.insert(mine.end(), {begin, end});
  int count = int(mine.size());
  std::vector<int> counts(static_cast<size_t>(mpi.size())), offsets(static_cast<size_t>(mpi.size()));
  MPI_Gather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, MPI_COMM_WORLD);
  for (size_t k = 1; k < counts.size(); ++k) offsets[k] = offsets[k - 1] + counts[k - 1];
  std::vector<uint64_t> all(size_t(offsets.back() + counts.back()));
  MPI_Gatherv(mine.data(), count, MPI_UINT64_T, all.data(), counts.data(), offsets.data(), MPI_UINT64_T, 0,
              MPI_COMM_WORLD);
  if (rank != 0) return bytes + mine.size() * sizeof(uint64_t);
  Film::PassRanges ranges;
  for (size_t i = 0; i + 1 < all.size(); i += 2) ranges.emplace_back(all[i], all[i + 1]);
  film.setPassRanges(ranges);
  return bytes;
}

// Every rank's share, gathered on rank 0: passes, busy seconds, when it finished, bytes
// sent and the devices that rendered.
void gatherShares(const MpiSession& mpi, RenderResult& r, uint64_t passes, double seconds, uint64_t bytes) {
  constexpr int kNameBytes = 256;
  const double mine[4] = {double(passes), seconds, MPI_Wtime(), double(bytes)};
  // Each device with its passes: "name: 12 passes, other: 3 passes".
  std::string list;
  for (const auto& d : r.stats.devices)
    list += (list.empty() ? "" : ", ") + d.name + ": " +
            std::to_string(r.film.pixels() ? d.samples / r.film.pixels() : 0) + " passes" +
            (d.error.empty() ? "" : " (failed)");
  char devices[kNameBytes] = {};
  std::strncpy(devices, list.c_str(), kNameBytes - 1);
  std::vector<double> all(size_t(4 * mpi.size()));
  std::vector<char> names(size_t(kNameBytes * mpi.size()));
  MPI_Gather(mine, 4, MPI_DOUBLE, all.data(), 4, MPI_DOUBLE, 0, MPI_COMM_WORLD);
  MPI_Gather(devices, kNameBytes, MPI_CHAR, names.data(), kNameBytes, MPI_CHAR, 0, MPI_COMM_WORLD);
  if (mpi.rank() != 0) return;
  double lastEnd = 0.0;
  for (int k = 0; k < mpi.size(); ++k) lastEnd = std::max(lastEnd, all[size_t(4 * k + 2)]);
  for (int k = 0; k < mpi.size(); ++k) {
    RenderStats::RankShare share;
    share.rank = k;
    share.passes = uint64_t(all[size_t(4 * k)]);
    share.seconds = all[size_t(4 * k + 1)];
    share.idleSeconds = lastEnd - all[size_t(4 * k + 2)];
    share.bytesSent = uint64_t(all[size_t(4 * k + 3)]);
    share.devices = std::string(&names[size_t(kNameBytes * k)]);
    r.stats.ranks.push_back(share);
  }
}

}  // namespace

bool startedByMpirun() {
  const char* size = std::getenv("OMPI_COMM_WORLD_SIZE");
  return size && *size;
}

MpiSession::MpiSession(int* argc, char*** argv) {
  // Worker threads ask for passes (one at a time, under the pool's lock) while the pool's
  // merger thread reports finished passes, and rank 0's server thread answers while its
  // main thread renders: calls come from several threads at once.
  int provided = 0;
  MPI_Init_thread(argc, argv, MPI_THREAD_MULTIPLE, &provided);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
  if (provided < MPI_THREAD_MULTIPLE) {
    if (rank_ == 0) std::fprintf(stderr, "fredholm: error: this MPI library does not support MPI_THREAD_MULTIPLE\n");
    abort(1);
  }
}

MpiSession::~MpiSession() { MPI_Finalize(); }

void MpiSession::abort(int code) const {
  MPI_Abort(MPI_COMM_WORLD, code);
  std::exit(code);
}

RenderResult renderAcrossRanks(const MpiSession& mpi, const std::vector<DeviceInfo>& devices, const Scene& scene,
                               const Bvh& bvh, const Camera& camera, const RenderSettings& settings,
                               RenderLinks links) {
  RootLedger root(uint32_t(std::max(1, settings.spp)), settings.seconds, links.resume.get());
  RemoteLedger remote(mpi.rank());
  links.ledger = mpi.rank() == 0 ? static_cast<PassLedger*>(&root) : &remote;
  std::thread server;
  if (mpi.rank() == 0) server = std::thread([&] { root.serve(mpi.size()); });
  const double start = MPI_Wtime();
  RenderResult r;
  try {
    r = render(devices, scene, bvh, camera, settings, links);
  } catch (...) {
    // The error ends the job (MPI_Abort, cli/main.cpp); the server cannot be joined first,
    // as it waits for ranks that will never say goodbye.
    if (server.joinable()) server.detach();
    throw;
  }
  const double seconds = MPI_Wtime() - start;
  if (mpi.rank() == 0) server.join();
  else remote.bye();

  const uint64_t passes = r.film.passes();
  const uint64_t bytes = reduceFilm(r.film, mpi) + (mpi.rank() == 0 ? root.bytes : remote.bytes);
  gatherShares(mpi, r, passes, seconds, bytes);
  int complete = r.complete ? 1 : 0, allComplete = 0;
  MPI_Reduce(&complete, &allComplete, 1, MPI_INT, MPI_MIN, 0, MPI_COMM_WORLD);
  uint64_t counts[4] = {r.stats.cameraRays, r.stats.bounceRays, r.stats.shadowRays, r.stats.nonfinite}, sums[4] = {};
  MPI_Reduce(counts, sums, 4, MPI_UINT64_T, MPI_SUM, 0, MPI_COMM_WORLD);
  double slowest = 0.0;
  MPI_Reduce(&r.stats.seconds, &slowest, 1, MPI_DOUBLE, MPI_MAX, 0, MPI_COMM_WORLD);
  if (mpi.rank() != 0) return RenderResult{};
  r.complete = allComplete == 1;
  r.stats.cameraRays = sums[0];
  r.stats.bounceRays = sums[1];
  r.stats.shadowRays = sums[2];
  r.stats.nonfinite = sums[3];
  r.stats.samples = r.film.passes() * r.film.pixels();
  r.stats.seconds = slowest;
  return r;
}

}  // namespace fh
