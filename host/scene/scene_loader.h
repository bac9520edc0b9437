// OBJ+MTL scenes into fh::Scene, through tinyobjloader after obj_lint's checks.
#pragma once
#include <string>

#include "scene/scene.h"

namespace fh {

// Loads an OBJ file and its MTL libraries. Throws fh::Error naming the file (and line)
// for anything that would load wrong; recoverable problems become Scene::warnings.
Scene loadScene(const std::string& objPath);

// The built-in Cornell box (embedded in the binary).
Scene loadDefaultScene();

// Fills Scene::lights from the emissive triangles (for scenes built in code).
void collectLights(Scene& scene);

}  // namespace fh
