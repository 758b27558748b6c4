#pragma once
// The stimulus set of the study-server benchmarks: `count` conditions c0, c1, ... in one block "bench", one PNG
// file each whose bytes `bytesOf(id)` gives (the server never decodes them, so any bytes stand in for a PNG; the
// manifest records their real sha256), and manifest.json beside them. Written atomically into `folder`.
#include "common/files.h"
#include "common/hash.h"

#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>

namespace skinlab::bench {

inline void writeBenchStimulusSet(const std::filesystem::path& folder, int count, int width, int height,
                                  const std::function<std::string(const std::string& id)>& bytesOf) {
    std::filesystem::create_directories(folder / "png");
    nlohmann::json manifest{
        {"format", "skinlab-stimuli"}, {"version", 1}, {"set", "bench"}, {"stimuli", nlohmann::json::array()}};
    for (int m = 0; m < count; ++m) {
        const std::string id = "c" + std::to_string(m);
        const std::string bytes = bytesOf(id);
        writeFileAtomic(folder / "png" / (id + ".png"), bytes);
        manifest["stimuli"].push_back({{"id", id},
                                       {"files", {{"png", "png/" + id + ".png"}}},
                                       {"sha256", {{"png", sha256Hex(bytes)}}},
                                       {"factors", {{"method", id}}},
                                       {"block", "bench"},
                                       {"reference", false},
                                       {"width", width},
                                       {"height", height}});
    }
    writeFileAtomic(folder / "manifest.json", manifest.dump());
}

} // namespace skinlab::bench
