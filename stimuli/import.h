#pragma once
// `skinlab stimuli import TABLE -o DIR`: images made elsewhere (another renderer, photographs, another paper's
// figures) become a stimulus set with the same folder layout and manifest (contract 2) as a built one, so that
// `study create`, `analyze metrics` and `report` use it unchanged. The table (CSV or TOML, docs/stimuli.md,
// "Importing images from other renderers") names each image, its factor levels, block and reference flag, and how
// its pixels are encoded. Everything is checked before anything is written.
#include "analysis/metrics/cvvdp.h"

#include <filesystem>
#include <string>
#include <vector>

namespace skinlab::stimuli {

struct ImportOptions {
    std::filesystem::path table;     // CSV (header row) or TOML ([[stimulus]] tables)
    std::filesystem::path outputDir; // the set folder to write
    std::filesystem::path images;    // folder the `file` paths are relative to (default: the table's folder)
    std::string name;                // set name (default: the table's `name`, else its file stem)
    bool contactSheet = true;
    bool predict = true; // ColorVideoVDP against each block's reference, as `stimuli build` does
    metrics::CvvdpDisplay display = metrics::cvvdpDisplay("standard_fhd"); // of the predictions (named or custom)
};

struct ImportSummary {
    std::string set;
    size_t stimuli = 0;
    size_t blocks = 0;
    std::filesystem::path manifest;
    std::filesystem::path contactHtml;    // empty without a contact sheet
    std::vector<std::string> predictions; // one line per block with a reference (predictionLines)
};

// Reads and checks the table and every image, then writes DIR/png/ID.png (8-bit sRGB), DIR/exr/ID.exr (linear
// float RGB), manifest.json, manifest.csv and the contact sheet, each atomically. Bad input throws InputError
// "TABLE:LINE: COLUMN: message" before anything is written.
ImportSummary importStimuli(const ImportOptions& options);

// The sRGB transfer functions (IEC 61966-2-1) the import applies: display value ↔ linear light, both in [0, 1]
// (the encode clamps).
float srgbToLinear(float encoded);
float linearToSrgb(float linear);

} // namespace skinlab::stimuli
