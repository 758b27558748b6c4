#include "experiments/viewing_conditions.h"

#include <cmath>
#include <numbers>

namespace skinlab::experiments {

double pixelsPerMmFromCard(double cardWidthCss, double devicePixelRatio) {
    return cardWidthCss * devicePixelRatio / kIdCardWidthMm;
}

double pixelsPerDegree(double pixelsPerMm, double distanceMm) {
    return 2.0 * distanceMm * std::tan(0.5 * std::numbers::pi / 180.0) * pixelsPerMm;
}

bool mobileUserAgent(const std::string& userAgent) {
    for (const char* word : {"Mobi", "Android", "iPhone", "iPad"})
        if (userAgent.find(word) != std::string::npos) return true;
    return false;
}

std::vector<std::string> unmetRequirements(const RequirementsDesign& r, const ViewingConditions& c) {
    std::vector<std::string> unmet;
    if ((r.minScreenWidth > 0 && c.screenWidth < r.minScreenWidth) ||
        (r.minScreenHeight > 0 && c.screenHeight < r.minScreenHeight))
        unmet.push_back("This study needs a screen of at least " + std::to_string(r.minScreenWidth) + " x " +
                        std::to_string(r.minScreenHeight) + " pixels (this one has " + std::to_string(c.screenWidth) +
                        " x " + std::to_string(c.screenHeight) + ").");
    if (r.noZoom && std::abs(c.devicePixelRatio - std::round(c.devicePixelRatio)) > 1e-6)
        unmet.push_back("Reset the browser zoom to 100% (Ctrl+0 or Cmd+0).");
    if (r.fullscreen && !c.fullscreen) unmet.push_back("Switch the browser to full screen.");
    if (r.desktop && (c.mobile || !c.pointerFine))
        unmet.push_back("This study needs a desktop or laptop computer with a mouse or trackpad.");
    return unmet;
}

} // namespace skinlab::experiments
