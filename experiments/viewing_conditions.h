#pragma once
// Viewing conditions of a participant's session as the page reports them (screen, device-pixel ratio, colour
// depth, viewport, full screen, pointer), the credit-card calibration, pixels per degree, and the design's
// requirements checked against them. Reference: docs/study-protocol.md ("Running online").
#include "experiments/study_design.h"

#include <optional>
#include <string>
#include <vector>

namespace skinlab::experiments {

// ISO/IEC 7810 ID-1 (a credit card): 85.60 mm x 53.98 mm.
inline constexpr double kIdCardWidthMm = 85.60;
inline constexpr double kIdCardHeightMm = 53.98;

struct ViewingConditions {
    int screenWidth = 0; // CSS pixels (screen.width)
    int screenHeight = 0;
    int screenWidthPx = 0; // device pixels (CSS x devicePixelRatio, rounded)
    int screenHeightPx = 0;
    double devicePixelRatio = 1;
    int colourDepth = 0;   // screen.colorDepth, bits per pixel
    int viewportWidth = 0; // CSS pixels (innerWidth)
    int viewportHeight = 0;
    bool fullscreen = false;
    bool pointerFine = true; // matchMedia("(pointer: fine)")
    int touchPoints = 0;     // navigator.maxTouchPoints
    bool mobile = false;     // the browser says it is a mobile one (User-Agent "Mobi", "Android", "iPhone", "iPad")
    std::optional<double> pixelsPerMm;       // device pixels per mm, from the card calibration
    std::optional<double> viewingDistanceMm; // the design's
    std::optional<double> pixelsPerDegree;   // device (= image) pixels per degree of visual angle
};

// Device pixels per mm from the width of the on-screen card (CSS pixels) matched to a real one.
double pixelsPerMmFromCard(double cardWidthCss, double devicePixelRatio);
// Pixels subtending one degree at `distanceMm`: 2 d tan(0.5 deg) x pixels per mm.
double pixelsPerDegree(double pixelsPerMm, double distanceMm);
// Whether a User-Agent names a mobile browser.
bool mobileUserAgent(const std::string& userAgent);

// The requirements the conditions do not meet, each as a sentence for the participant; empty = all met.
std::vector<std::string> unmetRequirements(const RequirementsDesign& requirements, const ViewingConditions& conditions);

} // namespace skinlab::experiments
