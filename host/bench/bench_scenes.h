// The scenes `fredholm bench` measures, also reachable as `fredholm render bench:NAME`.
#pragma once
#include <string>

#include "scene/scene.h"

namespace fh {

// A bench scene by name (cornell, bunny-box, sponza, bunnies-1m: the generated scene of
// about 1.1M triangles) or an OBJ path; `name` is what the bench reports it as.
Scene benchScene(const std::string& spec, std::string& name);

// Throws the error benchScene would for a scene it cannot read (a shared scene that is not
// there, a bad spheres:N, a path that does not exist) without loading anything, so a bench
// can refuse before it measures.
void checkBenchScene(const std::string& spec);

// The directory of the larger bench scenes, which do not ship (their licences or sizes):
// $FREDHOLM_SCENES, else "" (none).
std::string sharedScenesDir();

// A scene without emitters (Sponza) gets a stand-in light so shadow rays can be timed.
void addBenchLightIfNone(Scene& scene);

}  // namespace fh
