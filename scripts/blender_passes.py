"""Run inside Blender's Python (bpy 5): open a rest-embree EXR in the compositor as an artist
would (an Image node) and write each pass Blender finds to OUTDIR/<pass>.exr through the
compositor's output, 32-bit float, untouched by the view transform. scripts/blender-test.sh
then compares each against the rendered file's channels.

    python3 blender_passes.py EXR OUTDIR WIDTH HEIGHT PASS...

Exits 1 naming every documented PASS Blender does not show as its own pass."""

import sys

import bpy

path, outdir, width, height, *wanted = sys.argv[1:]
scene = bpy.context.scene
scene.render.resolution_x, scene.render.resolution_y = int(width), int(height)
scene.render.resolution_percentage = 100
scene.render.use_compositing = True
scene.render.image_settings.file_format = "OPEN_EXR"
scene.render.image_settings.color_depth = "32"
scene.view_settings.view_transform = "Standard"

tree = bpy.data.node_groups.new("passes", "CompositorNodeTree")
tree.interface.new_socket("Image", in_out="OUTPUT", socket_type="NodeSocketColor")
scene.compositing_node_group = tree
image = tree.nodes.new("CompositorNodeImage")
image.image = bpy.data.images.load(path)
out = tree.nodes.new("NodeGroupOutput")

shown = {o.name: o for o in image.outputs if o.enabled}
print("blender-test: Blender", bpy.app.version_string, "shows the passes", sorted(shown))
missing = [p for p in wanted if p not in shown]
if missing:
    print("blender-test: FAILED: Blender shows no pass named", ", ".join(missing))
    sys.exit(1)
for name in wanted:
    for link in list(tree.links):
        tree.links.remove(link)
    tree.links.new(shown[name], out.inputs[0])
    bpy.ops.render.render()
    bpy.data.images["Render Result"].save_render(f"{outdir}/{name}.exr")
