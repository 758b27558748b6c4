#include "cli/options.h"

#include "common/error.h"

#include <array>
#include <cmath>
#include <sstream>

namespace skinlab::cli {

CLI::Option* addAssetsOption(CLI::App& command, std::string& assets) {
    return command.add_option("--assets", assets,
                              "Folder of the shared assets that assets: paths name (default $SKINLAB_ASSETS)");
}

CLI::Option* addOverridesOption(CLI::App& command, std::vector<std::string>& overrides, const std::string& what) {
    return command.add_option("--set", overrides, "Override a " + what + ": key=value (repeatable)")
        ->type_name("KEY=VALUE")
        ->take_all();
}

namespace {

std::string formatNumber(double value) {
    std::ostringstream out;
    out << value;
    return out.str();
}

// "WIDTHxHEIGHT" → {width, height}; InputError naming --display-resolution otherwise.
std::array<int, 2> parseResolution(const std::string& text) {
    const auto separator = text.find('x');
    std::array<int, 2> size{0, 0};
    bool ok = separator != std::string::npos && separator > 0 && separator + 1 < text.size();
    if (ok) {
        try {
            std::size_t used = 0;
            size[0] = std::stoi(text.substr(0, separator), &used);
            ok = used == separator;
            const std::string rest = text.substr(separator + 1);
            size[1] = std::stoi(rest, &used);
            ok = ok && used == rest.size();
        } catch (const std::exception&) {
            ok = false;
        }
    }
    if (!ok || size[0] <= 0 || size[1] <= 0)
        throwInput("--display-resolution", "", "\"" + text + "\" must be WIDTHxHEIGHT in pixels, e.g. 1920x1080");
    return size;
}

std::string displayNameList() {
    std::string list;
    for (const std::string& name : metrics::cvvdpDisplayNames()) list += (list.empty() ? "" : ", ") + name;
    return list;
}

} // namespace

bool DisplayArguments::changed() const { return pixelsPerDegree || resolution || overrides.any(); }

metrics::CvvdpDisplayOverrides DisplayArguments::changes() const {
    metrics::CvvdpDisplayOverrides result = overrides;
    if (pixelsPerDegree) {
        if (!(*pixelsPerDegree > 0.0) || !std::isfinite(*pixelsPerDegree))
            throwInput("--ppd", "", formatNumber(*pixelsPerDegree) + " must be a positive number");
        if (overrides.pixelsPerDegree && *overrides.pixelsPerDegree != *pixelsPerDegree)
            throwInput("--ppd", "", "differs from --display-ppd (one viewing geometry: give one of them)");
        result.pixelsPerDegree = pixelsPerDegree;
    }
    if (resolution) result.resolution = parseResolution(*resolution);
    return result;
}

metrics::CvvdpDisplay DisplayArguments::resolve(const std::optional<std::string>& fallback) const {
    const metrics::CvvdpDisplayOverrides checked = changes();
    return metrics::applyCvvdpOverrides(metrics::cvvdpDisplay(name.value_or(fallback.value_or("standard_fhd"))),
                                        checked);
}

void addDisplayOptions(CLI::App& command, DisplayArguments& display, const std::string& nameHelp) {
    command.add_option("--display", display.name, nameHelp + ": " + displayNameList());
    command.add_option("--ppd", display.pixelsPerDegree,
                       "Pixels per degree of visual angle of the viewing geometry, for FLIP and ColorVideoVDP alike "
                       "(the same as --display-ppd; default: the display's)");
    metrics::CvvdpDisplayOverrides& o = display.overrides;
    command.add_option("--display-ppd", o.pixelsPerDegree,
                       "Custom display: pixels per degree (overrides the geometry)");
    command.add_option("--display-resolution", display.resolution,
                       "Custom display: resolution WIDTHxHEIGHT in pixels (with the diagonal and distance: ppd)");
    command.add_option("--display-diagonal-in", o.diagonalInches, "Custom display: diagonal in inches");
    command.add_option("--display-distance-m", o.viewingDistanceMetres, "Custom display: viewing distance in metres");
    command.add_option("--display-peak", o.peakLuminance, "Custom display: peak luminance in cd/m2");
    command.add_option("--display-contrast", o.contrast, "Custom display: contrast ratio (peak / black level)");
    command.add_option("--display-ambient", o.ambientIlluminance, "Custom display: ambient light in lux");
    command.add_option("--display-reflectivity", o.reflectivity,
                       "Custom display: reflectivity of the screen (0-1, default 0.005)");
}

} // namespace skinlab::cli
