// The environment variables fredholm reads only so that tests can provoke what is hard to
// provoke otherwise (a crash at a known point, a device that dies, a slow rank): all of them
// here, read once, so none hides in the code that acts on it. Users never need them; the
// user-facing variables are in docs/usage.md, and docs/testing.md#test-hooks points here.
#pragma once
#include <string>

namespace fh {

struct TestHooks {
  // FREDHOLM_KILL_AFTER_PASSES=N: the process raises SIGKILL right after saving a checkpoint
  // that holds N passes or more, a crash at a known point (render/pass_pool.cpp); -1: never.
  // Used by tests/test_checkpoint.cpp, test_adaptive.cpp and test_mpi.cpp (resume after it).
  long killAfterPasses = -1;

  // FREDHOLM_FAIL_DEVICE=I:N: device I fails when it finishes its (N+1)-th pass, as a device
  // that dies mid-render (render/render.cpp); device -1: none. Used by
  // tests/test_multi_device.cpp (its in-process tests through ScopedTestHooks) and test_mpi.cpp.
  struct DeviceFailure {
    int device = -1;
    long afterPasses = -1;
  } failDevice;

  // FREDHOLM_SLOW_RANK=R: under mpirun, rank R waits 200 ms before asking for each pass, as
  // a rank on a slower machine (distributed/mpi_render.cpp); -1: none. Used by tests/test_mpi.cpp.
  int slowRank = -1;

  // FREDHOLM_TEST_STRATEGY=S: the strategy test::renderSettings() gives the rendering suites
  // (tests/test_support.cpp parses it; CTest runs each suite under several,
  // tests/CMakeLists.txt); empty: the device's own. fredholm itself never reads it.
  std::string testStrategy;

  // In-process only (no variable): bdpt keeps, for each path, only the contribution of the
  // strategy with this many light vertices (kernels/bdpt.cl, FH_BDPT_ONLY_S), weight one, so
  // each strategy's estimator can be tested alone; -1: all of them, weighted. Used by
  // tests/test_path_tracer.cpp.
  int bdptOnlyLightVertices = -1;

  // In-process only: vcm keeps only its merges at the first camera vertex (and the emitters
  // the camera sees), weight one (kernels/bdpt.cl, FH_VCM_MERGE_ONLY), so that merging's
  // estimator can be tested alone. Used by tests/test_path_tracer.cpp.
  bool vcmMergeOnly = false;

  // In-process only: the path tracer's light sampling (nee, mis) places the point on the
  // picked light by a dimension of its own for every light, as where its share is narrow
  // (kernels/sampling.h, FH_NARROW_SHARE), so that a test can measure what drawing the
  // pick and the point from one 2D sample gains. Used by tests/test_path_tracer.cpp.
  bool everyShareNarrow = false;
};

// The hooks, parsed from the environment on first use. A malformed value is an Error that
// names the variable (the process reads them all at once, so any render reports it).
const TestHooks& testHooks();

// For tests that render in-process: `hooks` in place of the environment's while it lives.
// Set it between renders, never while one runs (its threads read the hooks unlocked).
class ScopedTestHooks {
 public:
  explicit ScopedTestHooks(const TestHooks& hooks);
  ~ScopedTestHooks();
  ScopedTestHooks(const ScopedTestHooks&) = delete;
  ScopedTestHooks& operator=(const ScopedTestHooks&) = delete;

 private:
  TestHooks saved_;
};

}  // namespace fh
