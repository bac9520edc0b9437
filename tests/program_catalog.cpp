#include "program_catalog.h"

#include "bench/ray_workload.h"
#include "kernels/path_state.h"
#include "render/light_tracer.h"
#include "render/render_aov.h"
#include "render/wavefront.h"

namespace fh {

std::vector<ProgramSpec> everyProgramVariant() {
  // The deepest stack a BVH asks for changes only an array size; the default stands in.
  const std::string traversal = "-DFH_TRAVERSAL_STACK=64";
  std::vector<ProgramSpec> programs = {intersectProgram(traversal), benchRaysProgram(traversal), aovProgram()};
  for (Method method : {Method::PT, Method::NEE, Method::MIS})
    for (unsigned bits = 0; bits < 16; ++bits)
      for (Strategy strategy : {Strategy::Scalar, Strategy::Simd8}) {
        const SceneFeatures features{(bits & 1) != 0, (bits & 2) != 0, (bits & 4) != 0, (bits & 8) != 0};
        programs.push_back(pathTracerProgram(features, method, traversal, strategy));
      }
  // The environment map (FH_ENV_MAP) alone; all() below includes it with every material feature.
  for (Method method : {Method::PT, Method::NEE, Method::MIS})
    for (Strategy strategy : {Strategy::Scalar, Strategy::Simd8}) {
      SceneFeatures features;
      features.environmentMap = true;
      programs.push_back(pathTracerProgram(features, method, traversal, strategy));
    }
  // The megakernel calls the same stage code: no features and all of them are enough.
  for (Method method : {Method::PT, Method::NEE, Method::MIS})
    for (const SceneFeatures& features : {SceneFeatures{}, SceneFeatures::all()})
      programs.push_back(pathTracerProgram(features, method, traversal, Strategy::Megakernel));
  // Recording the --aovs layers (FH_AOVS), with and without the features shade branches on.
  for (Strategy strategy : {Strategy::Scalar, Strategy::Megakernel8})
    for (const SceneFeatures& features : {SceneFeatures{}, SceneFeatures::all()})
      programs.push_back(pathTracerProgram(features, Method::PT, traversal, strategy, true));
  // Light tracing (--method lt) and bidirectional path tracing (bdpt): their kernels for every
  // material feature, and lt's camera paths (mis keeping those that leave the first vertex by
  // a delta lobe) with glass and mirrors.
  for (Method method : {Method::LT, Method::BDPT})
    for (unsigned bits = 0; bits < 16; ++bits)
      programs.push_back(
          lightTracerProgram(method, {(bits & 1) != 0, (bits & 2) != 0, (bits & 4) != 0, (bits & 8) != 0}, traversal));
  // bdpt's light subpaths from the environment map too.
  programs.push_back(lightTracerProgram(Method::BDPT, SceneFeatures::all(), traversal));
  for (Strategy strategy : {Strategy::Scalar, Strategy::Simd8, Strategy::Megakernel8})
    programs.push_back(pathTracerProgram(SceneFeatures::all(), Method::LT, traversal, strategy));
  return programs;
}

}  // namespace fh
