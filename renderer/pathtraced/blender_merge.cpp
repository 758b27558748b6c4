#include "renderer/pathtraced/blender_merge.h"

#include <algorithm>
#include <cstddef>

namespace skinlab::renderer::pathtraced {

CyclesImage renderBlenderFrame(BlenderEngine engine, BlenderSceneInputs inputs, float exposure) {
    const SceneSpec& spec = *inputs.spec;
    if (engine == BlenderEngine::Eevee) {
        inputs.params = spec.eevee.sceneParams();
        inputs.eeveeSettings = spec.eevee.toJson();
        return renderWithEevee(inputs, exposure);
    }
    inputs.params = spec.pathtraced;
    return renderWithCycles(inputs, exposure);
}

BlenderMerge mergeRasterizerLayers(CyclesImage& image, BlenderEngine engine, const SceneSpec& spec,
                                   const RasterizerLayers& layers) {
    BlenderMerge merge;
    const std::size_t pixels = layers.mask->size(); // the output size
    merge.rasterizerSpecular =
        (engine == BlenderEngine::Eevee ? spec.eevee.specularSource : spec.pathtraced.specularSource) == "rasterizer";
    if (merge.rasterizerSpecular) {
        // Blender rendered no specular lobe; its beauty gets the rasterizer's specular pass (same camera), so only
        // the diffuse/subsurface layer comes from Blender.
        const std::vector<float>& specular = *layers.specular;
        for (std::size_t p = 0; p < pixels; ++p)
            for (std::size_t c = 0; c < 3; ++c) {
                image.specular[p * 3 + c] = specular[p * 4 + c];
                image.beauty[p * 3 + c] += specular[p * 4 + c];
            }
    }
    // Anti-aliasing: Blender's depth and material-index passes do not follow its box filter's coverage (the index
    // pass keeps the first hit), so the depth and mask of the rasterizer's resolve (same camera and triangles:
    // nearest depth, skin coverage) replace them, and every method's AOVs mean the same.
    merge.rasterizerDepthAndMask = layers.antialiased;
    if (merge.rasterizerDepthAndMask) {
        image.depth = *layers.depth;
        image.mask = *layers.mask;
        for (float& m : image.mask) m = std::clamp(m, 0.0f, 1.0f);
    } else if (layers.fractionalSkin) {
        // A skin-mask map or per-vertex skin below 1: Blender's index pass only knows the material's flag, so the
        // rasterizer's mask (same camera, point-sampled) supplies the fraction.
        const std::vector<float>& mask = *layers.mask;
        for (std::size_t p = 0; p < pixels; ++p) image.mask[p] *= std::clamp(mask[p], 0.0f, 1.0f);
    }
    return merge;
}

namespace {
// `channels` without depth.Z and mask.Y when the rasterizer supplied them.
nlohmann::json withoutRasterizerDepthAndMask(const nlohmann::json& channels, const BlenderMerge& merge) {
    if (!merge.rasterizerDepthAndMask) return channels;
    nlohmann::json kept = nlohmann::json::array();
    for (const auto& channel : channels)
        if (channel != "depth.Z" && channel != "mask.Y") kept.push_back(channel);
    return kept;
}
} // namespace

void addBlenderMetadata(ExrMetadata& metadata, BlenderEngine engine, const SceneSpec& spec, const CyclesImage& image,
                        const BlenderMerge& merge, const nlohmann::json& blenderChannels) {
    const nlohmann::json diffuseOnly = {"R, G, B: diffuse only", "diffuse.*", "depth.Z", "mask.Y"};
    if (engine == BlenderEngine::Eevee) {
        nlohmann::json record = spec.eevee.toJson();
        record["blender_version"] = image.blenderVersion;
        record["render_seconds"] = image.renderSeconds;
        record["wall_seconds"] = image.wallSeconds;
        record["channels_from_eevee"] = withoutRasterizerDepthAndMask(
            merge.rasterizerSpecular ? diffuseOnly
                                     : nlohmann::json{"R", "G", "B", "diffuse.*", "specular.*", "depth.Z", "mask.Y"},
            merge);
        metadata.strings["skinlab:eevee"] = record.dump();
        metadata.strings["skinlab:blender_version"] = image.blenderVersion;
        metadata.floats["skinlab:render_seconds"] = static_cast<float>(image.renderSeconds);
        return;
    }
    const nlohmann::json params = spec.pathtraced.toJson();
    const nlohmann::json channelsFromCycles = withoutRasterizerDepthAndMask(
        params.value("specular_source", "cycles") == "rasterizer" ? diffuseOnly : blenderChannels, merge);
    metadata.strings["skinlab:pathtraced"] =
        nlohmann::json{{"samples", params.at("samples")},         {"seed", params.at("seed")},
                       {"blender_version", image.blenderVersion}, {"render_seconds", image.renderSeconds},
                       {"wall_seconds", image.wallSeconds},       {"channels_from_cycles", channelsFromCycles}}
            .dump();
    metadata.strings["skinlab:blender_version"] = image.blenderVersion;
    metadata.floats["skinlab:pathtraced_samples"] = static_cast<float>(params.at("samples").get<int>());
    metadata.floats["skinlab:pathtraced_seed"] = static_cast<float>(params.at("seed").get<int>());
    metadata.floats["skinlab:render_seconds"] = static_cast<float>(image.renderSeconds);
}

} // namespace skinlab::renderer::pathtraced
