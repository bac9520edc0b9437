"""An independent reference from Blender Cycles for an OBJ+MTL scene as fredholm reads it.

Runs inside Blender (Debian's `blender`, headless, 3.4):

  blender -b --factory-startup --python bench/cycles_reference.py -- \
      SCENE.obj CAMERA.json OUT.exr --width 128 --height 128 --spp 4096 --seed 1 --max-bounces 64 \
      [--threads 2] [--require-exact]

Its last stdout line is one JSON object: seconds_render (wall seconds of the render call:
Cycles' scene sync, BVH build, sampling and the EXR write), seconds_total (since the script
started, Blender's own start-up not included), spp, width,
height, threads, samples_per_second, mean_rgb, nonfinite_pixels, out, exact (every material
translated exactly), materials (name: how it was translated) and notes.

What it sets up, so that Cycles solves the same equation fredholm does:
- the OBJ imported with no axis change (forward +Y, up +Z: Blender's own axes, so OBJ
  coordinates stay as they are; checked against the file's vertex bounds); `vn` normals
  come in as custom split normals on smooth faces, which Cycles shades with;
- every material replaced as below, plus an emission of the MTL's Ke on the front face only
  (Geometry > Backfacing selects the plain surface behind); Cycles' Emission strength 1
  means radiance = colour, which bench/cycles_compare.py checks on the closed-form plane
  under a light;
- faces that repeat an earlier face exactly removed (see remove_duplicate_faces);
- a black world, the camera from the JSON (eye, target, up, vertical field of view);
- box pixel filter 1 pixel wide, no denoising, no clamping, no adaptive sampling, no light
  threshold, no glossy blur, caustics on, the same bounce limit for every kind, Standard
  view transform (an EXR is written linear anyway), a fixed number of threads.

The MTL is read as fredholm reads it (tinyobjloader's defaults: Kd Ks Ke Tf 0, Ns 1, Ni 1,
illum 0; one value is grey; an illum outside 0-9 is 2; Kd, and Ks where illum >= 2, or Tf of
glass, above 1 scaled down to a largest channel of 1). The materials (kernels/bsdf.h):
- Lambert (illum 0 or 1, or Ks 0; not glass): Diffuse BSDF of Kd, roughness 0. Exact.
- glossy (illum 2, 3, 5 or 8 with Ks > 0, not a mirror): fredholm has
  Kd/pi (1 - max_c F(Ks, cos_o)) + GGX(alpha = sqrt(2/(Ns+2))) with F = Schlick(Ks, wo.h)
  and the height-correlated Smith G2. Here: Diffuse BSDF of Kd (1 - max_c F) + Glossy BSDF
  (GGX, roughness sqrt(alpha): Cycles squares it) of colour F, with F = Schlick(Ks, cos_o)
  from Layer Weight's Facing (1 - |cos_o|). The diffuse part is exact; the glossy lobe
  differs in (a) Fresnel taken at the view angle cos_o = wo.n rather than per microfacet
  at wo.h (the same where Ks = 1 or the lobe is narrow), (b) Cycles 3.4's GGX masking-
  shadowing, separable G1(wo) G1(wi) rather than height-correlated 1/(1 + L(wo) + L(wi)):
  a little darker at grazing angles and for rough lobes. (a) outweighs (b): Cycles is
  brighter, more so for rough lobes seen at grazing angles. Multiple scattering off (plain
  GGX, not Multiscatter GGX) in both. The Principled BSDF is further off: Disney diffuse
  not weighted by 1 - F, F0 from `specular`, a dielectric-shaped Fresnel.
- mirror (illum 3, 5 or 8 with Ns >= 1000 and Ks > 0): the same with a sharp Glossy BSDF; the
  mirror's half vector is n, so Schlick at cos_o is fredholm's formula: exact.
- glass (illum 4, 6, 7, 9): Mix Shader by a Fresnel node of IOR Ni (exact dielectric Fresnel,
  1/Ni from the back face, 1 under total internal reflection) between a sharp Refraction BSDF
  of colour Tf and a sharp white Glossy BSDF: reflection untinted as in fredholm (the Glass
  BSDF would tint it by its colour too). Kd and Ks unused, as in fredholm. Difference:
  fredholm scales a path's weight by (eta_i / eta_t)^2 at each refraction, Cycles does not;
  the factors cancel on paths that enter and leave a medium (camera and lights outside
  every closed glass or water volume), not on light starting or ending inside one.
Shading normals: both interpolate `vn`; fredholm drops sampled directions that a shading
normal sends through the geometric surface the wrong way, Cycles handles those cases its
own way, so silhouettes of smooth-shaded glossy, mirror and glass meshes may differ slightly.
Only glossy and glass need the approximate translation (a note on stderr names each such
material). --require-exact refuses, as before, anything but diffuse + emission (Ks 0 and
illum 0-2 in every material): bench/cycles_compare.py needs an exact twin.
"""
import argparse
import json
import math
import os
import re
import sys
import time

