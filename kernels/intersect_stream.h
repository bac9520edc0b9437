// Any-hit queries for a stream of up to FH_STREAM rays per work-item: the stream goes down
// the 8-wide BVH together, each node fetched once for all of its rays that reach it and
// tested against them one by one (the single-ray box test), the rays that hit each child
// carried down as a 64-bit mask. A shadow ray on a large tree waits on memory for most
// of its node and leaf loads; in a stream, neighbouring rays reach mostly the same nodes,
// and only the first of them waits. (Embree's ray streams work the same way; Fuetterling,
// Lojewski, Pfreundt and Ebert, "Efficient Ray Tracing Kernels for Modern CPU
// Architectures", JCGT 2015.) The answers are find_occluder's: every node and leaf a ray's
// segment touches is still tested until the ray is found occluded.
#ifndef FH_INTERSECT_STREAM_H
#define FH_INTERSECT_STREAM_H

#include "intersect.h"

// Asks for a child's lines (a node's boxes or a leaf's triangles) ahead of its visit, for
// children that wait on the stack a while before they are popped: every other 64-byte
// line, as x86 caches fetch lines in pairs. x86 only (the hint is a Clang built-in);
// elsewhere nothing.
FH_INLINE void fetch_child_early(__global const Bvh8Node* nodes, __global const TriangleBlock8* blocks, int child) {
#ifdef __AVX__
  __global const char* p = child >= 0 ? (__global const char*)(nodes + child) : (__global const char*)(blocks + ~child);
  const int bytes = child >= 0 ? (int)sizeof(Bvh8Node) : (int)sizeof(TriangleBlock8);
  for (int offset = 0; offset < bytes; offset += 128) __builtin_prefetch(p + offset);
#endif
}

// The index of the lowest set bit of m (m != 0).
FH_INLINE int lowest_bit64(ulong m) { return 63 - (int)clz(m & (0ul - m)); }

// Bit l set where ray l (l < count; its constants are lane l % 8 of r[l / 8]) has an
// occluder on [t_min[l], t_max[l]).
FH_INLINE ulong find_occluders(__global const Bvh8Node* nodes, __global const TriangleBlock8* blocks,
                               const RayPrecomp8* r, const float* t_min, const float* t_max, int count) {
  ulong open = count >= 64 ? ~0ul : (1ul << count) - 1ul;  // rays not yet occluded
  ulong occluded = 0ul;
  int stack_ref[FH_TRAVERSAL_STACK];
  ulong stack_rays[FH_TRAVERSAL_STACK];
  int sp = 0;
  stack_ref[sp] = 0;  // the root
  stack_rays[sp++] = open;
  while (sp > 0) {
    --sp;
    const int ref = stack_ref[sp];
    const ulong rays = stack_rays[sp] & open;
    if (rays == 0ul) continue;
    if (ref >= 0) {
      __global const Bvh8Node* node = nodes + ref;
      // Lane c: the rays that hit child c. A ray's eight hit bits are spread over the lanes
      // in one step, where a loop over them mispredicts.
      ulong8 child_rays = (ulong8)(0ul);
      const int8 filled = vload8(0, node->child) != (int8)(0);
      for (ulong m = rays; m != 0ul; m &= m - 1ul) {
        const int l = lowest_bit64(m);
        const RayPrecomp ray = ray_of_lane(&r[l >> 3], l & 7);
        float8 t_near, t_far;
        child_intervals(&ray, node, t_max[l], &t_near, &t_far);
        const int8 hits = ~(t_near > t_far) & (t_near != (float8)(INFINITY)) & filled;
        child_rays |= select((ulong8)(0ul), (ulong8)(1ul << l), convert_long8(hits));
      }
      ulong pushed[8];
      vstore8(child_rays, 0, pushed);
      // The children some ray hit, pushed last to first so they are visited in lane order.
      const int8 reached = convert_int8(child_rays != (ulong8)(0ul));
      for (uint c = lane_bits(reached); c != 0u; c &= ~(0x80000000u >> clz(c))) {
        const int highest = 31 - (int)clz(c);
        const int child = node->child[highest];
        fetch_child_early(nodes, blocks, child);
        stack_ref[sp] = child;
        stack_rays[sp++] = pushed[highest];
      }
    } else {
      __global const TriangleBlock8* block = blocks + ~ref;
      for (ulong m = rays; m != 0ul; m &= m - 1ul) {
        const int l = lowest_bit64(m);
        float t_end = t_max[l], b1, b2;
        const RayPrecomp ray = ray_of_lane(&r[l >> 3], l & 7);
        if (intersect_block(&ray, block, t_min[l], &t_end, -1, &b1, &b2, true) >= 0) occluded |= 1ul << l;
      }
      open &= ~occluded;
      if (open == 0ul) break;
    }
  }
  return occluded;
}

#endif
