# Builds a skinlab scene in Blender and renders it with Cycles or EEVEE (docs/pathtraced.md). Run headless:
#   blender -b --factory-startup -noaudio --python cycles_scene.py -- render SCENE.json
#   blender -b --factory-startup -noaudio --python cycles_scene.py -- profile PROFILE.json
# "render": SCENE.json is written by renderer/pathtraced/blender_scene.cpp (geometry in a binary file beside it,
# camera, lights, environment, materials, settings); the script writes a linear multilayer OpenEXR with the
# passes skinlab reads back, and a small JSON record (Blender version, render time). settings.engine chooses the
# engine: "cycles" (sss.method = "pathtraced") or "eevee" (sss.method = "eevee": the same scene rendered with EEVEE's
# screen-space subsurface scattering; its skin mask comes from a shader AOV, as EEVEE has no material index pass).
# "profile": the edge-response scene of the profile fit (renderer/pathtraced/profile_fit.h): a large skin slab
# lit from straight above by a sun whose light a plate, invisible to the camera, cuts off at x = 0.
# The script only uses Blender's own Python modules (no numpy). Every failure exits with status 1 and a message.
import array
import json
import math
import os
import sys
import time
import traceback

import bpy
from mathutils import Matrix, Vector


def fail(message):
    print("skinlab-cycles: error: " + message, file=sys.stderr, flush=True)
    sys.exit(1)


def reset_scene():
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    return scene


def configure_output(scene, settings):
    render = scene.render
    render.resolution_x = int(settings["width"])
    render.resolution_y = int(settings["height"])
    render.resolution_percentage = 100
    render.pixel_aspect_x = 1.0
    render.pixel_aspect_y = 1.0
    render.film_transparent = False
    # Linear output: the view transform does not touch EXR data, but keep it neutral anyway.
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    scene.view_settings.exposure = 0.0
    scene.view_settings.gamma = 1.0
    image = render.image_settings
    image.file_format = "OPEN_EXR_MULTILAYER"
    image.color_depth = "32"
    image.exr_codec = "ZIP"
    render.use_file_extension = False
    render.use_stamp = False


def configure_eevee(scene, settings):
    # EEVEE (Blender 3.x): rasterised with GL (headless: Blender falls back to surfaceless EGL, Mesa's llvmpipe on a
    # machine without GPU). Every effect but subsurface scattering and shadows off: no ambient occlusion, no
    # screen-space reflections or refraction, no bloom, no motion blur, no volumetrics.
    scene.render.engine = "BLENDER_EEVEE"
    eevee = scene.eevee
    own = settings["eevee"]
    eevee.taa_render_samples = int(settings["samples"])
    eevee.sss_samples = int(own["sss_samples"])
    eevee.sss_jitter_threshold = float(own["sss_jitter_threshold"])
    eevee.use_soft_shadows = bool(own["soft_shadows"])
    eevee.shadow_cascade_size = str(int(own["shadow_map_size"]))
    eevee.shadow_cube_size = str(int(own["shadow_map_size"]))
    eevee.use_shadow_high_bitdepth = True
    eevee.use_gtao = False
    eevee.use_ssr = False
    eevee.use_bloom = False
    eevee.use_motion_blur = False
    eevee.use_volumetric_lights = False
    eevee.use_volumetric_shadows = False
    # Lights reach everything they would light (EEVEE otherwise cuts a light off where it falls below 0.01).
    eevee.light_threshold = 1e-6
    scene.render.filter_size = float(settings["filter_width_px"])
    configure_output(scene, settings)


def configure_engine(scene, settings):
    if settings.get("engine", "cycles") == "eevee":
        configure_eevee(scene, settings)
    else:
        configure_cycles(scene, settings)