T_START = time.perf_counter()

import bmesh
import bpy
from mathutils import Matrix, Vector


def parse_args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    p = argparse.ArgumentParser(prog="cycles_reference.py")
    p.add_argument("obj")
    p.add_argument("camera")
    p.add_argument("output")
    p.add_argument("--width", type=int, default=128)
    p.add_argument("--height", type=int, default=128)
    p.add_argument("--spp", type=int, default=1024)
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--max-bounces", type=int, default=64)
    p.add_argument("--threads", type=int, default=2, help="Cycles' render threads (fixed)")
    p.add_argument("--require-exact", action="store_true",
                   help="refuse any scene but diffuse + emission, the one exact translation")
    args = p.parse_args(argv)
    if args.threads < 1:
        p.error("--threads must be at least 1")
    return args


def note(message):
    print(f"cycles_reference: note: {message}", file=sys.stderr)


def fail(message):
    print(f"cycles_reference: error: {message}", file=sys.stderr)
    sys.exit(1)


GLASS_ILLUM = (4, 6, 7, 9)
MIRROR_ILLUM = (3, 5, 8)
NS_MIRROR = 1000.0  # FH_NS_MIRROR in kernels/bsdf.h


def new_material():
    # tinyobjloader's defaults, which fredholm keeps.
    return {"Kd": (0.0, 0.0, 0.0), "Ks": (0.0, 0.0, 0.0), "Ke": (0.0, 0.0, 0.0), "Tf": (0.0, 0.0, 0.0),
            "Ns": 1.0, "Ni": 1.0, "illum": 0}


def read_mtl(obj_path, require_exact):
    """The materials of the OBJ's mtllib files, as fredholm reads them. With require_exact,
    rejects anything not Lambertian (Ks other than 0, illum above 2), as the exact twin needs."""
    materials = {}
    with open(obj_path) as f:
        libs = [line.split(None, 1)[1].strip() for line in f if line.startswith("mtllib")]
    for lib in libs:
        path = os.path.join(os.path.dirname(obj_path), lib)
        current = None
        with open(path) as f:
            for number, line in enumerate(f, 1):
                words = line.split("#", 1)[0].split()
                if not words:
                    continue
                key = words[0]
                if key == "newmtl":
                    # fredholm uses a material's first definition: a later one is read into nothing.
                    current = new_material()
                    materials.setdefault(words[1], current)
                elif key in ("Kd", "Ks", "Ke", "Tf", "Kt") and current is not None:
                    values = tuple(float(v) for v in words[1:4])
                    # One value is grey, as the MTL specification and fredholm read it.
                    current["Tf" if key == "Kt" else key] = values * 3 if len(values) == 1 else values
                elif key in ("Ns", "Ni") and current is not None:
                    current[key] = float(words[1])
                elif key == "illum" and current is not None:
                    illum = int(float(words[1]))
                    current["illum"] = illum if 0 <= illum <= 9 else 2  # as fredholm's MTL lint reads it
                if require_exact and key == "Ks" and any(float(v) != 0.0 for v in words[1:4]):
                    fail(f"{path}:{number}: Ks is not 0: only diffuse + emission scenes have an exact Cycles twin")
                elif require_exact and key == "illum" and int(words[1]) > 2:
                    fail(f"{path}:{number}: illum {words[1]}: only diffuse + emission scenes have an exact Cycles twin")
                elif key.startswith("map_"):
                    fail(f"{path}:{number}: textures are not translated")
    for m in materials.values():
        # fredholm's MTL lint scales a reflectance or transmittance above 1 down (hue kept).
        for key in (("Tf",) if m["illum"] in GLASS_ILLUM else ("Kd", "Ks") if m["illum"] >= 2 else ("Kd",)):
            largest = max(m[key])
            if largest > 1.0:
                m[key] = tuple(c / largest for c in m[key])
        m["model"] = fredholm_model(m)
    return materials


