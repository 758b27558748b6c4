#include "analysis/metrics/seed_mean.h"

#include "common/error.h"
#include "common/files.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cstddef>
#include <memory>

namespace skinlab::metrics {
namespace {

struct SeedImage {
    OIIO::ImageSpec spec;
    std::vector<float> pixels; // interleaved, spec.nchannels per pixel
    nlohmann::json resolved;   // skinlab:resolved without pathtraced.seed
    nlohmann::json pathtraced; // skinlab:pathtraced
};

nlohmann::json jsonAttribute(const OIIO::ImageSpec& spec, const std::string& file, const char* key) {
    const std::string text = spec.get_string_attribute(key);
    if (text.empty())
        throwInput(file, key,
                   "metadata attribute is missing: a seed mean needs skinlab's path-traced renders "
                   "(sss.method = \"pathtraced\")");
    try {
        return nlohmann::json::parse(text);
    } catch (const nlohmann::json::exception&) {
        throwInput(file, key, "is not JSON");
    }
}

SeedImage readSeed(const std::filesystem::path& path) {
    const std::string file = path.string();
    auto input = OIIO::ImageInput::open(file);
    if (!input) {
        std::string reason = OIIO::geterror();
        if (auto newline = reason.find('\n'); newline != std::string::npos) reason.resize(newline);
        throwInput(file, "", "not a readable image (" + reason + ")");
    }
    SeedImage seed;
    seed.spec = input->spec();
    seed.pathtraced = jsonAttribute(seed.spec, file, "skinlab:pathtraced");
    seed.resolved = jsonAttribute(seed.spec, file, "skinlab:resolved");
    if (seed.resolved.contains("pathtraced") && seed.resolved["pathtraced"].is_object())
        seed.resolved["pathtraced"].erase("seed");
    if (!seed.pathtraced.contains("seed") || !seed.pathtraced["seed"].is_number_integer())
        throwInput(file, "skinlab:pathtraced", "has no integer \"seed\"");
    const std::size_t count = static_cast<std::size_t>(seed.spec.width) * static_cast<std::size_t>(seed.spec.height) *
                              static_cast<std::size_t>(seed.spec.nchannels);
    seed.pixels.resize(count);
    if (!input->read_image(0, 0, 0, seed.spec.nchannels, OIIO::TypeDesc::FLOAT, seed.pixels.data()))
        throwInput(file, "", "cannot read its pixels (" + input->geterror() + ")");
    return seed;
}

// The channels the path tracer's noise is in: the beauty and the light layers.
bool averaged(const std::string& channel) {
    return channel == "R" || channel == "G" || channel == "B" || channel.rfind("diffuse.", 0) == 0 ||
           channel.rfind("specular.", 0) == 0;
}

} // namespace

nlohmann::json writeSeedMean(const std::vector<std::filesystem::path>& seeds, const std::filesystem::path& output) {
    if (seeds.size() < 2)
        throwInput("SEED.exr", "",
                   "a seed mean needs at least two path-traced renders of the same scene with different seeds, got " +
                       std::to_string(seeds.size()));
    const SeedImage first = readSeed(seeds.front());
    const std::string firstFile = seeds.front().string();
    std::vector<double> sum(first.pixels.begin(), first.pixels.end());
    nlohmann::json seedNumbers = nlohmann::json::array({first.pathtraced["seed"]});
    nlohmann::json files = nlohmann::json::array({seeds.front().filename().string()});
    for (std::size_t k = 1; k < seeds.size(); ++k) {
        const SeedImage seed = readSeed(seeds[k]);
        const std::string file = seeds[k].string();
        if (seed.spec.width != first.spec.width || seed.spec.height != first.spec.height)
            throwInput(file, "",
                       std::to_string(seed.spec.width) + "x" + std::to_string(seed.spec.height) + " differs from " +
                           firstFile + " (" + std::to_string(first.spec.width) + "x" +
                           std::to_string(first.spec.height) + ")");
        if (seed.spec.channelnames != first.spec.channelnames)
            throwInput(file, "", "its channels differ from " + firstFile + "'s");
        if (seed.resolved != first.resolved)
            throwInput(file, "skinlab:resolved",
                       "differs from " + firstFile + "'s in more than pathtraced.seed: a seed mean needs one scene");
        for (const auto& other : seedNumbers)
            if (other == seed.pathtraced["seed"])
                throwInput(file, "skinlab:pathtraced",
                           "seed " + seed.pathtraced["seed"].dump() +
                               " is given twice: a seed mean needs independent seeds");
        seedNumbers.push_back(seed.pathtraced["seed"]);
        files.push_back(seeds[k].filename().string());
        for (std::size_t i = 0; i < sum.size(); ++i) sum[i] += static_cast<double>(seed.pixels[i]);
    }

    const int channels = first.spec.nchannels;
    std::vector<bool> mean(static_cast<std::size_t>(channels));
    nlohmann::json averagedChannels = nlohmann::json::array();
    for (int c = 0; c < channels; ++c) {
        mean[static_cast<std::size_t>(c)] = averaged(first.spec.channel_name(c));
        if (mean[static_cast<std::size_t>(c)]) averagedChannels.push_back(first.spec.channel_name(c));
    }
    std::vector<float> pixels(first.pixels.size());
    const double count = static_cast<double>(seeds.size());
    for (std::size_t i = 0; i < pixels.size(); ++i)
        pixels[i] = mean[i % static_cast<std::size_t>(channels)] ? static_cast<float>(sum[i] / count) : first.pixels[i];

    nlohmann::json truth{{"kind", "pathtraced-seed-mean"},
                         {"seeds", seedNumbers},
                         {"files", files},
                         {"samples", first.pathtraced.value("samples", nlohmann::json())},
                         {"averaged_channels", averagedChannels},
                         {"note", "mean of independent Cycles seeds: noise variance of one seed / their count"}};
    OIIO::ImageSpec spec = first.spec;
    spec.erase_attribute("skinlab:pathtraced_seed");
    spec.erase_attribute("skinlab:render_seconds");
    nlohmann::json pathtraced = first.pathtraced;
    pathtraced["seed"] = seedNumbers;
    pathtraced.erase("render_seconds");
    pathtraced.erase("wall_seconds");
    spec.attribute("skinlab:pathtraced", pathtraced.dump());
    spec.attribute("skinlab:resolved", first.resolved.dump());
    spec.attribute(truthAttribute, truth.dump());
    spec.attribute("compression", "zips");
    spec.attribute("DateTime", "");
    spec.set_format(OIIO::TypeDesc::FLOAT);

    AtomicOutput atomic(output);
    auto writer = OIIO::ImageOutput::create("openexr");
    if (!writer) throw RuntimeError("OpenImageIO has no OpenEXR writer: " + OIIO::geterror());
    if (!writer->open(atomic.tempPath().string(), spec) || !writer->write_image(OIIO::TypeDesc::FLOAT, pixels.data()) ||
        !writer->close())
        throwInput(output.string(), "", "cannot write EXR (" + writer->geterror() + ")");
    atomic.commit();
    return truth;
}

nlohmann::json describeTruth(const std::filesystem::path& reference) {
    auto input = OIIO::ImageInput::open(reference.string());
    if (!input) return {{"kind", "image"}};
    const OIIO::ImageSpec& spec = input->spec();
    const std::string truth = spec.get_string_attribute(truthAttribute);
    if (!truth.empty()) {
        try {
            return nlohmann::json::parse(truth);
        } catch (const nlohmann::json::exception&) {
            throwInput(reference.string(), truthAttribute, "is not JSON");
        }
    }
    const std::string resolved = spec.get_string_attribute("skinlab:resolved");
    if (resolved.empty()) return {{"kind", "image"}};
    nlohmann::json record{{"kind", "render"}};
    try {
        const nlohmann::json scene = nlohmann::json::parse(resolved);
        if (scene.contains("sss") && scene["sss"].contains("method")) record["method"] = scene["sss"]["method"];
        if (scene.contains("pathtraced") && scene["pathtraced"].contains("seed"))
            record["seed"] = scene["pathtraced"]["seed"];
    } catch (const nlohmann::json::exception&) {
        // A render whose resolved parameters are not JSON is described by its kind only.
    }
    return record;
}

} // namespace skinlab::metrics