def configure_cycles(scene, settings):
    scene.render.engine = "CYCLES"
    cycles = scene.cycles
    cycles.device = "CPU"
    cycles.samples = int(settings["samples"])
    cycles.use_adaptive_sampling = False
    cycles.use_denoising = False
    cycles.seed = int(settings["seed"])
    cycles.use_animated_seed = False
    bounces = int(settings["max_bounces"])
    cycles.max_bounces = bounces
    cycles.diffuse_bounces = bounces
    cycles.glossy_bounces = bounces
    cycles.transmission_bounces = bounces
    cycles.volume_bounces = 0
    cycles.transparent_max_bounces = 8
    cycles.sample_clamp_direct = 0.0
    cycles.sample_clamp_indirect = 0.0
    cycles.blur_glossy = 0.0
    cycles.light_sampling_threshold = 0.0
    cycles.caustics_reflective = True
    cycles.caustics_refractive = True
    # Gaussian over filter_width_px pixels: Blender's sync gives Cycles' box filter a width of 1 pixel whatever
    # filter_width says (a box always averages the whole pixel), so only a narrow Gaussian samples the pixel
    # centre as the rasterizer does (docs/pathtraced.md, "Pixel footprint").
    # The profile fit asks for the box: each pixel the mean over its width, what its integral of E sums.
    cycles.pixel_filter_type = "BOX" if settings.get("pixel_filter") == "box" else "GAUSSIAN"
    cycles.filter_width = float(settings["filter_width_px"])
    render = scene.render
    threads = int(settings.get("threads", 0))
    if threads > 0:
        render.threads_mode = "FIXED"
        render.threads = threads
    else:
        render.threads_mode = "AUTO"
    configure_output(scene, settings)


# The shader AOV that carries the skin flag in EEVEE (a value per pixel, averaged over the TAA samples).
SKIN_AOV = "skinlab_skin"


def configure_passes(scene, engine="cycles"):
    layer = scene.view_layers[0]
    layer.use_pass_combined = True
    layer.use_pass_z = True
    if engine == "eevee":
        # EEVEE: Diffuse Light (direct and world light, subsurface scattering included) x Diffuse Colour, Specular
        # Light x Specular Colour; no indirect or index passes.
        layer.use_pass_diffuse_direct = True
        layer.use_pass_diffuse_color = True
        layer.use_pass_glossy_direct = True
        layer.use_pass_glossy_color = True
        aov = layer.aovs.add()
        aov.name = SKIN_AOV
        aov.type = "VALUE"
        return layer
    layer.use_pass_diffuse_direct = True
    layer.use_pass_diffuse_indirect = True
    layer.use_pass_diffuse_color = True
    layer.use_pass_glossy_direct = True
    layer.use_pass_glossy_indirect = True
    layer.use_pass_glossy_color = True
    layer.use_pass_material_index = True
    layer.use_pass_object_index = True
    return layer


def read_floats(handle, count):
    values = array.array("f")
    values.fromfile(handle, count)
    if sys.byteorder != "little":
        values.byteswap()
    return values


def read_uints(handle, count):
    values = array.array("I")
    if values.itemsize != 4:
        values = array.array("L")
    values.fromfile(handle, count)
    if sys.byteorder != "little":
        values.byteswap()
    return values


def build_mesh(path, description, name):
    vertex_count = int(description["vertex_count"])
    index_count = int(description["index_count"])
    with open(path, "rb") as handle:
        handle.seek(int(description["offset"]))
        positions = read_floats(handle, vertex_count * 3)
        normals = read_floats(handle, vertex_count * 3)
        uvs = read_floats(handle, vertex_count * 2)
        colors = read_floats(handle, vertex_count * 3)
        skin = read_floats(handle, vertex_count)
        indices = read_uints(handle, index_count)
    mesh = bpy.data.meshes.new(name)
    mesh.vertices.add(vertex_count)
    mesh.vertices.foreach_set("co", positions)
    triangles = index_count // 3
    mesh.loops.add(index_count)
    mesh.loops.foreach_set("vertex_index", indices)
    mesh.polygons.add(triangles)
    mesh.polygons.foreach_set("loop_start", array.array("i", range(0, index_count, 3)))
    mesh.polygons.foreach_set("loop_total", array.array("i", [3]) * triangles)
    mesh.polygons.foreach_set("use_smooth", array.array("b", [1]) * triangles)
    mesh.update(calc_edges=True)
    # Per-loop UVs from the per-vertex ones (Blender's v = 0 is the image bottom; the file already says so).
    uv_layer = mesh.uv_layers.new(name="UVMap")
    loop_uvs = array.array("f", [0.0]) * (index_count * 2)
    for loop, vertex in enumerate(indices):
        loop_uvs[2 * loop] = uvs[2 * vertex]
        loop_uvs[2 * loop + 1] = uvs[2 * vertex + 1]
    uv_layer.data.foreach_set("uv", loop_uvs)
    color_attribute = mesh.attributes.new("skinlab_color", "FLOAT_COLOR", "POINT")
    rgba = array.array("f", [1.0]) * (vertex_count * 4)
    for v in range(vertex_count):
        rgba[4 * v] = colors[3 * v]
        rgba[4 * v + 1] = colors[3 * v + 1]
        rgba[4 * v + 2] = colors[3 * v + 2]
    color_attribute.data.foreach_set("color", rgba)
    skin_attribute = mesh.attributes.new("skinlab_skin", "FLOAT", "POINT")
    skin_attribute.data.foreach_set("value", skin)
    # The renderer's smooth normals, exactly.
    mesh.use_auto_smooth = True
    mesh.auto_smooth_angle = math.pi
    mesh.normals_split_custom_set_from_vertices([tuple(normals[3 * v:3 * v + 3]) for v in range(vertex_count)])
    return mesh