def fredholm_model(m):
    """The BSDF fredholm builds for a material (material_bsdf in kernels/bsdf.h)."""
    if m["illum"] in GLASS_ILLUM:
        return "glass"
    if m["illum"] >= 2 and max(m["Ks"]) > 0.0:
        return "mirror" if m["illum"] in MIRROR_ILLUM and m["Ns"] >= NS_MIRROR else "glossy"
    return "lambert"


def obj_bounds(obj_path):
    lo, hi = [math.inf] * 3, [-math.inf] * 3
    with open(obj_path) as f:
        for line in f:
            if line.startswith("v "):
                v = [float(x) for x in line.split()[1:4]]
                lo = [min(a, b) for a, b in zip(lo, v)]
                hi = [max(a, b) for a, b in zip(hi, v)]
    return lo, hi


def clear_scene():
    for obj in list(bpy.data.objects):
        bpy.data.objects.remove(obj, do_unlink=True)
    for material in list(bpy.data.materials):
        bpy.data.materials.remove(material)


def import_obj(path):
    bpy.ops.wm.obj_import(filepath=path, forward_axis="Y", up_axis="Z")
    meshes = [o for o in bpy.context.scene.objects if o.type == "MESH"]
    if not meshes:
        fail(f"{path}: Blender imported no mesh")
    lo, hi = [math.inf] * 3, [-math.inf] * 3
    for o in meshes:
        for v in o.data.vertices:
            w = o.matrix_world @ v.co
            lo = [min(a, b) for a, b in zip(lo, w)]
            hi = [max(a, b) for a, b in zip(hi, w)]
    want_lo, want_hi = obj_bounds(path)
    if max(abs(a - b) for a, b in zip(lo + hi, want_lo + want_hi)) > 1e-4 * max(1.0, *map(abs, want_hi)):
        fail(f"{path}: imported bounds {lo} {hi} differ from the file's {want_lo} {want_hi} (axis change?)")
    for o in meshes:
        remove_duplicate_faces(o)
    return meshes


def remove_duplicate_faces(obj):
    """Deletes faces with exactly the same corners as an earlier face.

    Cycles keeps a ray from hitting the triangle it leaves by excluding that primitive, not
    by an offset, so a second copy of the same face shadows the first: the archive's Cornell
    box has two (its "Bottom Face" lines index the front faces again), which Cycles renders
    black. A duplicate adds no surface, so removing it leaves the scene the same."""
    bm = bmesh.new()
    bm.from_mesh(obj.data)
    seen, duplicates = set(), []
    for face in bm.faces:
        key = tuple(sorted(tuple(round(c, 6) for c in v.co) for v in face.verts))
        if key in seen:
            duplicates.append(face)
        seen.add(key)
    if duplicates:
        print(f"cycles_reference: {obj.name}: removed {len(duplicates)} duplicate faces")
        bmesh.ops.delete(bm, geom=duplicates, context="FACES_ONLY")
        bm.to_mesh(obj.data)
    bm.free()


def diffuse_with_front_emission(name, kd, ke):
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    nodes, links = m.node_tree.nodes, m.node_tree.links
    nodes.clear()
    out = nodes.new("ShaderNodeOutputMaterial")
    diffuse = nodes.new("ShaderNodeBsdfDiffuse")
    diffuse.inputs["Color"].default_value = (*kd, 1.0)
    diffuse.inputs["Roughness"].default_value = 0.0
    if max(ke) <= 0.0:
        links.new(diffuse.outputs["BSDF"], out.inputs["Surface"])
        return m
    emission = nodes.new("ShaderNodeEmission")
    emission.inputs["Color"].default_value = (*ke, 1.0)
    emission.inputs["Strength"].default_value = 1.0
    front = nodes.new("ShaderNodeAddShader")
    links.new(diffuse.outputs["BSDF"], front.inputs[0])
    links.new(emission.outputs["Emission"], front.inputs[1])
    geometry = nodes.new("ShaderNodeNewGeometry")
    pick = nodes.new("ShaderNodeMixShader")  # factor 1 (back face) picks the second input
    links.new(geometry.outputs["Backfacing"], pick.inputs["Fac"])
    links.new(front.outputs["Shader"], pick.inputs[1])
    links.new(diffuse.outputs["BSDF"], pick.inputs[2])
    links.new(pick.outputs["Shader"], out.inputs["Surface"])
    if hasattr(m.cycles, "sample_as_light"):
        m.cycles.sample_as_light = True
    return m


