"""A scene modelled and animated in Blender 5 (bpy), exported as glTF binary: what a user's tool
writes, for rest-embree's glTF reader to place (docs/scene-format.md, "glTF files").

    python3 scripts/blender_gltf.py OUT.glb [test|demo]

`test` (the default) builds the scene `scripts/blender-test.sh` renders against its hand-written
twin `tests/data/blender_twin.toml`: two boxes sharing one mesh (a linked duplicate), a
metallic-roughness material, an emissive box, a point light, a camera, and a box keyed to move
at constant velocity. `demo` builds `scenes/fleet.glb`: three ships of one mesh, keyed to pass
the camera at 0.9c (with time_scale = 10 in scenes/fleet.toml), under a point light.

Blender is Z-up; its exporter writes glTF's Y-up (x, z, -y), which rest-embree takes as it is.
"""

import sys

import bpy


def clear():
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.fps = 24
    return scene


def material(name, color, metallic=0.0, roughness=0.5, emission=None, strength=1.0):
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    bsdf = m.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (*color, 1.0)
    bsdf.inputs["Metallic"].default_value = metallic
    bsdf.inputs["Roughness"].default_value = roughness
    if emission is not None:
        bsdf.inputs["Emission Color"].default_value = (*emission, 1.0)
        bsdf.inputs["Emission Strength"].default_value = strength
    return m


def cube(name, location, mat, mesh=None):
    """A unit cube (half-extent 0.5) at `location`; with `mesh`, a linked duplicate of it."""
    if mesh is None:
        bpy.ops.mesh.primitive_cube_add(size=1.0, location=location)
        obj = bpy.context.active_object
        obj.data.materials.append(mat)
    else:
        obj = bpy.data.objects.new(name, mesh)
        obj.location = location
        bpy.context.scene.collection.objects.link(obj)
    obj.name = name
    return obj


def light(location, watts):
    data = bpy.data.lights.new("lamp", type="POINT")
    data.energy = watts
    data.shadow_soft_size = 0.0
    obj = bpy.data.objects.new("lamp", data)
    obj.location = location
    bpy.context.scene.collection.objects.link(obj)


def camera(location, rotation_deg, fov_deg):
    import math

    data = bpy.data.cameras.new("eye")
    data.sensor_fit = "VERTICAL"
    data.angle_y = math.radians(fov_deg)
    obj = bpy.data.objects.new("eye", data)
    obj.location = location
    obj.rotation_euler = tuple(math.radians(a) for a in rotation_deg)
    bpy.context.scene.collection.objects.link(obj)
    bpy.context.scene.camera = obj


def keyed(obj, frames_and_places):
    for frame, place in frames_and_places:
        obj.location = place
        obj.keyframe_insert(data_path="location", frame=frame)
    for fc in obj.animation_data.action.fcurves if hasattr(obj.animation_data.action, "fcurves") else []:
        for k in fc.keyframe_points:
            k.interpolation = "LINEAR"


def linear_keys(obj):
    """Blender 5's layered actions keep their curves in channelbags; every key LINEAR."""
    action = obj.animation_data.action
    curves = []
    if hasattr(action, "fcurves"):
        curves = list(action.fcurves)
    for layer in getattr(action, "layers", []):
        for strip in layer.strips:
            for bag in getattr(strip, "channelbags", []):
                curves.extend(bag.fcurves)
    for fc in curves:
        for k in fc.keyframe_points:
            k.interpolation = "LINEAR"


def test_scene():
    scene = clear()
    white = material("white", (0.8, 0.8, 0.8))
    paint = material("paint", (0.8, 0.3, 0.2), metallic=0.0, roughness=0.5)
    glow = material("glow", (0.0, 0.0, 0.0), emission=(1.0, 0.6, 0.2), strength=2.0)
    # Blender's (x, y, z) is glTF's (x, z, -y): the camera at the origin looks along Blender's
    # +y, glTF's -z, at boxes 10 away.
    a = cube("left", (-1.5, 10.0, 0.0), paint)
    cube("right", (1.5, 10.0, 0.0), paint, mesh=a.data)
    cube("lamp_box", (0.0, 12.0, 2.0), glow)
    mover = cube("mover", (0.0, 10.0, -1.5), white)
    # From (0, 10, -1.5) at frame 1 to (2, 10, -1.5) at frame 49: 2 units in 2 s.
    keyed(mover, [(1, (0.0, 10.0, -1.5)), (49, (2.0, 10.0, -1.5))])
    linear_keys(mover)
    light((0.0, 0.0, 5.0), 1000.0)
    camera((0.0, 0.0, 0.0), (90.0, 0.0, 0.0), 40.0)
    scene.frame_start, scene.frame_end = 1, 49
    return scene


def demo_scene():
    scene = clear()
    hull = material("hull", (0.75, 0.75, 0.8), metallic=0.3, roughness=0.4)
    engine = material("engine", (0.0, 0.0, 0.0), emission=(0.3, 0.6, 1.0), strength=4.0)
    # A ship: a long box with a glowing engine block at its stern.
    bpy.ops.mesh.primitive_cube_add(size=1.0, location=(0, 0, 0))
    ship = bpy.context.active_object
    ship.scale = (3.0, 0.8, 0.8)
    bpy.ops.object.transform_apply(scale=True)
    ship.data.materials.append(hull)
    bpy.ops.mesh.primitive_cube_add(size=1.0, location=(-1.7, 0, 0))
    glow = bpy.context.active_object
    glow.scale = (0.4, 0.6, 0.6)
    bpy.ops.object.transform_apply(scale=True)
    glow.data.materials.append(engine)
    ship.select_set(True)
    glow.select_set(True)
    bpy.context.view_layer.objects.active = ship
    bpy.ops.object.join()
    ship.name = "ship"
    fleet = [ship]
    for i, name in enumerate(["ship2", "ship3"]):
        twin = bpy.data.objects.new(name, ship.data)
        scene.collection.objects.link(twin)
        fleet.append(twin)
    # Three ships in echelon, each keyed along +x: 18 units in 2 s (0.9c at time_scale 10).
    for i, obj in enumerate(fleet):
        y, z = 8.0 + 2.5 * i, 1.2 * (i - 1)
        keyed(obj, [(1, (-9.0 - 2.0 * i, y, z)), (49, (9.0 - 2.0 * i, y, z))])
        linear_keys(obj)
    light((0.0, 4.0, 5.0), 3000.0)
    camera((0.0, 0.0, 0.5), (90.0, 0.0, 0.0), 50.0)
    scene.frame_start, scene.frame_end = 1, 49
    return scene


def export(path):
    bpy.ops.export_scene.gltf(
        filepath=path,
        export_format="GLB",
        export_cameras=True,
        export_lights=True,
        export_animations=True,
        export_yup=True,
        export_apply=False,
    )


if __name__ == "__main__":
    out = sys.argv[1]
    kind = sys.argv[2] if len(sys.argv) > 2 else "test"
    {"test": test_scene, "demo": demo_scene}[kind]()
    export(out)
    print(f"blender_gltf: wrote {out} ({kind})")