def load_image(path, colorspace):
    image = bpy.data.images.load(path, check_existing=True)
    image.colorspace_settings.name = colorspace
    return image


def image_node(nodes, links, path, colorspace, uv):
    node = nodes.new("ShaderNodeTexImage")
    node.image = load_image(path, colorspace)
    node.interpolation = "Linear"
    node.extension = "REPEAT"
    links.new(uv.outputs["UV"], node.inputs["Vector"])
    return node


def multiply(nodes, links, a, b, operation="MULTIPLY"):
    node = nodes.new("ShaderNodeMath")
    node.operation = operation
    for slot, value in ((0, a), (1, b)):
        if isinstance(value, (int, float)):
            node.inputs[slot].default_value = float(value)
        else:
            links.new(value, node.inputs[slot])
    return node.outputs[0]


def multiply_color(nodes, links, a, b):
    node = nodes.new("ShaderNodeVectorMath")
    node.operation = "MULTIPLY"
    for slot, value in ((0, a), (1, b)):
        if isinstance(value, (list, tuple)):
            node.inputs[slot].default_value = (float(value[0]), float(value[1]), float(value[2]))
        else:
            links.new(value, node.inputs[slot])
    return node.outputs[0]


def piecewise_linear(nodes, links, value, knots, values):
    # values[0] up to knots[0], values[-1] from knots[-1] on, linear in between: with a = the input clamped to
    # [knots[0], knots[-1]], values[0] + s_0 (a - knots[0]) + sum over the interior knots of
    # (s_i - s_(i-1)) max(a - knots[i], 0), s_i the slope after knot i.
    clamp = nodes.new("ShaderNodeClamp")
    clamp.clamp_type = "MINMAX"
    clamp.inputs["Min"].default_value = float(knots[0])
    clamp.inputs["Max"].default_value = float(knots[-1])
    links.new(value, clamp.inputs["Value"])
    a = clamp.outputs["Result"]
    slopes = [(float(values[i + 1]) - float(values[i])) / (float(knots[i + 1]) - float(knots[i]))
              for i in range(len(knots) - 1)]
    result = multiply(nodes, links, multiply(nodes, links, a, float(knots[0]), "SUBTRACT"), slopes[0])
    result = multiply(nodes, links, result, float(values[0]), "ADD")
    for i in range(1, len(knots) - 1):
        hinge = multiply(nodes, links, multiply(nodes, links, a, float(knots[i]), "SUBTRACT"), 0.0, "MAXIMUM")
        result = multiply(nodes, links, multiply(nodes, links, hinge, slopes[i] - slopes[i - 1]), result, "ADD")
    return result


def per_channel(nodes, links, colour, channel_socket):
    # A colour whose channel c is channel_socket(c, the input's channel c), through Separate / Combine Color.
    separate = nodes.new("ShaderNodeSeparateColor")
    separate.mode = "RGB"
    links.new(colour, separate.inputs["Color"])
    combine = nodes.new("ShaderNodeCombineColor")
    combine.mode = "RGB"
    for channel in range(3):
        links.new(channel_socket(channel, separate.outputs[channel]), combine.inputs[channel])
    return combine.outputs["Color"]


def radius_from_albedo(nodes, links, albedo, table):
    # pathtraced.radius_model = "albedo": each channel's radius follows that channel of the subsurface colour
    # through the table written by skinlab (renderer/sss/pathtraced_params.h, albedoRadiusTable; already scaled).
    return per_channel(nodes, links, albedo, lambda c, a: piecewise_linear(nodes, links, a, table["albedo"],
                                                                           table["radius"][c]))


