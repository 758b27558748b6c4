#pragma once
// One image rendered by Blender (Cycles, or EEVEE for sss.method = "eevee"): the scene written for Blender into a
// fresh temporary folder, Blender run headless, its multilayer EXR read back into the channels of skinlab's EXR
// layout. The folder is removed after a successful
// run and kept (with blender.log) after a failed one; the error names it. docs/pathtraced.md.
#include "renderer/pathtraced/blender_scene.h"

#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace skinlab::renderer::pathtraced {

struct CyclesImage {
    int width = 0;
    int height = 0;
    // Top row first. RGB interleaved, linear, exposure applied.
    std::vector<float> beauty;   // Cycles' Combined pass
    std::vector<float> diffuse;  // (DiffDir + DiffInd) × DiffCol: subsurface light is part of it in Cycles 3.x
    std::vector<float> specular; // (GlossDir + GlossInd) × GlossCol
    std::vector<float> depth;    // view-axis depth, world units; +inf where no surface
    std::vector<float> mask;     // 1 where the first hit is a skin material (material index pass / EEVEE's AOV), else 0
    std::string blenderVersion;
    double renderSeconds = 0.0; // the engine's render call, as timed by the script (EEVEE: shader compilation too)
    double wallSeconds = 0.0;   // the whole Blender run (start-up, scene building, render, EXR write)
};

// A temporary folder of its own (mkdtemp under the system temporary folder).
std::filesystem::path makeWorkFolder(const std::string& prefix);

// Reads every channel of an EXR Blender wrote (names as in the file, e.g. "ViewLayer.Combined.R"), top row first.
// Throws InputError naming the file.
std::map<std::string, std::vector<float>> readExrChannels(const std::filesystem::path& path, int& width, int& height);

// The values of the channel whose name ends with `suffix` ("Combined.R"); throws InputError naming the file.
const std::vector<float>& channelEndingWith(const std::map<std::string, std::vector<float>>& channels,
                                            const std::string& suffix, const std::filesystem::path& file);

// The record cycles_scene.py writes beside the image ({"blender_version", "render_seconds"}).
nlohmann::json readRecord(const std::filesystem::path& path);

CyclesImage renderWithCycles(const BlenderSceneInputs& inputs, float exposure);

// The same with EEVEE (inputs.engine = "eevee"; docs/pathtraced.md, "EEVEE"): beauty = Combined, diffuse = Diffuse
// Light × Diffuse Colour (subsurface light included), specular = Specular Light × Specular Colour, depth = Z (view
// axis), mask = the skin AOV (material flag, averaged over the TAA samples) ≥ 0.5.
CyclesImage renderWithEevee(const BlenderSceneInputs& inputs, float exposure);

} // namespace skinlab::renderer::pathtraced
