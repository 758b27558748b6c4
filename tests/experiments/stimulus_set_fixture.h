#pragma once
// Builds a small stimulus set (tiny PNGs + manifest.json, contract 2) in a fresh temporary folder, so the
// experiment tests never need the renderer.
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

// A fresh folder under the system temp dir, removed by the destructor.
class TemporaryFolder {
public:
    explicit TemporaryFolder(const std::string& stem);
    ~TemporaryFolder();
    const std::filesystem::path& path() const { return path_; }

private:
    std::filesystem::path path_;
};

// Writes png/ID.png and manifest.json into `folder`; ids are "<block index>-<method>". Each image has a
// distinct high-frequency pattern (any resampling would change its pixels). Factor "quality" holds the method's
// index as a number (usable as --truth-factor). Each stimulus's resolved parameters hold sss.method = its method
// ("eevee-no-sss": EEVEE with eevee.sss = false).
void writeStimulusSet(const std::filesystem::path& folder, const StimulusSetSpec& spec = {});

// Writes `text` to folder/name and returns the path.
std::filesystem::path writeText(const std::filesystem::path& folder, const std::string& name, const std::string& text);

} // namespace skinlab::experiments::test_support
