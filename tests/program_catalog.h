// Every program variant fredholm can build, for checks that must see all of them (the
// portability gates: strict offline compiles for other targets, builds with optimisation
// off). The entries come from the same functions the renderers call.
#pragma once
#include <vector>

#include "device/program.h"

namespace fh {

std::vector<ProgramSpec> everyProgramVariant();

}  // namespace fh
