// Subdividing the icosahedron, with each edge's midpoint made once and shared.
#include "scene/icosphere.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>

namespace fh {

IndexedMesh icosphere(int levels) {
  const float g = (1.f + std::sqrt(5.f)) / 2.f;
  IndexedMesh m;
  m.vertices = {{-1, g, 0}, {1, g, 0}, {-1, -g, 0}, {1, -g, 0}, {0, -1, g}, {0, 1, g},
                {0, -1, -g}, {0, 1, -g}, {g, 0, -1}, {g, 0, 1}, {-g, 0, -1}, {-g, 0, 1}};
  m.faces = {{0, 11, 5}, {0, 5, 1}, {0, 1, 7}, {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
             {11, 10, 2}, {10, 7, 6}, {7, 1, 8}, {3, 9, 4}, {3, 4, 2}, {3, 2, 6}, {3, 6, 8},
             {3, 8, 9}, {4, 9, 5}, {2, 4, 11}, {6, 2, 10}, {8, 6, 7}, {9, 8, 1}};
  for (float3& p : m.vertices) p = normalize(p);
  for (int level = 0; level < levels; ++level) {
    std::map<std::pair<unsigned, unsigned>, unsigned> midpoints;
    auto midpoint = [&](unsigned a, unsigned b) {
      const auto key = std::minmax(a, b);
      const auto it = midpoints.find(key);
      if (it != midpoints.end()) return it->second;
      m.vertices.push_back(normalize((m.vertices[a] + m.vertices[b]) * 0.5f));
      return midpoints[key] = unsigned(m.vertices.size() - 1);
    };
    std::vector<std::array<unsigned, 3>> finer;
    for (const auto& f : m.faces) {
      const unsigned ab = midpoint(f[0], f[1]), bc = midpoint(f[1], f[2]), ca = midpoint(f[2], f[0]);
      finer.insert(finer.end(), {{f[0], ab, ca}, {f[1], bc, ab}, {f[2], ca, bc}, {ab, bc, ca}});
    }
    m.faces = std::move(finer);
  }
  return m;
}

}  // namespace fh
