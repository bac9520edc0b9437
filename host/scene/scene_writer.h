// Writes a scene as OBJ + MTL (+ camera sidecar): built-in scenes become files another
// renderer can read (bench/cycles_compare.py renders the closed-form scene in Cycles).
#pragma once
#include <string>
#include <vector>

#include "scene/scene.h"

namespace fh {

// Writes objPath, the .mtl beside it and, if the scene has a camera, the .camera.json
// sidecar the loader reads back. Every path is checked before anything is written: an
// existing file is an error unless `force`. Returns the paths written.
std::vector<std::string> writeObjScene(const Scene& scene, const std::string& objPath, bool force);

}  // namespace fh
