#!/usr/bin/python3
"""Mitsuba 3's ray casting alone, on the rays a diffuse path tracer casts: what a sample of its
path tracer spends in rays, for the split of a sample's time (bench/RESULTS.md).

  /opt/mi-venv/bin/python bench/peers/mitsuba_rays.py [--obj scenes/cornell-box/CornellBox-Original.obj]
      [--size 512] [--spp 16] [--bounces 4] [--variant llvm_ad_rgb] [--repeats 3]

Loads the OBJ as one mesh (materials do not change what a ray hits) and casts, in Mitsuba's
wavefront style (one array of rays per bounce): camera rays through the pixels (the project's
default camera), then per bounce the closest hits of cosine-distributed rays from the last
hits, and one shadow ray per hit toward a uniform point on the emitters (the faces whose MTL
gives Ke). Times only scene.ray_intersect and scene.ray_test (dr.eval, after a warm-up of
each for the JIT), and prints one JSON line: ns per closest-hit ray and per shadow ray.
"""
import argparse, json, math, os, time

import numpy as np


def triangles(obj_path):
    """Every face's triangles (fan-triangulated, as tinyobjloader does), and those of faces whose
    material has a positive Ke, each as (n, 3, 3)."""
    current, emissive, verts, tris, lights = None, set(), [], [], []
    folder = os.path.dirname(obj_path)
    with open(obj_path) as f:
        lines = [l.split("#", 1)[0].split() for l in f]
    for p in lines:
        if p and p[0] == "mtllib":
            with open(os.path.join(folder, p[1])) as m:
                for q in (l.split("#", 1)[0].split() for l in m):
                    if q and q[0] == "newmtl":
                        current = q[1]
                    elif q and q[0] == "Ke" and any(float(x) > 0 for x in q[1:4]):
                        emissive.add(current)
    for p in lines:
        if not p:
            continue
        if p[0] == "v":
            verts.append([float(x) for x in p[1:4]])
        elif p[0] == "usemtl":
            current = p[1]
        elif p[0] == "f":
            idx = [int(t.split("/")[0]) for t in p[1:]]
            idx = [i - 1 if i > 0 else len(verts) + i for i in idx]
            for k in range(1, len(idx) - 1):
                tri = [verts[idx[0]], verts[idx[k]], verts[idx[k + 1]]]
                tris.append(tri)
                if current in emissive:
                    lights.append(tri)
    return np.array(tris, dtype=np.float32), np.array(lights, dtype=np.float32)


def main():
    ap = argparse.ArgumentParser()
    root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    ap.add_argument("--obj", default=os.path.join(root, "scenes/cornell-box/CornellBox-Original.obj"))
    ap.add_argument("--size", type=int, default=512)
    ap.add_argument("--spp", type=int, default=16)
    ap.add_argument("--bounces", type=int, default=4, help="closest-hit rays after the camera's")
    ap.add_argument("--variant", default="llvm_ad_rgb")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--libllvm", default="/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1")
    a = ap.parse_args()
    if "DRJIT_LIBLLVM_PATH" not in os.environ and os.path.exists(a.libllvm):
        os.environ["DRJIT_LIBLLVM_PATH"] = a.libllvm
    import drjit as dr
    import mitsuba as mi
    mi.set_variant(a.variant)
    # The mesh built here: Mitsuba's OBJ reader takes no negative (relative) indices.
    tris, lights = triangles(a.obj)
    mesh = mi.Mesh("scene", len(tris) * 3, len(tris))
    params = mi.traverse(mesh)
    params["vertex_positions"] = mi.Float(tris.reshape(-1))
    params["faces"] = mi.UInt32(np.arange(len(tris) * 3, dtype=np.uint32))
    params.update()
    scene = mi.load_dict({"type": "scene", "mesh": mesh})
    assert len(lights), "no emitters in " + a.obj

    n = a.size * a.size * a.spp
    rng = np.random.default_rng(1)
    # The camera: eye (0, 1, 3.5), looking at (0, 1, 0), 40 degrees vertical field of view.
    px = (np.arange(n) % (a.size * a.size)).astype(np.float64)
    x = (px % a.size + rng.random(n)) / a.size * 2 - 1
    y = 1 - (px // a.size + rng.random(n)) / a.size * 2
    t = math.tan(math.radians(40) / 2)
    d = np.stack([x * t, y * t, -np.ones(n)], 1)
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    f32 = lambda v: mi.Vector3f(*(mi.Float(v[:, i].astype(np.float32)) for i in range(3)))
    camera = mi.Ray3f(mi.Point3f(0.0, 1.0, 3.5), f32(d))

    def timed(fn):
        fn()  # the JIT's compile
        best = float("inf")
        for _ in range(a.repeats):
            start = time.perf_counter()
            fn()
            best = min(best, time.perf_counter() - start)
        return best

    closest_s, closest_rays, shadow_s, shadow_rays = 0.0, 0, 0.0, 0
    ray = camera
    sampler_rng = np.random.default_rng(2)
    for bounce in range(a.bounces + 1):
        def closest():
            si = scene.ray_intersect(ray)
            dr.eval(si.t, si.p, si.n)
            dr.sync_thread()
            return si
        closest_s += timed(closest)
        si = closest()
        closest_rays += dr.width(ray.d)
        valid = np.array(si.is_valid())
        if not valid.any():
            break
        # One shadow ray per hit toward a uniform point on a uniformly chosen emitter triangle.
        m = dr.width(si.t)
        tri = lights[sampler_rng.integers(0, len(lights), m)]
        u, v = sampler_rng.random(m), sampler_rng.random(m)
        su = np.sqrt(u)
        target = (1 - su)[:, None] * tri[:, 0] + (su * (1 - v))[:, None] * tri[:, 1] + (su * v)[:, None] * tri[:, 2]
        shadow = si.spawn_ray_to(mi.Point3f(*(mi.Float(target[:, i].astype(np.float32)) for i in range(3))))
        shadow_mask = mi.Bool(valid)

        def test():
            hit = scene.ray_test(shadow, shadow_mask)
            dr.eval(hit)
            dr.sync_thread()
        shadow_s += timed(test)
        shadow_rays += int(valid.sum())
        # The next bounce: cosine-distributed about the normal on the ray's side.
        frame = mi.Frame3f(dr.select(dr.dot(si.n, ray.d) < 0, si.n, -si.n))
        s2 = mi.Point2f(mi.Float(sampler_rng.random(m).astype(np.float32)),
                        mi.Float(sampler_rng.random(m).astype(np.float32)))
        wo = frame.to_world(mi.warp.square_to_cosine_hemisphere(s2))
        ray = si.spawn_ray(wo)
        keep = np.nonzero(valid)[0]
        ray = mi.Ray3f(mi.Point3f(*(mi.Float(np.array(c)[keep]) for c in (ray.o.x, ray.o.y, ray.o.z))),
                       mi.Vector3f(*(mi.Float(np.array(c)[keep]) for c in (ray.d.x, ray.d.y, ray.d.z))))
    print(json.dumps({"renderer": "mitsuba " + mi.__version__ + " " + a.variant, "obj": os.path.basename(a.obj),
                      "closest_rays": closest_rays, "ns_per_closest_ray": 1e9 * closest_s / closest_rays,
                      "shadow_rays": shadow_rays, "ns_per_shadow_ray": 1e9 * shadow_s / max(shadow_rays, 1)}))


if __name__ == "__main__":
    main()
