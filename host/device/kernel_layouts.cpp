// Every struct the host shares with the kernels (kernels/types.h), checked in one place:
// sizes and field offsets as OpenCL C lays them out (scalars and fixed arrays only, each
// at its natural alignment, no padding the host could add on its own). A field added on
// one side without the other fails the build here.
#include <cstddef>

#include "kernels/types.h"

namespace fh::gpu {

#define FH_LAYOUT(type, field, offset) static_assert(offsetof(type, field) == (offset), #type "." #field)

static_assert(sizeof(Bvh8Node) == 224, "Bvh8Node");
FH_LAYOUT(Bvh8Node, lo_x, 0);
FH_LAYOUT(Bvh8Node, hi_x, 32);
FH_LAYOUT(Bvh8Node, lo_y, 64);
FH_LAYOUT(Bvh8Node, hi_y, 96);
FH_LAYOUT(Bvh8Node, lo_z, 128);
FH_LAYOUT(Bvh8Node, hi_z, 160);
FH_LAYOUT(Bvh8Node, child, 192);

static_assert(sizeof(TriangleBlock8) == 320, "TriangleBlock8");
FH_LAYOUT(TriangleBlock8, v, 0);
FH_LAYOUT(TriangleBlock8, id, 288);

static_assert(sizeof(CameraParams) == 80, "CameraParams");
FH_LAYOUT(CameraParams, origin, 0);
FH_LAYOUT(CameraParams, forward, 16);
FH_LAYOUT(CameraParams, right, 32);
FH_LAYOUT(CameraParams, up, 48);
FH_LAYOUT(CameraParams, width, 64);
FH_LAYOUT(CameraParams, height, 68);

// Checked against the word offsets the kernels gather fields by (FH_MATERIAL_*, 4 bytes a word).
static_assert(sizeof(GpuMaterial) == 80 && sizeof(GpuMaterial) == 4 * FH_MATERIAL_WORDS, "GpuMaterial");
FH_LAYOUT(GpuMaterial, kd, 4 * FH_MATERIAL_KD);
FH_LAYOUT(GpuMaterial, ke, 4 * FH_MATERIAL_KE);
FH_LAYOUT(GpuMaterial, ks, 4 * FH_MATERIAL_KS);
FH_LAYOUT(GpuMaterial, ks[3], 4 * FH_MATERIAL_NS);
FH_LAYOUT(GpuMaterial, tf, 4 * FH_MATERIAL_TF);
FH_LAYOUT(GpuMaterial, tf[3], 4 * FH_MATERIAL_NI);
FH_LAYOUT(GpuMaterial, illum, 4 * FH_MATERIAL_ILLUM);
FH_LAYOUT(GpuMaterial, texture, 4 * FH_MATERIAL_TEXTURE);

static_assert(sizeof(RenderParams) == 144, "RenderParams");
FH_LAYOUT(RenderParams, camera, 0);
FH_LAYOUT(RenderParams, env, 80);
FH_LAYOUT(RenderParams, seed, 96);
FH_LAYOUT(RenderParams, pixel_count, 100);
FH_LAYOUT(RenderParams, max_depth, 104);
FH_LAYOUT(RenderParams, rr_depth, 108);
FH_LAYOUT(RenderParams, light_count, 112);
FH_LAYOUT(RenderParams, filter_table_size, 116);
FH_LAYOUT(RenderParams, filter_radius, 120);
FH_LAYOUT(RenderParams, replicates, 124);
FH_LAYOUT(RenderParams, env_width, 128);
FH_LAYOUT(RenderParams, env_height, 132);
FH_LAYOUT(RenderParams, env_u_shift, 136);
FH_LAYOUT(RenderParams, env_pick, 140);

static_assert(sizeof(PassShape) == 16, "PassShape");
FH_LAYOUT(PassShape, pixels, 0);
FH_LAYOUT(PassShape, first_sample, 4);
FH_LAYOUT(PassShape, first_pass, 8);
FH_LAYOUT(PassShape, list, 12);

static_assert(sizeof(WavefrontCounters) == 368, "WavefrontCounters");
FH_LAYOUT(WavefrontCounters, ray_length, 0);
FH_LAYOUT(WavefrontCounters, shadow_length, 8);
FH_LAYOUT(WavefrontCounters, finished_length, 12);
FH_LAYOUT(WavefrontCounters, free_length, 16);
FH_LAYOUT(WavefrontCounters, nonfinite, 20);
FH_LAYOUT(WavefrontCounters, next_sample, 24);
FH_LAYOUT(WavefrontCounters, sample_limit, 28);
FH_LAYOUT(WavefrontCounters, new_count, 32);
FH_LAYOUT(WavefrontCounters, new_first, 36);
FH_LAYOUT(WavefrontCounters, new_free_top, 40);
FH_LAYOUT(WavefrontCounters, new_queue_base, 44);
FH_LAYOUT(WavefrontCounters, bounce_rays, 48);
FH_LAYOUT(WavefrontCounters, shadow_rays, 56);
FH_LAYOUT(WavefrontCounters, queued_rays, 64);
FH_LAYOUT(WavefrontCounters, iterations, 72);
FH_LAYOUT(WavefrontCounters, shapes, 76);
FH_LAYOUT(WavefrontCounters, pass_entries, 108);
FH_LAYOUT(WavefrontCounters, pass_done, 112);

#undef FH_LAYOUT

}  // namespace fh::gpu
