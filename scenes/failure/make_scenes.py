#!/usr/bin/python3
"""Writes the "where methods fail" scenes of this folder (OBJ + MTL + camera sidecar).

Each is built to defeat one sampling strategy; tests/test_path_tracer.cpp renders them in
CI and bench/converge_table.sh charts them. Run from anywhere: the files land beside this
script. Faces are counter-clockwise seen from their front; emitters shine from the front.

- caustic: a glass sphere (index 1.5, flat-faceted icosphere) focuses a small light onto a
  diffuse floor. Light reaches the caustic only through two refractions, which no light
  sample can connect: every method finds it by BSDF sampling alone.
- hidden-light: two rooms joined by a gap above a partition; the light sits low in the far
  room, so what the camera sees is lit almost only indirectly (light sampling from it is
  mostly blocked).
- tiny-light: a 0.04 x 0.04 light of radiance 156.25 over a diffuse plane (the scene of the
  TinyBrightLight test, whose camera also sees the light): BRDF sampling alone almost never
  finds it. The camera here (40 degrees) leaves the light out of view, so the error charts
  measure light transport, not how well the sub-pixel positions cover a 2-pixel light.
"""
import json
import math
import os

HERE = os.path.dirname(os.path.abspath(__file__))


class Obj:
    def __init__(self):
        self.vertices, self.faces = [], []  # faces: (material, [vertex indices])

    def vertex(self, p):
        self.vertices.append(p)
        return len(self.vertices)

    def quad(self, material, a, b, c, d):
        self.faces.append((material, [self.vertex(p) for p in (a, b, c, d)]))

    def triangle(self, material, a, b, c):
        self.faces.append((material, [self.vertex(p) for p in (a, b, c)]))

    def write(self, name, materials, camera, comment):
        base = os.path.join(HERE, name)
        with open(base + ".mtl", "w") as f:
            f.write(f"# {comment}\n")
            for m, fields in materials.items():
                f.write(f"\nnewmtl {m}\n" + "".join(f"{k} {v}\n" for k, v in fields.items()))
        with open(base + ".obj", "w") as f:
            f.write(f"# {comment}\n# written by make_scenes.py\nmtllib {name}.mtl\n")
            for p in self.vertices:
                f.write("v %.7g %.7g %.7g\n" % tuple(p))
            current = None
            for material, face in self.faces:
                if material != current:
                    f.write(f"usemtl {material}\n")
                    current = material
                f.write("f " + " ".join(str(i) for i in face) + "\n")
        with open(base + ".camera.json", "w") as f:
            json.dump(camera, f)
            f.write("\n")


