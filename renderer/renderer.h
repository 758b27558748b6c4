#pragma once
// The renderer's public entry point: one scene spec in, one set of files out (linear EXR with AOVs, optional
// display PNG) plus a record of how it was made. `skinlab render`, `skinlab stimuli build` and the benchmarks
// all go through here, so every image of the project is made the same way.
#include <cstdint>
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

// One interactive frame (Renderer::renderDisplay): the display image and, when asked, the linear beauty and the
// AOVs the band metrics need, with what was re-run to make it.
struct DisplayFrame {
    int width = 0;
    int height = 0;
    std::vector<std::uint8_t> srgb8; // RGB, top row first: the bytes `skinlab render --png` encodes
    // Only with `withLinear`: R, G, B as the EXR's beauty; depth.Z; mask.Y (top row first), resolved as the EXR's
    // with anti-aliasing (render.antialiasing, docs/rendering.md): mask as coverage, depth the nearest sample's.
    std::vector<float> beauty;
    std::vector<float> depth;
    std::vector<float> mask;
    float focalLengthPixels = 0.0f; // skinlab:f_px, of the output image (not of the supersampled passes)
    float supportRadiusMm = 0.0f;   // skinlab:sss_radius_mm
    double mmPerUnit = 1.0;
    nlohmann::json resolved;
    nlohmann::json timingsMs;       // the pass timer's record of the passes that ran, plus "cpu" and "wall_total"
    std::vector<std::string> reran; // the groups re-run: "upload", "lighting", "sss" (the last always)
};

// Owns the headless EGL context and GL resources; create once, render many times (not thread-safe).
class Renderer {
public:
    Renderer(); // throws RuntimeError naming what was tried when no EGL platform works
    ~Renderer();
    Renderer(const Renderer&) = delete;
    Renderer& operator=(const Renderer&) = delete;

    RenderResult render(const RenderRequest& request);
    // The display image of `request` (its exrPath and pngPath are ignored) for live tuning: the uploaded scene
    // (model, maps, environment), the shadow maps and the lighting passes' targets stay resident between calls, and
    // a call re-runs only what its values change: the upload when the model, maps, materials or environment differ;
    // the shadow maps when the lights or shadow settings differ; the other lighting passes (main … transmittance)
    // when the camera, size, exposure, transmittance or an [sss] key the main pass reads differ; always the SSS
    // stage, add specular and tone map. The image is the same, byte for byte, as render()'s PNG of the same
    // request. A method Blender renders is refused (InputError naming it): run it through render().
    DisplayFrame renderDisplay(const RenderRequest& request, bool withLinear = false);
    std::string glRenderer() const;
    std::string glVersion() const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

} // namespace skinlab::renderer
