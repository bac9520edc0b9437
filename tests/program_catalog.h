// The program variants fredholm can build, for checks that must see them (the portability
// gates: strict offline compiles for other targets, builds with optimisation off). The
// entries come from the same functions the renderers call.
#pragma once
#include <string>
#include <vector>

#include "device/program.h"

namespace fh {

// Which sets of material features (glossy, glass, textures, vertex normals) a catalogue
// spans. Every combination is what a scene can ask for. No kernel condition names two
// features at once (FeatureSwitches.NoConditionNamesTwoFeatures checks), so none and all
// of them compile both sides of every feature switch: enough for a compiler's back end,
// which sees the code the front end has already checked in every combination.
enum class FeatureSpan { EveryCombination, NoneAndAll };

std::vector<ProgramSpec> programVariants(FeatureSpan span);

// What only a CPU builds beyond programVariants: the light methods' kernels in eight lanes
// (their lanes: GPUs take one), with none and with all features. The portable front end
// compiles them (spir64); a GPU back end never sees them.
std::vector<ProgramSpec> cpuLaneVariants();

// The feature macros SceneFeatures::buildOptions() defines.
std::vector<std::string> featureMacros();

}  // namespace fh
