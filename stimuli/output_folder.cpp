#include "stimuli/output_folder.h"

#include "common/error.h"

#include <algorithm>
#include <spdlog/spdlog.h>

namespace skinlab::stimuli {

namespace fs = std::filesystem;

namespace {
std::string shardText(const std::optional<Shard>& shard) {
    return shard ? "shard " + std::to_string(shard->index) + "/" + std::to_string(shard->count) : "the whole set";
}
} // namespace

std::string exrRelativePath(const std::string& id) { return "exr/" + id + ".exr"; }
std::string pngRelativePath(const std::string& id) { return "png/" + id + ".png"; }

std::optional<Manifest> claimOutputFolder(const fs::path& dir, const std::string& set,
                                          const std::optional<Shard>& shard) {
    std::error_code ec;
    if (!fs::exists(dir, ec)) return std::nullopt;
    if (!fs::is_directory(dir, ec)) throwInput(dir.string(), "", "exists and is not a folder");
    std::optional<Manifest> existing = readManifest(dir);
    if (!existing) {
        if (!fs::is_empty(dir, ec))
            throwInput(dir.string(), "",
                       "is not empty and holds no stimulus set (no manifest.json); choose a new or empty folder");
        return std::nullopt;
    }
    if (existing->set != set)
        throwInput(dir.string(), "",
                   "holds stimulus set '" + existing->set + "', not '" + set + "'; choose another folder");
    bool sameShard = existing->shard.has_value() == shard.has_value() &&
                     (!shard || (existing->shard->index == shard->index && existing->shard->count == shard->count));
    if (!sameShard)
        throwInput(dir.string(), "",
                   "holds " + shardText(existing->shard) + " of set '" + set + "', not " + shardText(shard) +
                       "; choose another folder");
    return existing;
}

void tidyOutputFolder(const fs::path& dir, const std::vector<std::string>& keepIds) {
    for (const char* sub : {"exr", "png"}) {
        fs::path folder = dir / sub;
        std::error_code ec;
        if (!fs::is_directory(folder, ec)) continue;
        std::vector<fs::path> remove;
        for (const auto& entry : fs::directory_iterator(folder)) {
            std::string name = entry.path().filename().string();
            bool temporary = !name.empty() && name.front() == '.' && name.find(".tmp-") != std::string::npos;
            bool ours = entry.path().extension() == "." + std::string(sub);
            bool kept = std::find(keepIds.begin(), keepIds.end(), entry.path().stem().string()) != keepIds.end();
            if (temporary || (ours && !kept)) remove.push_back(entry.path());
        }
        for (const auto& path : remove) {
            spdlog::debug("stimuli: removing {}", path.string());
            fs::remove(path, ec);
        }
    }
}

} // namespace skinlab::stimuli
