// Packet traversal: eight rays of one work-item go down the 8-wide BVH together, each node
// loaded once for all eight and its children tested one by one across the rays (float8
// over rays, where trace_ray is float8 over children). For coherent batches (camera rays of
// neighbouring pixels), which visit mostly the same nodes, the per-node work of single-ray
// traversal (ordering the children, pushing, popping, the branches that mispredict) is
// then paid once for eight rays.
//
// The hits are trace_ray's, bit for bit: every (ray, box) and (ray, triangle) test is the
// same arithmetic, a box is culled only where it cannot hold the closest hit, and ties in t
// go to the lower triangle index (closer_hit8), so the visiting order does not matter.
#ifndef FH_INTERSECT_PACKET_H
#define FH_INTERSECT_PACKET_H

#include "intersect.h"

// The rays' constants as lanes. The watertight test's axis order (kx, ky, kz: 0 for x, 1 for
// y, 2 for z) is each lane's own; where every lane shares it (`uniform`) it is also kept as
// scalars, so a triangle's components load once for all lanes, and otherwise each lane
// picks its own three (packets of incoherent rays, on small trees).
typedef struct {
  float8 lo_offset_x, lo_offset_y, lo_offset_z, hi_offset_x, hi_offset_y, hi_offset_z;  // FH_SLAB_OFFSET, per plane
  float8 inv_x, inv_y, inv_z;
  float8 sx, sy, sz, ox, oy, oz;
  float8 t_min;
  int8 lane_kx, lane_ky, lane_kz;
  int kx, ky, kz;
  bool uniform;
} RayPacket;

// Slab-test constants of one axis for all lanes, as precompute_ray makes them: the low
// plane is a lane's entry plane where its direction is positive, its exit plane elsewhere.
FH_INLINE void slab_lanes(float8 o, float8 d, float8* lo_offset, float8* hi_offset, float8* inv) {
  const float8 tiny = (float8)(1e-30f);
  const int8 flat = fabs(d) < tiny;
  const float8 eps = fmax(fabs(o), (float8)(1.0f)) * 0x1p-20f;
  *inv = 1.0f / select(d, tiny, flat);
  const float8 org_lo = select(o, o + eps, flat), org_hi = select(o, o - eps, flat);
  *lo_offset = FH_SLAB_OFFSET(org_lo, *inv, *inv, float8);
  *hi_offset = FH_SLAB_OFFSET(org_hi, *inv, -*inv, float8);
}

// precompute_ray for ray l in lane l, all lanes at once (the same operations, so the same
// bits).
FH_INLINE void make_packet_lanes(float8 ox, float8 oy, float8 oz, float8 dx, float8 dy, float8 dz, float8 t_min,
                                 RayPacket* p) {
  int8 kx, ky, kz;
  float8 along;
  axis_orders8(dx, dy, dz, &kx, &ky, &kz, &along);
  p->lane_kx = kx;
  p->lane_ky = ky;
  p->lane_kz = kz;
  p->kx = kx.s0;
  p->ky = ky.s0;
  p->kz = kz.s0;
  p->uniform = all_lanes((kx == (int8)(p->kx)) & (ky == (int8)(p->ky)) & (kz == (int8)(p->kz)));
  p->sx = component8(dx, dy, dz, kx) / along;
  p->sy = component8(dx, dy, dz, ky) / along;
  p->sz = 1.0f / along;
  p->ox = component8(ox, oy, oz, kx);
  p->oy = component8(ox, oy, oz, ky);
  p->oz = component8(ox, oy, oz, kz);
  slab_lanes(ox, dx, &p->lo_offset_x, &p->hi_offset_x, &p->inv_x);
  slab_lanes(oy, dy, &p->lo_offset_y, &p->hi_offset_y, &p->inv_y);
  slab_lanes(oz, dz, &p->lo_offset_z, &p->hi_offset_z, &p->inv_z);
  p->t_min = t_min;
}

