#include "stimulus_set_fixture.h"

#include "common/files.h"
#include "common/hash.h"

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

namespace skinlab::experiments::test_support {
namespace fs = std::filesystem;

namespace {
// The resolved parameters a method name stands for: sss.method, and "eevee-no-sss" for EEVEE without SSS.
nlohmann::json resolvedOf(const std::string& method) {
    if (method == "eevee-no-sss") return {{"sss", {{"method", "eevee"}}}, {"eevee", {{"sss", false}}}};
    return {{"sss", {{"method", method}}}};
}
} // namespace

void writeStimulusSet(const fs::path& folder, const StimulusSetSpec& spec) {
    fs::create_directories(folder / "png");
    nlohmann::json manifest{
        {"format", "skinlab-stimuli"},
        {"version", 1},
        {"set", "test-set"},
        {"spec_sha256", std::string(64, '0')},
        {"renderer", {{"gl_renderer", "none (test fixture)"}, {"gl_version", ""}, {"skinlab_version", ""}}},
        {"stimuli", nlohmann::json::array()}};
    int serial = 0;
    for (std::size_t b = 0; b < spec.blocks.size(); ++b) {
        std::vector<std::string> methods = spec.methods;
        if (spec.withReference) methods.push_back("reference");
        for (std::size_t m = 0; m < methods.size(); ++m) {
            const bool isReference = spec.withReference && m + 1 == methods.size();
            const std::string id = std::to_string(b) + "-" + methods[m];
            cv::Mat image(spec.height, spec.width, CV_8UC3);
            ++serial;
            for (int y = 0; y < spec.height; ++y)
                for (int x = 0; x < spec.width; ++x) {
                    // Checkerboard of 1-pixel cells in two colours specific to the stimulus.
                    const bool on = ((x + y) % 2) == 0;
                    image.at<cv::Vec3b>(y, x) = on ? cv::Vec3b(static_cast<unsigned char>(20 * serial % 256), 40, 200)
                                                   : cv::Vec3b(230, static_cast<unsigned char>(37 * serial % 256), 10);
                }
            const fs::path png = folder / "png" / (id + ".png");
            cv::imwrite(png.string(), image);
            manifest["stimuli"].push_back(
                {{"id", id},
                 {"files", {{"exr", "exr/" + id + ".exr"}, {"png", "png/" + id + ".png"}}},
                 {"sha256", {{"exr", std::string(64, '0')}, {"png", sha256File(png)}}},
                 {"factors", {{"scene", spec.blocks[b]}, {"method", methods[m]}, {"quality", static_cast<double>(m)}}},
                 {"block", spec.blocks[b]},
                 {"reference", isReference},
                 {"width", spec.width},
                 {"height", spec.height},
                 {"resolved", resolvedOf(methods[m])},
                 {"timings_ms", nlohmann::json::object()}});
        }
    }
    writeFileAtomic(folder / "manifest.json", manifest.dump(2));
}

fs::path writeText(const fs::path& folder, const std::string& name, const std::string& text) {
    const fs::path path = folder / name;
    writeFileAtomic(path, text);
    return path;
}

} // namespace skinlab::experiments::test_support
