// The unit icosphere: the icosahedron with each face split into four `levels` times
// (20 * 4^levels triangles), every vertex on the unit sphere and shared by the faces around
// it (closed: every edge belongs to two faces), faces counter-clockwise seen from outside.
// Generated scenes use it: the bench's sphere field, the test scenes, the watertightness tests.
#pragma once
#include <array>
#include <vector>

#include "base/vec.h"

namespace fh {

struct IndexedMesh {
  std::vector<float3> vertices;
  std::vector<std::array<unsigned, 3>> faces;
};

IndexedMesh icosphere(int levels);

}  // namespace fh