// make_packet_lanes for rays from arrays; lanes at or past `count` repeat the last ray (the
// caller leaves them out).
FH_INLINE void make_packet(const float3* org, const float3* dir, int count, const float* t_min, RayPacket* p) {
  float a[7][FH_PACKET];
  for (int l = 0; l < FH_PACKET; ++l) {
    const int k = min(l, count - 1);
    a[0][l] = org[k].x;
    a[1][l] = org[k].y;
    a[2][l] = org[k].z;
    a[3][l] = dir[k].x;
    a[4][l] = dir[k].y;
    a[5][l] = dir[k].z;
    a[6][l] = t_min[k];
  }
  make_packet_lanes(vload8(0, a[0]), vload8(0, a[1]), vload8(0, a[2]), vload8(0, a[3]), vload8(0, a[4]),
                    vload8(0, a[5]), vload8(0, a[6]), p);
}

// The near distance of child `c` for each ray, +INFINITY where the ray misses it or no
// longer needs it (t_hit: each ray's current hit, -INFINITY for rays that are done).
FH_INLINE float8 packet_child_near(const RayPacket* p, __global const Bvh8Node* node, int c, float8 t_hit) {
  const float8 tx0 = fma((float8)(node->lo_x[c]), p->inv_x, p->lo_offset_x);
  const float8 tx1 = fma((float8)(node->hi_x[c]), p->inv_x, p->hi_offset_x);
  const float8 ty0 = fma((float8)(node->lo_y[c]), p->inv_y, p->lo_offset_y);
  const float8 ty1 = fma((float8)(node->hi_y[c]), p->inv_y, p->hi_offset_y);
  const float8 tz0 = fma((float8)(node->lo_z[c]), p->inv_z, p->lo_offset_z);
  const float8 tz1 = fma((float8)(node->hi_z[c]), p->inv_z, p->hi_offset_z);
  return slab_near(tx0, tx1, ty0, ty1, tz0, tz1, t_hit);
}

// Pushes the children any ray hits, farthest first (by the nearest ray's distance), and
// returns the nearest, or 0 if none is hit.
FH_INLINE int packet_order_children(const RayPacket* p, __global const Bvh8Node* node, float8 t_hit,
                                    int* stack_node, float* stack_t, int* sp) {
  int ref[8];
  float key[8];
  int n = 0;
  for (int c = 0; c < 8; ++c) {
    const int child = node->child[c];
    if (child == 0) break;  // empty slots come last
    const float t = min_lane(packet_child_near(p, node, c, t_hit));
    if (t == INFINITY) continue;
    // Insertion sort by decreasing distance.
    int j = n++;
    while (j > 0 && key[j - 1] < t) {
      key[j] = key[j - 1];
      ref[j] = ref[j - 1];
      --j;
    }
    key[j] = t;
    ref[j] = child;
  }
  if (n == 0) return 0;
  for (int k = 0; k < n - 1; ++k) {
    stack_node[*sp] = ref[k];
    stack_t[*sp] = key[k];
    ++*sp;
  }
  return ref[n - 1];
}

typedef struct {
  float8 t, b1, b2;
  int8 triangle;  // BVH-order index, -1 while none
} PacketHits;

// Vertex `vertex` of a leaf's triangle j in each lane's axis order (x: kx, y: ky, z: kz).
FH_INLINE void packet_vertex(const RayPacket* p, __global const TriangleBlock8* block, int vertex, int j, float8* x,
                             float8* y, float8* z) {
  if (p->uniform) {
    *x = (float8)(block->v[vertex][p->kx][j]);
    *y = (float8)(block->v[vertex][p->ky][j]);
    *z = (float8)(block->v[vertex][p->kz][j]);
    return;
  }
  const float8 vx = (float8)(block->v[vertex][0][j]), vy = (float8)(block->v[vertex][1][j]),
               vz = (float8)(block->v[vertex][2][j]);
  *x = component8(vx, vy, vz, p->lane_kx);
  *y = component8(vx, vy, vz, p->lane_ky);
  *z = component8(vx, vy, vz, p->lane_kz);
}