def walk_colour(nodes, links, albedo, table):
    # The colour given to the random walk: each channel a divided by the walk's excess reflectance k(a) at that
    # colour (renderer/sss/pathtraced_params.h, walkReflectanceTable), so flat skin reflects a itself.
    if not table:
        return albedo
    return per_channel(nodes, links, albedo, lambda c, a: multiply(
        nodes, links, a, piecewise_linear(nodes, links, a, table["albedo"], table["gain"]), "DIVIDE"))


def principled_specular(nodes, links, bsdf, description, textures, uv):
    # The Principled BSDF's specular lobe: F0 = 0.08 x specular (x the specular map), GGX at the given roughness.
    bsdf.inputs["Metallic"].default_value = 0.0
    bsdf.inputs["Specular Tint"].default_value = 0.0
    bsdf.inputs["Sheen"].default_value = 0.0
    bsdf.inputs["Clearcoat"].default_value = 0.0
    bsdf.inputs["Roughness"].default_value = float(description["roughness"])
    specular = float(description["specular"])
    if specular > 0.0 and textures.get("specular"):
        separate = nodes.new("ShaderNodeSeparateColor")
        links.new(image_node(nodes, links, textures["specular"], "Non-Color", uv).outputs["Color"],
                  separate.inputs["Color"])
        links.new(multiply(nodes, links, separate.outputs[0], specular), bsdf.inputs["Specular"])
    else:
        bsdf.inputs["Specular"].default_value = specular


def normal_input(nodes, links, textures, uv):
    # The tangent-space normal map's output socket, or None without a normal map.
    if not textures.get("normal"):
        return None
    normal_map = nodes.new("ShaderNodeNormalMap")
    normal_map.space = "TANGENT"
    normal_map.uv_map = "UVMap"
    normal_map.inputs["Strength"].default_value = float(textures.get("normal_strength", 1.0))
    links.new(image_node(nodes, links, textures["normal"], "Non-Color", uv).outputs["Color"],
              normal_map.inputs["Color"])
    return normal_map.outputs["Normal"]


def lambert_material(material, nodes, links, output, bsdf, albedo, mask, radius, description, textures, uv):
    # diffuse = "lambert": the rasterizer's diffuse model. Non-skin: a Lambertian Diffuse BSDF; skin: the
    # Subsurface Scattering node's random walk, whose entry and exit are Lambertian (no Fresnel factor, no
    # retro-reflection lobe); mixed by the skin mask. The Principled BSDF's diffuse is Burley's, whose
    # retro-reflection term (which Blender adds beside the random walk too) brightens grazing views
    # (docs/pathtraced.md, "The rim at grazing view"). The specular lobe stays the Principled BSDF's (black base
    # colour, no subsurface: its diffuse closure has zero weight), added on top as Blender's Principled adds it.
    diffuse = nodes.new("ShaderNodeBsdfDiffuse")
    diffuse.inputs["Roughness"].default_value = 0.0
    links.new(albedo, diffuse.inputs["Color"])
    shaders = [diffuse]
    surface = diffuse.outputs["BSDF"]
    if description["sss"]:
        walk = nodes.new("ShaderNodeSubsurfaceScattering")
        walk.falloff = "RANDOM_WALK_FIXED_RADIUS"
        links.new(walk_colour(nodes, links, albedo, description.get("walk_gain_table")), walk.inputs["Color"])
        walk.inputs["Scale"].default_value = 1.0
        walk.inputs["Radius"].default_value = tuple(float(r) for r in description["radius"])
        if radius is not None:
            links.new(radius, walk.inputs["Radius"])
        shaders.append(walk)
        mix = nodes.new("ShaderNodeMixShader")
        links.new(mask, mix.inputs["Fac"])
        links.new(diffuse.outputs["BSDF"], mix.inputs[1])
        links.new(walk.outputs["BSSRDF"], mix.inputs[2])
        surface = mix.outputs["Shader"]
    bsdf.inputs["Base Color"].default_value = (0.0, 0.0, 0.0, 1.0)
    bsdf.inputs["Subsurface"].default_value = 0.0
    principled_specular(nodes, links, bsdf, description, textures, uv)
    shaders.append(bsdf)
    normal = normal_input(nodes, links, textures, uv)
    if normal is not None:
        for shader in shaders:
            links.new(normal, shader.inputs["Normal"])
    add = nodes.new("ShaderNodeAddShader")
    links.new(surface, add.inputs[0])
    links.new(bsdf.outputs["BSDF"], add.inputs[1])
    links.new(add.outputs["Shader"], output.inputs["Surface"])
    return material