def schlick_nodes(nodes, links, ks):
    """Schlick's Fresnel at the view angle, F = Ks + (1 - Ks) (1 - cos_o)^5, and the diffuse
    share 1 - max_c F = (1 - max Ks) (1 - (1 - cos_o)^5) (F grows with Ks in every channel).
    Returns the two sockets."""
    facing = nodes.new("ShaderNodeLayerWeight")  # Facing = 1 - |N.I| at blend 0.5
    facing.inputs["Blend"].default_value = 0.5
    m5 = nodes.new("ShaderNodeMath")
    m5.operation = "POWER"
    links.new(facing.outputs["Facing"], m5.inputs[0])
    m5.inputs[1].default_value = 5.0
    fresnel = nodes.new("ShaderNodeMixRGB")  # (1 - m5) Ks + m5 white
    fresnel.blend_type = "MIX"
    fresnel.use_clamp = False
    links.new(m5.outputs["Value"], fresnel.inputs["Fac"])
    fresnel.inputs["Color1"].default_value = (*ks, 1.0)
    fresnel.inputs["Color2"].default_value = (1.0, 1.0, 1.0, 1.0)
    left = nodes.new("ShaderNodeMath")  # 1 - m5
    left.operation = "SUBTRACT"
    left.inputs[0].default_value = 1.0
    links.new(m5.outputs["Value"], left.inputs[1])
    share = nodes.new("ShaderNodeMath")
    share.operation = "MULTIPLY"
    links.new(left.outputs["Value"], share.inputs[0])
    share.inputs[1].default_value = 1.0 - max(ks)
    return fresnel.outputs["Color"], share.outputs["Value"]


def specular_surface(nodes, links, m):
    """Diffuse Kd (1 - max F) + Glossy of colour F: GGX for glossy, sharp for a mirror."""
    ks = tuple(min(max(c, 0.0), 1.0) for c in m["Ks"])  # fredholm clamps Ks to [0, 1]
    fresnel, share = schlick_nodes(nodes, links, ks)
    diffuse = nodes.new("ShaderNodeBsdfDiffuse")
    diffuse.inputs["Roughness"].default_value = 0.0
    tint = nodes.new("ShaderNodeVectorMath")
    tint.operation = "SCALE"
    tint.inputs[0].default_value = m["Kd"]
    links.new(share, tint.inputs["Scale"])
    links.new(tint.outputs["Vector"], diffuse.inputs["Color"])
    glossy = nodes.new("ShaderNodeBsdfGlossy")
    if m["model"] == "mirror":
        glossy.distribution = "SHARP"
    else:
        glossy.distribution = "GGX"
        # fredholm's alpha (floored at 1e-3 as there); Cycles' alpha is roughness squared.
        alpha = max(math.sqrt(2.0 / (max(m["Ns"], 0.0) + 2.0)), 1e-3)
        glossy.inputs["Roughness"].default_value = math.sqrt(alpha)
    links.new(fresnel, glossy.inputs["Color"])
    both = nodes.new("ShaderNodeAddShader")
    links.new(diffuse.outputs["BSDF"], both.inputs[0])
    links.new(glossy.outputs["BSDF"], both.inputs[1])
    return both.outputs["Shader"]


def glass_surface(nodes, links, m):
    """Fresnel-weighted white sharp reflection and Tf-tinted sharp refraction."""
    ior = m["Ni"]
    fresnel = nodes.new("ShaderNodeFresnel")  # exact dielectric; 1/IOR from the back face
    fresnel.inputs["IOR"].default_value = ior
    refraction = nodes.new("ShaderNodeBsdfRefraction")
    refraction.distribution = "SHARP"
    refraction.inputs["Color"].default_value = (*(min(max(c, 0.0), 1.0) for c in m["Tf"]), 1.0)
    refraction.inputs["IOR"].default_value = ior
    reflection = nodes.new("ShaderNodeBsdfGlossy")
    reflection.distribution = "SHARP"
    reflection.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
    pick = nodes.new("ShaderNodeMixShader")  # factor F picks the reflection
    links.new(fresnel.outputs["Fac"], pick.inputs["Fac"])
    links.new(refraction.outputs["BSDF"], pick.inputs[1])
    links.new(reflection.outputs["BSDF"], pick.inputs[2])
    return pick.outputs["Shader"]


