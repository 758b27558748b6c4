#pragma once
// The renderer's public entry point: one scene spec in, one set of files out (linear EXR with AOVs, optional
// display PNG) plus a record of how it was made. `skinlab render`, `skinlab stimuli build` and the benchmarks
// all go through here, so every image of the project is made the same way.
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

namespace skinlab::renderer {

struct RenderRequest {
    // "builtin:halo|bleed|ear|head" or the path of a scene spec (TOML).
    std::string scene;
    // "key=value" overrides applied in order after the spec (exactly like `--set key=value`).
    std::vector<std::string> overrides;
    // Shorthands for the overrides sss.method, render.width, render.height (applied after `overrides`).
    std::optional<std::string> method;
    std::optional<int> width;
    std::optional<int> height;
    // Folder holding the shared assets (scanned head, HDR environments); empty: $SKINLAB_ASSETS.
    std::filesystem::path assetsDir;
    // Linear EXR (beauty + AOV channels), required; display PNG (tone mapped, sRGB), optional.
    std::filesystem::path exrPath;
    std::filesystem::path pngPath;
};

struct RenderResult {
    nlohmann::json resolved;  // every parameter after defaults and overrides (also stored in the EXR metadata)
    std::string glRenderer;   // GL_RENDERER, e.g. "llvmpipe (LLVM 15.0.6, 256 bits)"
    std::string glVersion;    // GL_VERSION
    nlohmann::json timingsMs; // {"passes": {"shadow": ms, ...}, "gpu_total": ms, "wall_total": ms}
};

// Resolves a request's scene spec (defaults, overrides, validation) without touching GL. Throws InputError for
// bad input. Used to decide whether a stimulus must be re-rendered.
nlohmann::json resolveScene(const RenderRequest& request);

// Owns the headless EGL context and GL resources; create once, render many times (not thread-safe).
class Renderer {
public:
    Renderer(); // throws RuntimeError naming what was tried when no EGL platform works
    ~Renderer();
    Renderer(const Renderer&) = delete;
    Renderer& operator=(const Renderer&) = delete;

    RenderResult render(const RenderRequest& request);
    std::string glRenderer() const;
    std::string glVersion() const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

} // namespace skinlab::renderer
