#include "program_catalog.h"

#include <sstream>

#include "bench/ray_workload.h"
#include "kernels/path_state.h"
#include "render/light_tracer.h"
#include "render/render_aov.h"
#include "render/wavefront.h"

namespace fh {

namespace {

// The material feature sets of a span: bit 0 glossy, 1 glass, 2 textures, 3 vertex normals.
std::vector<SceneFeatures> materialFeatureSets(FeatureSpan span) {
  std::vector<unsigned> bitsets;
  if (span == FeatureSpan::EveryCombination)
    for (unsigned bits = 0; bits < 16; ++bits) bitsets.push_back(bits);
  else
    bitsets = {0u, 15u};
  std::vector<SceneFeatures> sets;
  for (unsigned bits : bitsets)
    sets.push_back({(bits & 1) != 0, (bits & 2) != 0, (bits & 4) != 0, (bits & 8) != 0});
  return sets;
}

}  // namespace

std::vector<std::string> featureMacros() {
  std::vector<std::string> macros;
  std::string options = SceneFeatures::all().buildOptions(), token;
  for (std::istringstream in(options); in >> token;)
    if (token.rfind("-D", 0) == 0) macros.push_back(token.substr(2));
  return macros;
}

std::vector<ProgramSpec> programVariants(FeatureSpan span) {
  // The deepest stack a BVH asks for changes only an array size; the default stands in.
  const std::string traversal = "-DFH_TRAVERSAL_STACK=64";
  const std::vector<SceneFeatures> materialSets = materialFeatureSets(span);
  // The path tracer's stages also with the environment map (FH_ENV_MAP): alone and with
  // every material feature (all()), or, with none and all, in all() only.
  std::vector<SceneFeatures> pathSets = materialSets;
  SceneFeatures environmentAlone;
  environmentAlone.environmentMap = true;
  if (span == FeatureSpan::EveryCombination)
    pathSets.insert(pathSets.end(), {environmentAlone, SceneFeatures::all()});
  else
    pathSets.back() = SceneFeatures::all();
  std::vector<ProgramSpec> programs = {intersectProgram(traversal), benchRaysProgram(traversal), aovProgram()};
  for (Method method : {Method::PT, Method::NEE, Method::MIS})
    for (const SceneFeatures& features : pathSets)
      for (Strategy strategy : {Strategy::Scalar, Strategy::Simd8})
        programs.push_back(pathTracerProgram(features, method, traversal, strategy));
  // The megakernel calls the same stage code: no features and all of them are enough.
  for (Method method : {Method::PT, Method::NEE, Method::MIS})
    for (const SceneFeatures& features : {SceneFeatures{}, SceneFeatures::all()})
      programs.push_back(pathTracerProgram(features, method, traversal, Strategy::Megakernel));
  // Recording the --aovs layers (FH_AOVS), with and without the features shade branches on.
  for (Strategy strategy : {Strategy::Scalar, Strategy::Megakernel8})
    for (const SceneFeatures& features : {SceneFeatures{}, SceneFeatures::all()})
      programs.push_back(pathTracerProgram(features, Method::PT, traversal, strategy, true));
  // Light tracing (--method lt), bidirectional path tracing (bdpt) and vcm: their kernels for
  // every material feature, and lt's camera paths (mis keeping those that leave the first
  // vertex by a delta lobe) with glass and mirrors.
  for (Method method : {Method::LT, Method::BDPT, Method::VCM})
    for (const SceneFeatures& features : materialSets)
      programs.push_back(lightTracerProgram(method, features, traversal, 1));
  // bdpt's and vcm's light subpaths from the environment map too.
  for (Method method : {Method::BDPT, Method::VCM})
    programs.push_back(lightTracerProgram(method, SceneFeatures::all(), traversal, 1));
  for (Strategy strategy : {Strategy::Scalar, Strategy::Simd8, Strategy::Megakernel8})
    programs.push_back(pathTracerProgram(SceneFeatures::all(), Method::LT, traversal, strategy));
  return programs;
}

std::vector<ProgramSpec> cpuLaneVariants() {
  const std::string traversal = "-DFH_TRAVERSAL_STACK=64";
  std::vector<ProgramSpec> programs;
  for (Method method : {Method::LT, Method::BDPT, Method::VCM})
    for (const SceneFeatures& features : {SceneFeatures{}, SceneFeatures::all()})
      programs.push_back(lightTracerProgram(method, features, traversal, 8));
  return programs;
}

}  // namespace fh
