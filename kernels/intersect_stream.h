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

// A stream's rays: each ray's constants and segment, ray l's at index l of every array, so
// that a test finds them at one offset from the stream's start.
#define FH_STREAM_OF(type, name) type name[FH_STREAM];
typedef struct {
  FH_RAY_CONSTANTS(FH_STREAM_OF)
  float t_min[FH_STREAM], t_max[FH_STREAM];
} RayStream;

// Rays [at, at + 8) of the stream from eight set up together.
FH_INLINE void add_rays8(RayStream* out, int at, RayLanes8 lanes, float8 t_min, float8 t_max) {
  FH_RAY_CONSTANTS(FH_STORE_LANES_OF)
  vstore8(t_min, 0, out->t_min + at);
  vstore8(t_max, 0, out->t_max + at);
}

// The index of the lowest set bit of m (m != 0): on x86 one instruction (tzcnt) where clz
// takes four; OpenCL 1.2 has no ctz.
FH_INLINE int lowest_bit64(ulong m) {
#ifdef __AVX2__
  return __builtin_ctzl(m);
#else
  return 63 - (int)clz(m & (0ul - m));
#endif
}

// Whether a triangle of the block lies on the ray's segment [t_min, t_max): intersect_block's
// any-hit answer (which for a ray with no hit yet keeps the lanes with t_min <= t < t_max),
// with one branch, on the division-free test, where intersect_block takes three.
FH_INLINE bool block_occludes(const RayPrecomp* r, __global const TriangleBlock8* block, float t_min, float t_max) {
  const WatertightLanes e = watertight_block(r, block, t_min, t_max);
  if (!any_lane(e.maybe)) return false;
  const float8 t = e.t_scaled / e.det;
  return any_lane(e.maybe & (t >= (float8)(t_min)) & (t < (float8)(t_max)));
}

#if defined(__AVX512F__) && defined(__AVX512VL__)
typedef long fh_v8di __attribute__((vector_size(64)));
#endif

// Pushes the children some ray reaches (child_rays != 0), each with its rays: the inner
// nodes first, then the leaves, so that leaves are popped first (a leaf is one test and may
// end its rays, where a node opens a subtree), each kind last lane first so that it is
// popped in lane order (the binary tree's order, left before right). No branch per child:
// where a loop over the children reached mispredicts, AVX-512 packs them together in one
// instruction per array, and elsewhere every slot is stored and the stack pointer moves
// past those reached. The stack needs eight entries of room past its deepest use.
FH_INLINE void push_children(ulong8 child_rays, int8 child, int* stack_ref, ulong* stack_rays, int* sp) {
  const ulong8 rays = shuffle(child_rays, (ulong8)(7, 6, 5, 4, 3, 2, 1, 0));
  const int8 refs = shuffle(child, (uint8)(7, 6, 5, 4, 3, 2, 1, 0));
  const uint reached = lane_bits(convert_int8(rays != (ulong8)(0ul))), leaves = lane_bits(refs);
  const uint kinds[2] = {reached & ~leaves, reached & leaves};
#if defined(__AVX512F__) && defined(__AVX512VL__) && !defined(FH_PORTABLE_PUSH)
  for (int k = 0; k < 2; ++k) {
    const uchar lanes = (uchar)kinds[k];
    vstore8(as_ulong8(__builtin_ia32_compressdi512_mask((fh_v8di)rays, (fh_v8di)(ulong8)(0ul), lanes)), 0,
            stack_rays + *sp);
    vstore8(as_int8(__builtin_ia32_compresssi256_mask((fh_v8si)refs, (fh_v8si)(int8)(0), lanes)), 0,
            stack_ref + *sp);
    *sp += (int)popcount((uint)lanes);
  }
#else
  ulong r[8];
  int c[8];
  vstore8(rays, 0, r);
  vstore8(refs, 0, c);
  for (int k = 0; k < 2; ++k) {
    _Pragma("unroll") for (int i = 0; i < 8; ++i) {
      stack_ref[*sp] = c[i];
      stack_rays[*sp] = r[i];
      *sp += (int)((kinds[k] >> i) & 1u);
    }
  }
#endif
}

// Bit l set where ray l of the stream (l < count) has an occluder on its segment.
FH_INLINE ulong find_occluders(__global const Bvh8Node* nodes, __global const TriangleBlock8* blocks,
                               const RayStream* s, int count) {
  ulong open = count >= 64 ? ~0ul : (1ul << count) - 1ul;  // rays not yet occluded
  ulong occluded = 0ul;
  int stack_ref[FH_TRAVERSAL_STACK + 8];
  ulong stack_rays[FH_TRAVERSAL_STACK + 8];
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
      // Lane c: the rays that hit child c.
      ulong8 child_rays = (ulong8)(0ul);
      for (ulong m = rays; m != 0ul; m &= m - 1ul) {
        const int l = lowest_bit64(m);
        RayPrecomp ray;
        FH_RAY_AT(s, l, ray);
        float8 t_near, t_far;
        child_intervals(&ray, node, s->t_max[l], &t_near, &t_far);
        // intersect_children's misses, but for a box at infinity on an endless segment (t_near
        // and t_far both +INFINITY, which needs t_max = +INFINITY), whose leaves are then
        // tested exactly: the same answers, one comparison fewer per ray.
        const int8 hits = ~(t_near > t_far);
        child_rays |= select((ulong8)(0ul), (ulong8)(1ul << l), convert_long8(hits));
      }
      const int8 child = vload8(0, node->child);
      child_rays = select((ulong8)(0ul), child_rays, convert_long8(child != (int8)(0)));
      push_children(child_rays, child, stack_ref, stack_rays, &sp);
    } else {
      __global const TriangleBlock8* block = blocks + ~ref;
      for (ulong m = rays; m != 0ul; m &= m - 1ul) {
        const int l = lowest_bit64(m);
        RayPrecomp ray;
        FH_RAY_AT(s, l, ray);
        occluded |= (ulong)block_occludes(&ray, block, s->t_min[l], s->t_max[l]) << l;
      }
      open &= ~occluded;
      if (open == 0ul) break;
    }
  }
  return occluded;
}

#endif
