// Layouts shared by host and device: plain C structs of scalars and fixed arrays only, so
// both compilers lay them out identically (the host static_asserts the sizes).
#ifndef FH_TYPES_H
#define FH_TYPES_H

#ifdef __OPENCL_VERSION__
// Device helpers must be inlined into the kernels: PoCL's LLVM leaves larger ones out of
// line, and then passes rays, stacks and hits through memory (slower; see RESULTS).
// `static` matters: OpenCL C follows C99's inline rules, under which a plain `inline`
// function has no external definition, so a compiler that does not inline it (optimisation
// off, or always_inline taken as a hint) would leave it undefined at link time.
// FH_NO_FORCED_INLINE leaves inlining to the compiler, as a simulator (Oclgrind) needs
// and as a compiler that takes always_inline as a hint would do.
#ifdef FH_NO_FORCED_INLINE
#define FH_INLINE static inline
#else
#define FH_INLINE static inline __attribute__((always_inline))
#endif
#endif

#ifndef __OPENCL_VERSION__
#include <cstdint>
namespace fh {
namespace gpu {
typedef std::uint32_t uint;
#endif

#define FH_BVH_WIDTH 8
#define FH_MAX_LEAF_TRIANGLES 8  // a leaf is one TriangleBlock8
#define FH_PACKET 8               // rays per work-item in the packet kernels (ray_cast.cl)
// Ns at or above which an illum 3/5/8 surface is a perfect mirror (bsdf.h; the host's
// hasDeltaLobes asks the same).
#define FH_NS_MIRROR 1000.0f
#define FH_STREAM 64              // rays per work-item in the any-hit stream kernel (a 64-bit mask)

// An 8-wide BVH node: child boxes stored as structure of arrays so one work-item tests
// all eight with float8 operations. child[i] > 0: inner node index; child[i] < 0: leaf,
// the TriangleBlock8 with index ~child[i]; child[i] == 0: empty slot (the root, index 0,
// is never a child).
typedef struct {
  float lo_x[8], hi_x[8];
  float lo_y[8], hi_y[8];
  float lo_z[8], hi_z[8];
  int child[8];
} Bvh8Node;

// A leaf's triangles (up to eight) as structure of arrays, so one work-item tests them
// all with float8 operations: v[vertex][axis][lane]. id[lane] is the triangle's index in
// BVH order (-1 for an unused lane, whose vertices are all zero).
typedef struct {
  float v[3][3][8];
  int id[8];
} TriangleBlock8;

// Camera for the generate kernel; see host/scene/camera.h for the conventions.
typedef struct {
  float origin[4];
  float forward[4];
  float right[4];
  float up[4];  // already scaled: right by tan(fov/2)*aspect, up by tan(fov/2)
  int width, height;
  int pad0, pad1;
} CameraParams;

// A material as the kernels see it (host/render/device_scene.cpp maps MTL onto it). Only the
// fields a stage uses are read: diffuse and emission today, the rest for later lobes.
typedef struct {
  float kd[4];  // diffuse albedo rgb
  float ke[4];  // emitted radiance rgb (front side only)
  float ks[4];  // specular rgb, w: Ns
  float tf[4];  // transmission rgb (glass illum models only), w: Ni
  int illum, texture, pad0, pad1;
} GpuMaterial;
// GpuMaterial's fields as offsets in 32-bit words, for gathers of one field across lanes
// (host/device/kernel_layouts.cpp checks them against the struct).
#define FH_MATERIAL_KD 0
#define FH_MATERIAL_KE 4
#define FH_MATERIAL_KS 8
#define FH_MATERIAL_NS 11
#define FH_MATERIAL_TF 12
#define FH_MATERIAL_NI 15
#define FH_MATERIAL_ILLUM 16
#define FH_MATERIAL_TEXTURE 17
#define FH_MATERIAL_WORDS 20

// What every path-tracing stage needs to know about the render.
typedef struct {
  CameraParams camera;
  float env[4];           // constant environment radiance for escaped rays (--env)
  uint seed;
  uint pixel_count;       // width * height
  uint max_depth;         // bounces
  uint rr_depth;          // Russian roulette from this depth on
  uint light_count;
  uint filter_table_size; // entries of the pixel filter's inverse CDF
  float filter_radius;
  uint replicates;        // 1, or 2: even and odd passes are independently scrambled sequences
  // The environment map (FH_ENV_MAP, kernels/environment.h): its size, the u it is turned
  // by, and the probability that light sampling picks it rather than a triangle (0: never).
  uint env_width, env_height;
  float env_u_shift, env_pick;
} RenderParams;

// The wavefront's queue lengths and books, one struct in one device buffer. The device
// keeps its own books (iteration.cl), so the host can queue many iterations without
// waiting for any: it reads this back only now and then. 64-bit totals are (low, high)
// pairs, as OpenCL 1.2 has no 64-bit atomics to rely on.
#define FH_MAX_PASS_SLOTS 64  // passes in flight at most: local pass p is in pass slot p % this
// A megakernel launch starts up to this many samples per path slot: each slot takes its
// next sample where its path ends. More per launch means fewer launches, fewer means
// passes come back and a stop is seen sooner.
#define FH_MEGAKERNEL_SAMPLES_PER_SLOT 4
// A path's pass_entry: its sample's entry in the pass buffers and its pass's slot, in one uint.
#define FH_PASS_ENTRY(entry, slot) ((entry) * FH_MAX_PASS_SLOTS + (slot))
#define FH_PASS_ENTRY_INDEX(pass_entry) ((pass_entry) / FH_MAX_PASS_SLOTS)
#define FH_PASS_ENTRY_SLOT(pass_entry) ((pass_entry) % FH_MAX_PASS_SLOTS)

// Texel formats (texture_info[i].w, kernels/surface.h): linear float RGBA, four 32-bit words
// per texel; or an 8-bit sRGB image, one word per texel, decoded through a table.
#define FH_TEXELS_LINEAR_FLOAT 0u
#define FH_TEXELS_SRGB8 1u

// The shape of a run of passes: each covers `pixels` pixels, those listed from `list` on in
// the pixel list (an adaptive round's, render/adaptive.h), or with list FH_EVERY_PIXEL every
// pixel in order at sequence offset 0, read from no list; its first pass is local pass
// `first_pass` and starts at local sample `first_sample` (local sample numbers are 32 bits
// and wrap: host/render/wavefront.h).
#define FH_EVERY_PIXEL 0xFFFFFFFFu
typedef struct {
  uint pixels;
  uint first_sample;
  uint first_pass;
  uint list;
} PassShape;

typedef struct {
  uint ray_length[2];    // the two ray queues; the iteration's parity says which is current
  uint shadow_length;    // light-sample requests this iteration
  uint finished_length;  // paths finished this iteration
  uint free_length;      // free path slots: the free list's length
  uint nonfinite;        // samples whose radiance was NaN or infinite (dropped)
  uint next_sample;      // samples started so far on this device (local numbering, mod 2^32)
  uint sample_limit;     // local samples that may start: the passes granted so far (mod 2^32)
  uint new_count;        // this iteration's new samples,
  uint new_first;        // ... the first one's local index,
  uint new_free_top;     // ... the free list's length before they took their slots,
  uint new_queue_base;   // ... and where they go in the ray queue
  uint bounce_rays[2];   // rays traced after a bounce
  uint shadow_rays[2];   // light-sample requests (shadow rays at most)
  uint queued_rays[2];   // rays in the current queue, summed over iterations (occupancy)
  uint iterations;
  // The passes in flight are of two shapes at most: shapes[1] from its first sample on,
  // shapes[0] before it (the host sets a new shape once every sample of shapes[0] has
  // started). A pass's samples write the entries of the pass buffers from its first one
  // (the pass table's, kernels/generate.cl) on, around the ring of pass_entries, and a
  // pass's entries follow its predecessor's whatever their shapes.
  PassShape shapes[2];
  uint pass_entries;
  uint pass_done[FH_MAX_PASS_SLOTS];  // per pass slot: paths finished in the pass it holds
} WavefrontCounters;

// Ray buffers hold float4 pairs: origin.xyz + tmin, direction.xyz + tmax.
// Hit buffers hold float4: t, barycentric b1, b2, and the triangle index in BVH order as
// bits (-1: miss); per-triangle device data is stored in that order.
// Ordered triangles hold three float4 per triangle: v0 (w: original id bits), v1, v2.

#ifndef __OPENCL_VERSION__
}  // namespace gpu
}  // namespace fh
#endif

#endif
