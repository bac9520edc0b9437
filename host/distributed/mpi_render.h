// Renders shared by many processes on Open MPI (`mpirun -np N fredholm render ...`). Rank 0
// hands out passes one at a time as ranks ask for them (a ledger it serves on a thread of
// its own), every rank renders its passes on its own devices through the same pass pool
// local devices use (render/pass_pool.h), and the ranks' films are summed onto rank 0 with
// MPI_Reduce. Film sums are exact (render/film.h), so the sum is the same bits in any
// reduction order: the image does not depend on how many ranks there were or which
// rendered what. Debian's Open MPI 4.1 aborts the job when a rank dies: with --checkpoint
// every rank saves its own film (FILE.rank<r>, render/checkpoint.h), and a rerun with
// --resume FILE (any rank count) starts rank 0 from them all and hands out only the passes
// none holds, which completes the same image.
#pragma once
#include <memory>
#include <vector>

#include "accel/bvh.h"
#include "device/devices.h"
#include "render/render.h"
#include "render/settings.h"
#include "scene/camera.h"
#include "scene/scene.h"

namespace fh {

// Whether this process was started by mpirun (Open MPI names the job's size in the
// environment). Without mpirun, fredholm never initializes MPI.
bool startedByMpirun();

// MPI for the lifetime of the process's commands.
class MpiSession {
 public:
  MpiSession(int* argc, char*** argv);
  ~MpiSession();
  MpiSession(const MpiSession&) = delete;
  MpiSession& operator=(const MpiSession&) = delete;
  int rank() const { return rank_; }
  int size() const { return size_; }
  // Ends every rank of the job (after an error on one: the others would wait for it).
  [[noreturn]] void abort(int code) const;

 private:
  int rank_ = 0, size_ = 1;
};

// One render over every rank of `mpi`, each rendering on `devices` (its own); on rank 0,
// links.resume may hold passes done already. On rank 0 the result holds the whole film,
// the totals and stats.ranks; on the others, an empty film.
// FREDHOLM_SLOW_RANK=r (tests): rank r waits 200 ms before asking for each pass.
RenderResult renderAcrossRanks(const MpiSession& mpi, const std::vector<DeviceInfo>& devices, const Scene& scene,
                               const Bvh& bvh, const Camera& camera, const RenderSettings& settings,
                               RenderLinks links = {});

}  // namespace fh
