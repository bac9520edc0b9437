"""An independent reference from Blender Cycles for a diffuse OBJ+MTL scene.

Runs inside Blender (Debian's `blender`, headless):

  blender -b --factory-startup --python bench/cycles_reference.py -- \
      SCENE.obj CAMERA.json OUT.exr --width 128 --height 128 --spp 4096 --seed 1 --max-bounces 64

What it sets up, so that Cycles solves the same equation fredholm does:
- the OBJ imported with no axis change (forward +Y, up +Z: Blender's own axes, so OBJ
  coordinates stay as they are; checked against the file's vertex bounds);
- every material replaced by a diffuse BSDF of the MTL's Kd (roughness 0: Lambert) plus an
  emission of the MTL's Ke on the front face only (Geometry > Backfacing selects the plain
  diffuse behind); Cycles' Emission strength 1 means radiance = colour, which
  bench/cycles_compare.sh checks on the closed-form plane under a light;
- faces that repeat an earlier face exactly removed (see remove_duplicate_faces);
- a black world, the camera from the JSON (eye, target, up, vertical field of view);
- box pixel filter 1 pixel wide, no denoising, no clamping, no adaptive sampling, no light
  threshold, no glossy blur, the same bounce limit for every kind, Standard view transform
  (an EXR is written linear anyway).
Only scenes that need nothing more than diffuse + emission are accepted (illum 0-2 with
Ks 0): anything else would not be an exact equivalent.
"""
import argparse
import json
import math
import os
import re
import sys

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
    return p.parse_args(argv)


def fail(message):
    print(f"cycles_reference: error: {message}", file=sys.stderr)
    sys.exit(1)


def read_mtl(obj_path):
    """Kd and Ke of each material of the OBJ's mtllib files; rejects anything not Lambertian."""
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
                    current = words[1]
                    materials[current] = {"Kd": (0.0, 0.0, 0.0), "Ke": (0.0, 0.0, 0.0)}
                elif key in ("Kd", "Ke") and current:
                    values = tuple(float(v) for v in words[1:4])
                    # One value is grey, as the MTL specification and fredholm read it.
                    materials[current][key] = values * 3 if len(values) == 1 else values
                elif key == "Ks" and any(float(v) != 0.0 for v in words[1:4]):
                    fail(f"{path}:{number}: Ks is not 0: only diffuse + emission scenes have an exact Cycles twin")
                elif key == "illum" and int(words[1]) > 2:
                    fail(f"{path}:{number}: illum {words[1]}: only diffuse + emission scenes have an exact Cycles twin")
                elif key.startswith("map_"):
                    fail(f"{path}:{number}: textures are not translated")
    return materials


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
                replacements[name] = diffuse_with_front_emission("fh_" + name, mtl[name]["Kd"], mtl[name]["Ke"])
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


def main():
    args = parse_args()
    mtl = read_mtl(args.obj)
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
          f"{args.width}x{args.height}, {args.spp} spp, seed {args.seed}, {args.max_bounces} bounces")
    bpy.ops.render.render(write_still=True)
    print(f"cycles_reference: wrote {args.output}")


main()