def specular_with_front_emission(name, m):
    """A glossy, mirror or glass material, emitting Ke from the front as the diffuse one does."""
    material = bpy.data.materials.new(name)
    material.use_nodes = True
    nodes, links = material.node_tree.nodes, material.node_tree.links
    nodes.clear()
    out = nodes.new("ShaderNodeOutputMaterial")
    surface = (glass_surface if m["model"] == "glass" else specular_surface)(nodes, links, m)
    if max(m["Ke"]) <= 0.0:
        links.new(surface, out.inputs["Surface"])
        return material
    emission = nodes.new("ShaderNodeEmission")
    emission.inputs["Color"].default_value = (*m["Ke"], 1.0)
    emission.inputs["Strength"].default_value = 1.0
    front = nodes.new("ShaderNodeAddShader")
    links.new(surface, front.inputs[0])
    links.new(emission.outputs["Emission"], front.inputs[1])
    geometry = nodes.new("ShaderNodeNewGeometry")
    pick = nodes.new("ShaderNodeMixShader")  # factor 1 (back face) picks the second input
    links.new(geometry.outputs["Backfacing"], pick.inputs["Fac"])
    links.new(front.outputs["Shader"], pick.inputs[1])
    links.new(surface, pick.inputs[2])
    links.new(pick.outputs["Shader"], out.inputs["Surface"])
    if hasattr(material.cycles, "sample_as_light"):
        material.cycles.sample_as_light = True
    return material


APPROXIMATE = {
    "glossy": "Schlick Fresnel of the GGX lobe taken at the view angle, not per microfacet; Cycles' GGX has "
              "the separable Smith G, fredholm the height-correlated one",
    "glass": "Cycles does not scale radiance by 1/eta^2 across the interface (equal where paths enter and "
             "leave the medium)",
}


def describe(name, m):
    if m["model"] == "lambert":
        return f"Lambert Kd {m['Kd']}"
    if m["model"] == "glass":
        return f"glass Ni {m['Ni']} Tf {m['Tf']}"
    return f"{m['model']} Kd {m['Kd']} Ks {m['Ks']} Ns {m['Ns']}"


def replace_materials(meshes, mtl):
    replacements = {}
    for o in meshes:
        for slot in o.material_slots:
            if slot.material is None:
                fail(f"{o.name}: a face without a material")
            name = re.sub(r"\.\d{3}$", "", slot.material.name)
            if name not in mtl:
                fail(f"material '{name}' is not in the MTL files")
            if name not in replacements:
                m = mtl[name]
                if m["model"] == "lambert":
                    replacements[name] = diffuse_with_front_emission("fh_" + name, m["Kd"], m["Ke"])
                else:
                    replacements[name] = specular_with_front_emission("fh_" + name, m)
                if m["model"] in APPROXIMATE:
                    note(f"material '{name}' ({describe(name, m)}) is translated approximately: "
                         f"{APPROXIMATE[m['model']]}")
            slot.material = replacements[name]
    return replacements


def add_camera(scene, camera_path, width, height):
    with open(camera_path) as f:
        c = json.load(f)
    eye, target = Vector(c["eye"]), Vector(c["target"])
    up = Vector(c.get("up", [0, 1, 0]))
    forward = (target - eye).normalized()
    right = forward.cross(up).normalized()
    cam_up = right.cross(forward)
    # Blender cameras look down their local -Z with +Y up.
    m = Matrix((
        (right.x, cam_up.x, -forward.x, eye.x),
        (right.y, cam_up.y, -forward.y, eye.y),
        (right.z, cam_up.z, -forward.z, eye.z),
        (0, 0, 0, 1)))
    data = bpy.data.cameras.new("fh_camera")
    data.type = "PERSP"
    data.sensor_fit = "VERTICAL"
    data.angle_y = math.radians(c.get("fov_y_deg", 45.0))
    data.clip_start = 1e-4
    data.clip_end = 1e8
    cam = bpy.data.objects.new("fh_camera", data)
    scene.collection.objects.link(cam)
    cam.matrix_world = m
    scene.camera = cam
    scene.render.resolution_x, scene.render.resolution_y = width, height
    scene.render.resolution_percentage = 100
    scene.render.pixel_aspect_x = scene.render.pixel_aspect_y = 1.0