def icosphere(center, radius, subdivisions):
    """Triangles of a subdivided icosahedron, counter-clockwise seen from outside."""
    t = (1 + math.sqrt(5)) / 2
    verts = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t), (0, -1, -t), (0, 1, -t),
             (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    faces = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4), (11, 10, 2),
             (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9), (4, 9, 5), (2, 4, 11),
             (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    unit = lambda p: tuple(c / math.sqrt(sum(x * x for x in p)) for c in p)
    tris = [tuple(unit(verts[i]) for i in f) for f in faces]
    for _ in range(subdivisions):
        finer = []
        for a, b, c in tris:
            ab, bc, ca = (unit(tuple((x + y) / 2 for x, y in zip(p, q))) for p, q in ((a, b), (b, c), (c, a)))
            finer += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        tris = finer
    place = lambda p: tuple(center[k] + radius * p[k] for k in range(3))
    return [tuple(place(p) for p in tri) for tri in tris]


def caustic():
    # A ball lens of index n = 1.5 and radius R = 0.5 has its focal length n R / (2 (n - 1)) =
    # 0.75 from its centre (paraxial); the light 2.2 above the centre is imaged 1 / (1/0.75 -
    # 1/2.2) = 1.14 below it: the centre sits 1.14 above the floor, so the focus is on it.
    o = Obj()
    o.quad("floor", (-2, 0, -2), (-2, 0, 2), (2, 0, 2), (2, 0, -2))
    s = 0.15
    h = 3.34
    o.quad("light", (-s, h, -s), (s, h, -s), (s, h, s), (-s, h, s))  # faces down
    for tri in icosphere((0, 1.14, 0), 0.5, 3):
        o.triangle("glass", *tri)
    o.write("caustic", {
        "floor": {"Kd": "0.7 0.7 0.7", "illum": 1},
        "light": {"Kd": "0 0 0", "Ke": "40 40 40", "illum": 1},
        "glass": {"Kd": "0 0 0", "Ks": "1 1 1", "Tf": "1 1 1", "Ni": 1.5, "illum": 7},
    }, {"eye": [0, 2.2, 3.2], "target": [0, 0.6, 0], "up": [0, 1, 0], "fov_y_deg": 42},
        "Caustic: a glass ball lens focuses a small light onto a diffuse floor (fredholm failure suite)")


def hidden_light():
    o = Obj()
    x0, x1, y1, z0, z1 = -2.0, 2.0, 2.0, -1.0, 1.0
    # The room's six faces, fronts inward.
    o.quad("wall", (x0, 0, z0), (x0, 0, z1), (x1, 0, z1), (x1, 0, z0))      # floor, up
    o.quad("wall", (x0, y1, z0), (x1, y1, z0), (x1, y1, z1), (x0, y1, z1))  # ceiling, down
    o.quad("wall", (x0, 0, z0), (x0, y1, z0), (x0, y1, z1), (x0, 0, z1))    # x = -2, toward +x
    o.quad("wall", (x1, 0, z0), (x1, 0, z1), (x1, y1, z1), (x1, y1, z0))    # x = +2, toward -x
    o.quad("wall", (x0, 0, z0), (x1, 0, z0), (x1, y1, z0), (x0, y1, z0))    # z = -1, toward +z
    o.quad("wall", (x0, 0, z1), (x0, y1, z1), (x1, y1, z1), (x1, 0, z1))    # z = +1, toward -z
    # The partition x = 0 up to 1.5 (two-sided diffuse: one quad serves both rooms).
    o.quad("wall", (0, 0, z0), (0, 0, z1), (0, 1.5, z1), (0, 1.5, z0))
    # The light: low on the far wall of the right room, facing the partition (-x).
    s = 0.15
    o.quad("light", (1.99, 0.1, -s), (1.99, 0.1, s), (1.99, 0.4, s), (1.99, 0.4, -s))
    o.write("hidden-light", {
        "wall": {"Kd": "0.75 0.75 0.75", "illum": 1},
        "light": {"Kd": "0 0 0", "Ke": "50 50 50", "illum": 1},
    }, {"eye": [-1.9, 0.9, 0.95], "target": [0.0, 0.9, -0.5], "up": [0, 1, 0], "fov_y_deg": 65},
        "Hidden light: the camera's room is lit over a partition (fredholm failure suite)")


def tiny_light():
    o = Obj()
    o.quad("plane", (-5, 0, -5), (-5, 0, 5), (5, 0, 5), (5, 0, -5))
    s, h = 0.02, 1.0
    o.quad("light", (-s, h, -s), (s, h, -s), (s, h, s), (-s, h, s))  # faces down
    o.write("tiny-light", {
        "plane": {"Kd": "0.5 0.5 0.5", "illum": 1},
        "light": {"Kd": "0 0 0", "Ke": "156.25 156.25 156.25", "illum": 1},
    }, {"eye": [0, 0.5, 2.5], "target": [0, 0, 0], "up": [0, 1, 0], "fov_y_deg": 40},
        "Tiny light: 0.04 x 0.04 at radiance 156.25 over a plane (fredholm failure suite)")


if __name__ == "__main__":
    caustic()
    hidden_light()
    tiny_light()
    print("wrote caustic, hidden-light and tiny-light in", HERE)