def build_material(description, textures, engine="cycles"):
    material = bpy.data.materials.new(description["name"])
    material.use_nodes = True
    # The material index pass (first hit, not averaged) marks skin materials: skinlab's mask.Y.
    material.pass_index = 1 if description["skin"] > 0.0 else 0
    nodes = material.node_tree.nodes
    links = material.node_tree.links
    nodes.clear()
    output = nodes.new("ShaderNodeOutputMaterial")
    bsdf = nodes.new("ShaderNodeBsdfPrincipled")
    uv = nodes.new("ShaderNodeUVMap")
    uv.uv_map = "UVMap"
    vertex_color = nodes.new("ShaderNodeAttribute")
    vertex_color.attribute_type = "GEOMETRY"
    vertex_color.attribute_name = "skinlab_color"
    vertex_skin = nodes.new("ShaderNodeAttribute")
    vertex_skin.attribute_type = "GEOMETRY"
    vertex_skin.attribute_name = "skinlab_skin"

    # albedo = material albedo x vertex colour x albedo map (sRGB decoded)
    albedo = multiply_color(nodes, links, vertex_color.outputs["Color"], description["albedo"])
    if textures.get("albedo"):
        albedo = multiply_color(nodes, links, albedo,
                                image_node(nodes, links, textures["albedo"], textures.get("albedo_colorspace", "sRGB"),
                                           uv).outputs["Color"])
    # skin mask = material flag x vertex skin x mask map (red), clamped to [0, 1]
    mask = multiply(nodes, links, vertex_skin.outputs["Fac"], float(description["skin"]))
    if textures.get("skin_mask"):
        separate = nodes.new("ShaderNodeSeparateColor")
        links.new(image_node(nodes, links, textures["skin_mask"], "Non-Color", uv).outputs["Color"],
                  separate.inputs["Color"])
        mask = multiply(nodes, links, mask, separate.outputs[0])
    clamp = nodes.new("ShaderNodeClamp")
    links.new(mask, clamp.inputs["Value"])
    mask = clamp.outputs["Result"]

    radius = None
    if description.get("radius_table") and engine != "eevee":
        radius = radius_from_albedo(nodes, links, albedo, description["radius_table"])
    if engine != "eevee" and description.get("diffuse", "principled") == "lambert":
        return lambert_material(material, nodes, links, output, bsdf, albedo, mask, radius, description, textures, uv)

    links.new(albedo, bsdf.inputs["Base Color"])
    links.new(albedo, bsdf.inputs["Subsurface Color"])
    # EEVEE ignores the method: its kernel is always Christensen-Burley's (docs/pathtraced.md, "EEVEE").
    bsdf.subsurface_method = "BURLEY" if engine == "eevee" else "RANDOM_WALK_FIXED_RADIUS"
    bsdf.inputs["Subsurface Radius"].default_value = tuple(float(r) for r in description["radius"])
    if radius is not None:
        links.new(radius, bsdf.inputs["Subsurface Radius"])
    if description["sss"]:
        links.new(mask, bsdf.inputs["Subsurface"])
    else:
        bsdf.inputs["Subsurface"].default_value = 0.0
    principled_specular(nodes, links, bsdf, description, textures, uv)
    normal = normal_input(nodes, links, textures, uv)
    if normal is not None:
        links.new(normal, bsdf.inputs["Normal"])
    links.new(bsdf.outputs["BSDF"], output.inputs["Surface"])
    if engine == "eevee":
        skin_output = nodes.new("ShaderNodeOutputAOV")
        skin_output.name = SKIN_AOV
        skin_output.inputs["Value"].default_value = float(material.pass_index)
    return material


def aim(obj, direction):
    # Blender lights and cameras look along their local -Z.
    obj.rotation_mode = "QUATERNION"
    obj.rotation_quaternion = Vector(direction).normalized().to_track_quat("-Z", "Y")