def black_world(scene):
    world = bpy.data.worlds.new("fh_black")
    world.use_nodes = True
    background = world.node_tree.nodes.get("Background")
    background.inputs["Color"].default_value = (0, 0, 0, 1)
    background.inputs["Strength"].default_value = 0.0
    scene.world = world


def configure_cycles(scene, args):
    scene.render.engine = "CYCLES"
    cy = scene.cycles
    cy.device = "CPU"
    cy.samples = args.spp
    cy.seed = args.seed
    cy.use_animated_seed = False
    cy.use_adaptive_sampling = False
    cy.use_denoising = False
    cy.sample_clamp_direct = 0.0
    cy.sample_clamp_indirect = 0.0
    cy.light_sampling_threshold = 0.0
    cy.blur_glossy = 0.0
    cy.caustics_reflective = cy.caustics_refractive = True
    for kind in ("max_bounces", "diffuse_bounces", "glossy_bounces", "transmission_bounces",
                 "transparent_max_bounces"):
        setattr(cy, kind, args.max_bounces)
    cy.volume_bounces = 0
    cy.min_light_bounces = 0
    cy.min_transparent_bounces = 0
    cy.pixel_filter_type = "BOX"
    cy.filter_width = 1.0
    cy.film_exposure = 1.0
    scene.render.threads_mode = "FIXED"
    scene.render.threads = args.threads
    scene.render.film_transparent = False
    scene.render.use_persistent_data = False
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    scene.view_settings.exposure = 0.0
    scene.view_settings.gamma = 1.0
    scene.display_settings.display_device = "sRGB"
    s = scene.render.image_settings
    s.file_format = "OPEN_EXR"
    s.color_mode = "RGB"
    s.color_depth = "32"
    s.exr_codec = "ZIP"


def image_stats(path):
    """Mean RGB and the count of pixels with a non-finite channel, of the EXR written."""
    import numpy as np
    image = bpy.data.images.load(path)
    pixels = np.empty(image.size[0] * image.size[1] * image.channels, dtype=np.float32)
    image.pixels.foreach_get(pixels)
    rgb = pixels.reshape(-1, image.channels)[:, :3].astype(np.float64)
    bpy.data.images.remove(image)
    return [float(v) for v in rgb.mean(0)], int((~np.isfinite(rgb)).any(-1).sum())


def main():
    args = parse_args()
    mtl = read_mtl(args.obj, args.require_exact)
    clear_scene()
    scene = bpy.context.scene
    meshes = import_obj(args.obj)
    replaced = replace_materials(meshes, mtl)
    add_camera(scene, args.camera, args.width, args.height)
    black_world(scene)
    configure_cycles(scene, args)
    scene.render.filepath = args.output
    emitters = [name for name in replaced if max(mtl[name]["Ke"]) > 0]
    print(f"cycles_reference: {len(meshes)} meshes, materials {sorted(replaced)}, emitters {emitters}, "
          f"{args.width}x{args.height}, {args.spp} spp, seed {args.seed}, {args.max_bounces} bounces, "
          f"{args.threads} threads")
    start = time.perf_counter()
    bpy.ops.render.render(write_still=True)
    seconds = time.perf_counter() - start
    print(f"cycles_reference: wrote {args.output}")
    out = os.path.abspath(args.output)
    if not os.path.exists(out):
        fail(f"{out}: Blender wrote no image there (give the name with its .exr)")
    mean_rgb, nonfinite = image_stats(out)
    approximate = sorted(name for name in replaced if mtl[name]["model"] in APPROXIMATE)
    print(json.dumps({
        "renderer": "cycles", "blender": bpy.app.version_string, "seed": args.seed, "spp": args.spp,
        "width": args.width, "height": args.height, "threads": args.threads, "max_bounces": args.max_bounces,
        "samples_per_second": args.width * args.height * args.spp / seconds, "seconds_render": seconds,
        "seconds_total": time.perf_counter() - T_START, "mean_rgb": mean_rgb, "nonfinite_pixels": nonfinite,
        "scene": os.path.abspath(args.obj), "out": out, "exact": not approximate,
        "materials": {name: describe(name, mtl[name]) for name in sorted(replaced)},
        "notes": [f"{name}: {APPROXIMATE[mtl[name]['model']]}" for name in approximate],
    }), flush=True)
    # Leaves now, so that the JSON stays the last stdout line (Blender prints "Blender quit" otherwise).
    sys.exit(0)


main()