// The leaf's triangles one by one, each tested against all the rays: the watertight test of
// intersect_block, lane for lane the same arithmetic. Any-hit rays that are hit are done:
// their t becomes -INFINITY.
FH_INLINE void packet_intersect_block(const RayPacket* p, __global const TriangleBlock8* block, PacketHits* h,
                                      bool any_hit) {
  for (int j = 0; j < 8; ++j) {
    const int id = block->id[j];
    if (id < 0) break;  // empty lanes come last
    float8 x0, y0, z0, x1, y1, z1, x2, y2, z2;
    packet_vertex(p, block, 0, j, &x0, &y0, &z0);
    packet_vertex(p, block, 1, j, &x1, &y1, &z1);
    packet_vertex(p, block, 2, j, &x2, &y2, &z2);
    const WatertightLanes e = watertight_lanes(x0, y0, z0, x1, y1, z1, x2, y2, z2, p->ox, p->oy, p->oz, p->sx, p->sy,
                                               p->sz, p->t_min, h->t);
    const int8 maybe = e.maybe;
    if (!any_lane(maybe)) continue;
    const float8 quotient = e.t_scaled / e.det;
    const int8 valid = maybe & (quotient >= p->t_min) & closer_hit8(quotient, (int8)(id), h->t, h->triangle);
    if (!any_lane(valid)) continue;
    h->triangle = select(h->triangle, (int8)(id), valid);
    if (any_hit) {
      h->t = select(h->t, (float8)(-INFINITY), valid);
      continue;
    }
    h->t = select(h->t, quotient, valid);
    h->b1 = select(h->b1, e.v / e.det, valid);
    h->b2 = select(h->b2, e.w / e.det, valid);
  }
}

// The packet's rays, lane l on [t_min, t_end[l]) (t_end -INFINITY: a lane to leave out),
// traced together: closest hits, or for any-hit queries some occluder (h.t then -INFINITY
// where one is found). h.triangle is -1 where there is none.
FH_INLINE PacketHits trace_packet_lanes(__global const Bvh8Node* nodes, __global const TriangleBlock8* blocks,
                                        const RayPacket* p, float8 t_end, bool any_hit) {
  PacketHits h;
  h.t = t_end;
  h.b1 = h.b2 = (float8)(0.0f);
  h.triangle = (int8)(-1);
  int stack_node[FH_TRAVERSAL_STACK];
  float stack_t[FH_TRAVERSAL_STACK];
  int sp = 0;
  int ref = 0;  // the root
  float reach = max_lane(h.t);  // the farthest any ray still needs to look
  for (;;) {
    if (ref >= 0) {
      __global const Bvh8Node* node = nodes + ref;
      ref = packet_order_children(p, node, h.t, stack_node, stack_t, &sp);
      if (ref != 0) continue;
    } else {
      packet_intersect_block(p, blocks + ~ref, &h, any_hit);
      reach = max_lane(h.t);
      if (reach == -INFINITY) break;  // every any-hit ray is occluded
    }
    ref = 0;
    while (sp > 0) {
      --sp;
      if (stack_t[sp] <= reach * FH_SLAB_WIDEN) {
        ref = stack_node[sp];
        break;
      }
    }
    if (ref == 0) break;
  }
  return h;
}

// Traces rays org[l] + t dir[l], t in [t_min[l], t_max[l]), for l < count (1..8), into
// hit[l] as trace_ray would (any-hit queries: some occluder's index, where find_occluder
// finds one, and t_max).
FH_INLINE void trace_packet(__global const Bvh8Node* nodes, __global const TriangleBlock8* blocks, const float3* org,
                            const float3* dir, const float* t_min, const float* t_max, int count, bool any_hit,
                            TraceHit* hit) {
  RayPacket p;
  make_packet(org, dir, count, t_min, &p);
  float end[FH_PACKET];
  for (int l = 0; l < FH_PACKET; ++l) end[l] = l < count ? t_max[l] : -INFINITY;
  const PacketHits h = trace_packet_lanes(nodes, blocks, &p, vload8(0, end), any_hit);
  float t[FH_PACKET], b1[FH_PACKET], b2[FH_PACKET];
  int tri[FH_PACKET];
  vstore8(h.t, 0, t);
  vstore8(h.b1, 0, b1);
  vstore8(h.b2, 0, b2);
  vstore8(h.triangle, 0, tri);
  for (int l = 0; l < count; ++l) {
    hit[l].triangle = tri[l];
    hit[l].t = tri[l] >= 0 && !any_hit ? t[l] : t_max[l];
    hit[l].b1 = b1[l];
    hit[l].b2 = b2[l];
  }
}

#endif