def undo_spot_cosine(data):
    # Cycles' spot multiplies its smoothstep cone by the cosine to its axis; the rasterizer's does not. The light's
    # emission is divided by that cosine: the direction leaving the light, in the light's frame (the "Normal" of
    # its texture coordinates), has z = -cos (the spot looks along its -Z).
    data.use_nodes = True
    nodes = data.node_tree.nodes
    links = data.node_tree.links
    emission = next(node for node in nodes if node.type == "EMISSION")
    coordinates = nodes.new("ShaderNodeTexCoord")
    separate = nodes.new("ShaderNodeSeparateXYZ")
    links.new(coordinates.outputs["Normal"], separate.inputs["Vector"])
    cosine = multiply(nodes, links, separate.outputs["Z"], -1.0)
    cosine = multiply(nodes, links, cosine, 1e-3, "MAXIMUM")
    links.new(multiply(nodes, links, 1.0, cosine, "DIVIDE"), emission.inputs["Strength"])


def build_lights(scene, lights, engine="cycles", far=1000.0):
    for index, description in enumerate(lights):
        kind = description["type"]
        data = bpy.data.lights.new("skinlab_light_%d" % index, "SUN" if kind == "sun" else "SPOT")
        data.color = tuple(float(c) for c in description["color"])
        data.cycles.cast_shadow = bool(description["shadow"])
        data.cycles.max_bounces = 1024
        data.cycles.use_multiple_importance_sampling = True
        if engine == "eevee":
            data.use_shadow = bool(description["shadow"])
            data.use_contact_shadow = False
            if kind == "sun":
                # The cascades cover everything the camera sees (Blender's default stops at 200 units, 0.2 m
                # of a scene in millimetres).
                data.shadow_cascade_max_distance = far
            else:
                data.shadow_buffer_clip_start = 1e-3 * far
        if kind == "sun":
            data.energy = float(description["strength"])
            data.angle = float(description["angle_rad"])
        else:
            data.energy = float(description["power"])
            data.shadow_soft_size = 0.0
            data.spot_size = float(description["spot_size_rad"])
            data.spot_blend = float(description["spot_blend"])
            data.show_cone = False
            if engine == "cycles":
                undo_spot_cosine(data)
        obj = bpy.data.objects.new("skinlab_light_%d" % index, data)
        if kind == "spot":
            obj.location = Vector(description["position"])
        aim(obj, description["direction"])
        scene.collection.objects.link(obj)


def build_world(scene, description):
    world = bpy.data.worlds.new("skinlab_world")
    scene.world = world
    world.use_nodes = True
    nodes = world.node_tree.nodes
    links = world.node_tree.links
    nodes.clear()
    output = nodes.new("ShaderNodeOutputWorld")
    lighting = nodes.new("ShaderNodeBackground")
    lighting.inputs["Strength"].default_value = float(description["intensity"])
    if description.get("file"):
        environment = nodes.new("ShaderNodeTexEnvironment")
        environment.image = load_image(description["file"], "Linear")
        environment.projection = "EQUIRECTANGULAR"
        environment.interpolation = "Linear"
        # Blender's equirectangular lookup of direction D: u = 0.5 - atan2(D.y, D.x) / 2pi, v = 0.5 + asin(D.z) / pi;
        # skinlab's (renderer/scene/environment.cpp): u = 0.5 + atan2(e.x, -e.z) / 2pi, v_top = acos(e.y) / pi with
        # e = environment_from_world * d. D = rows . d reproduces it (rows given by the exporter).
        coordinates = nodes.new("ShaderNodeTexCoord")
        combine = nodes.new("ShaderNodeCombineXYZ")
        for axis, row in enumerate(description["lookup_rows"]):
            dot = nodes.new("ShaderNodeVectorMath")
            dot.operation = "DOT_PRODUCT"
            links.new(coordinates.outputs["Generated"], dot.inputs[0])
            dot.inputs[1].default_value = tuple(float(x) for x in row)
            links.new(dot.outputs["Value"], combine.inputs[axis])
        links.new(combine.outputs["Vector"], environment.inputs["Vector"])
        links.new(environment.outputs["Color"], lighting.inputs["Color"])
    else:
        lighting.inputs["Color"].default_value = tuple(float(c) for c in description["radiance"]) + (1.0,)
    shader = lighting.outputs["Background"]
    if description.get("camera_background") is not None:
        # What the camera sees directly differs from what lights the scene (environment.background = color).
        seen = nodes.new("ShaderNodeBackground")
        seen.inputs["Color"].default_value = tuple(float(c) for c in description["camera_background"]) + (1.0,)
        seen.inputs["Strength"].default_value = 1.0
        path = nodes.new("ShaderNodeLightPath")
        mix = nodes.new("ShaderNodeMixShader")
        links.new(path.outputs["Is Camera Ray"], mix.inputs["Fac"])
        links.new(shader, mix.inputs[1])
        links.new(seen.outputs["Background"], mix.inputs[2])
        shader = mix.outputs["Shader"]
    links.new(shader, output.inputs["Surface"])
    world.cycles.sampling_method = "MANUAL" if description.get("file") else "NONE"
    if description.get("file"):
        world.cycles.sample_map_resolution = 1024


