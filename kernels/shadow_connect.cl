// The shadow connect stage's kernel: one launch over its queue (functions: shadow_connect_stage.h).
#include "shadow_connect_stage.h"

__kernel void shadow_connect(RenderParams params,
                             __global const WavefrontCounters* counters FH_SCENE_PARAMS FH_PATH_PARAMS
                                 FH_SHADOW_PARAMS) {
  const SceneView scene = FH_SCENE_VIEW;
  const luint position = lane_positions(get_global_id(0) * FH_LANES);
  const lmask active = position < counters->shadow_length;
  if (!lanes_any(active)) return;
  const ShadowRequest r = load_shadow_request(select((luint)(0), position, active) FH_SHADOW_ARGS);  // idle lanes read request 0
  const PixelSampler sampler = path_sampler(r.path FH_PATH_ARGS);
  connect_light(params, &r, &sampler, active, &scene FH_PATH_ARGS);
}
