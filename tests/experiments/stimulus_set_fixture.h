#pragma once
// Builds a small stimulus set (tiny PNGs + manifest.json, contract 2) in a fresh temporary folder, so the
// experiment tests never need the renderer.
#include "tests/common/temp_folder.h"

#include <filesystem>
#include <string>
#include <vector>

namespace skinlab::experiments::test_support {

struct StimulusSetSpec {
    std::vector<std::string> blocks{"scene:a/mid", "scene:b/close"};
    std::vector<std::string> methods{"reference-like", "separable", "artistic"};
    bool withReference = true; // one extra stimulus per block with "reference": true, method "reference"
    int width = 24;
    int height = 16;
};

// A fresh folder under the build folder's tests-tmp/, removed by the destructor (tests/common/temp_folder.h).
using skinlab::test_support::TempFolder;

// Writes png/ID.png and manifest.json into `folder`; ids are "<block index>-<method>". Each image has a
// distinct high-frequency pattern (any resampling would change its pixels). Factor "quality" holds the method's
// index as a number (usable as --truth-factor). Each stimulus's resolved parameters hold sss.method = its method
// ("eevee-no-sss": EEVEE with eevee.sss = false).
void writeStimulusSet(const std::filesystem::path& folder, const StimulusSetSpec& spec = {});

// Writes `text` to folder/name and returns the path.
std::filesystem::path writeText(const std::filesystem::path& folder, const std::string& name, const std::string& text);

} // namespace skinlab::experiments::test_support