def build_camera(scene, description):
    data = bpy.data.cameras.new("skinlab_camera")
    data.type = "PERSP"
    data.sensor_fit = "VERTICAL"
    data.sensor_height = 24.0
    data.lens = 12.0 / math.tan(0.5 * float(description["fov_y_rad"]))
    # render.window: the window's part of the frame, off the view axis (units of the image height, vertical fit).
    data.shift_x = float(description.get("shift_x", 0.0))
    data.shift_y = float(description.get("shift_y", 0.0))
    data.clip_start = float(description["near"])
    data.clip_end = float(description["far"])
    obj = bpy.data.objects.new("skinlab_camera", data)
    m = description["view_to_world"]  # column-major 4x4
    obj.matrix_world = Matrix([[m[0], m[4], m[8], m[12]], [m[1], m[5], m[9], m[13]],
                               [m[2], m[6], m[10], m[14]], [m[3], m[7], m[11], m[15]]])
    scene.collection.objects.link(obj)
    scene.camera = obj


def render_to(scene, folder, output_name):
    output = os.path.join(folder, output_name)
    scene.render.filepath = output
    start = time.time()
    bpy.ops.render.render(write_still=True)
    seconds = time.time() - start
    if not os.path.isfile(output):
        fail(scene.render.engine + " wrote no image to " + output)
    return seconds


def write_record(folder, record_name, seconds, passes=1):
    record = {"blender_version": bpy.app.version_string, "render_seconds": seconds, "passes": passes,
              "engine": bpy.context.scene.render.engine}
    with open(os.path.join(folder, record_name), "w") as handle:
        json.dump(record, handle)


def render(scene, folder, output_name, record_name):
    write_record(folder, record_name, render_to(scene, folder, output_name))


def unshadowed_environment(scene):
    # The environment's light reaches every point as if nothing occluded it, and no light but the environment is
    # left (their shadows are rendered in the other pass). Objects are seen by camera rays only: neither shadow
    # rays nor the BSDF-sampled rays that multiple importance sampling combines with them stop at an object.
    # (The random walk inside an object intersects only that object and ignores ray visibility.)
    for obj in scene.collection.objects:
        if obj.type == "LIGHT":
            obj.hide_render = True
        elif obj.type == "MESH":
            obj.visible_shadow = False
            obj.visible_diffuse = False
            obj.visible_glossy = False
            obj.visible_transmission = False
            obj.visible_volume_scatter = False


def resolved_textures(textures, folder):
    # Maps skinlab wrote beside the scene (a model's generated maps: they come with a "<key>_colorspace") are named
    # relative to the scene's folder; the spec's texture files by their own paths.
    resolved = dict(textures)
    for key in ("albedo", "normal"):
        if resolved.get(key) and resolved.get(key + "_colorspace"):
            resolved[key] = os.path.join(folder, resolved[key])
    return resolved


def render_scene(path):
    folder = os.path.dirname(os.path.abspath(path))
    with open(path) as handle:
        description = json.load(handle)
    engine = description["settings"].get("engine", "cycles")
    scene = reset_scene()
    configure_engine(scene, description["settings"])
    configure_passes(scene, engine)
    textures = resolved_textures(description.get("textures", {}), folder)
    materials = [build_material(m, textures, engine) for m in description["materials"]]
    mesh_path = os.path.join(folder, description["mesh"]["file"])
    for index, part in enumerate(description["mesh"]["parts"]):
        mesh = build_mesh(mesh_path, part, "skinlab_part_%d" % index)
        mesh.materials.append(materials[int(part["material"])])
        obj = bpy.data.objects.new("skinlab_part_%d" % index, mesh)
        obj.pass_index = 1
        scene.collection.objects.link(obj)
    build_lights(scene, description["lights"], engine, float(description["camera"]["far"]))
    build_world(scene, description["world"])
    build_camera(scene, description["camera"])
    if description["world"].get("shadow", True):
        render(scene, folder, description["output"], description["record"])
    elif description.get("environment_output"):
        # Two passes, summed by skinlab: the lights with their shadows (the world dark), then the environment
        # unshadowed without the lights.
        # Every Background node of the world (what lights the scene and what the camera sees) dark, then restored.
        backgrounds = [node.inputs["Strength"] for node in scene.world.node_tree.nodes
                       if node.bl_idname == "ShaderNodeBackground"]
        strengths = [strength.default_value for strength in backgrounds]
        for strength in backgrounds:
            strength.default_value = 0.0
        seconds = render_to(scene, folder, description["output"])
        for strength, value in zip(backgrounds, strengths):
            strength.default_value = value
        unshadowed_environment(scene)
        seconds += render_to(scene, folder, description["environment_output"])
        write_record(folder, description["record"], seconds, passes=2)
    else:
        unshadowed_environment(scene)
        render(scene, folder, description["output"], description["record"])


