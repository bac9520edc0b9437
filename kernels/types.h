// Layouts shared by host and device: plain C structs of scalars and fixed arrays only, so
// both compilers lay them out identically (the host static_asserts the sizes).
#ifndef FH_TYPES_H
#define FH_TYPES_H

#ifndef __OPENCL_VERSION__
#include <cstdint>
namespace fh {
namespace gpu {
typedef std::uint32_t uint;
#endif

#define FH_BVH_WIDTH 8
#define FH_LEAF_BITS 4                       // triangles per leaf stored in the low bits
#define FH_MAX_LEAF_TRIANGLES 15

// An 8-wide BVH node: child boxes stored as structure of arrays so one work-item tests
// all eight with float8 operations. child[i] > 0: inner node index; child[i] < 0: leaf,
// with ~child[i] = first_triangle << FH_LEAF_BITS | count; child[i] == 0: empty slot
// (the root, index 0, is never a child).
typedef struct {
  float lo_x[8], hi_x[8];
  float lo_y[8], hi_y[8];
  float lo_z[8], hi_z[8];
  int child[8];
} Bvh8Node;

// Camera for the generate kernel; see host/camera.h for the conventions.
typedef struct {
  float origin[4];
  float forward[4];
  float right[4];
  float up[4];  // already scaled: right by tan(fov/2)*aspect, up by tan(fov/2)
  int width, height;
  int pad0, pad1;
} CameraParams;

// Ray buffers hold float4 pairs: origin.xyz + tmin, direction.xyz + tmax.
// Hit buffers hold float4: t, barycentric b1, b2, and the triangle index in BVH order as
// bits (-1: miss); per-triangle device data is stored in that order.
// Ordered triangles hold three float4 per triangle: v0 (w: original id bits), v1, v2.

#ifndef __OPENCL_VERSION__
}  // namespace gpu
}  // namespace fh
#endif

#endif