def box(name, low, high):
    mesh = bpy.data.meshes.new(name)
    x0, y0, z0 = low
    x1, y1, z1 = high
    vertices = [(x0, y0, z0), (x1, y0, z0), (x1, y1, z0), (x0, y1, z0),
                (x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)]
    faces = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7)]
    mesh.from_pydata(vertices, [], faces)
    mesh.update()
    # The attributes build_material reads (white, all skin).
    mesh.uv_layers.new(name="UVMap")
    color = mesh.attributes.new("skinlab_color", "FLOAT_COLOR", "POINT")
    color.data.foreach_set("color", [1.0] * (4 * len(vertices)))
    skin = mesh.attributes.new("skinlab_skin", "FLOAT", "POINT")
    skin.data.foreach_set("value", [1.0] * len(vertices))
    return bpy.data.objects.new(name, mesh)


def render_profile(path):
    # Edge response of a semi-infinite skin slab: top face z = 0 (mm), lit from straight above by a hard sun over
    # x < 0 only; an orthographic camera looks down on a strip across the edge. Radiance at x > 0 is the light
    # that travelled further than x inside the slab (docs/pathtraced.md, "Matched profiles").
    folder = os.path.dirname(os.path.abspath(path))
    with open(path) as handle:
        description = json.load(handle)
    scene = reset_scene()
    configure_cycles(scene, description["settings"])
    configure_passes(scene)
    size = float(description["slab_size"])
    slab = box("slab", (-size, -size, -size), (size, size, 0.0))
    material = build_material({"name": "skin", "skin": 1.0, "albedo": description["albedo"],
                               "radius": description["radius"], "radius_table": description.get("radius_table"),
                               "sss": True, "roughness": 0.5, "specular": 0.0}, {})
    slab.data.materials.append(material)
    scene.collection.objects.link(slab)
    # The plate: black, casts the shadow, invisible to camera rays.
    plate = box("plate", (0.0, -size, 1e-3), (size, size, 2e-3))
    black = bpy.data.materials.new("black")
    black.use_nodes = True
    black.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = (0.0, 0.0, 0.0, 1.0)
    black.node_tree.nodes["Principled BSDF"].inputs["Specular"].default_value = 0.0
    plate.data.materials.append(black)
    plate.visible_camera = False
    scene.collection.objects.link(plate)
    build_lights(scene, [{"type": "sun", "direction": [0.0, 0.0, -1.0], "color": [1.0, 1.0, 1.0],
                          "strength": math.pi, "angle_rad": 0.0, "shadow": True}])
    build_world(scene, {"intensity": 0.0, "radiance": [0.0, 0.0, 0.0]})
    data = bpy.data.cameras.new("camera")
    data.type = "ORTHO"
    data.sensor_fit = "HORIZONTAL"
    data.ortho_scale = float(description["strip_length"])
    data.clip_start = 1.0
    data.clip_end = 100.0
    camera = bpy.data.objects.new("camera", data)
    camera.location = (float(description["strip_centre"]), 0.0, 10.0)
    scene.collection.objects.link(camera)
    scene.camera = camera
    render(scene, folder, description["output"], description["record"])


def main():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    if len(argv) != 2 or argv[0] not in ("render", "profile"):
        fail("usage: blender -b --python cycles_scene.py -- render|profile FILE.json")
    try:
        if argv[0] == "render":
            render_scene(argv[1])
        else:
            render_profile(argv[1])
    except SystemExit:
        raise
    except Exception:
        traceback.print_exc()
        fail("building or rendering the scene failed (traceback above)")


main()
