#pragma once
// Views for replaying published shaders' sssWidth steps in pixels (test_sss_params.cpp, test_width_conventions.cpp),
// and where skinlab's artistic kernel puts its outermost tap in pixels at a given width_mm.
#include "renderer/sss/kernel.h"

#include <cmath>
#include <gtest/gtest.h>

namespace skinlab::renderer::sss::test {

struct View {
    double sssWidth, mmPerUnit, fovDeg, z, height;
    // tan(fovY / 2)
    double tanHalfFov() const { return std::tan(0.5 * fovDeg * 3.14159265358979323846 / 180.0); }
};
inline const View kViews[] = {View{0.012, 47.9, 20.0, 2.5, 720.0}, View{1.5, 1.0, 30.0, 300.0, 512.0},
                              View{0.05, 10.0, 45.0, 7.0, 1080.0}};

// The artistic kernel's outermost tap (25 taps: at width_mm) in pixels: pixels per mm = f_px / (mm_per_unit · z),
// f_px = (H/2) / tan(fovY/2).
inline double artisticEdgePixels(double widthMm, const View& v) {
    SssParams params;
    params.method = methodId("artistic");
    params.samples = 25;
    params.widthMm = widthMm;
    const Kernel kernel = makeKernel(params);
    EXPECT_EQ(kernel.stages.size(), 1u);
    const double edgeMm = kernel.stages.at(0).taps.back().offsetMm;
    const double fPx = 0.5 * v.height / v.tanHalfFov();
    return edgeMm * fPx / (v.mmPerUnit * v.z);
}

} // namespace skinlab::renderer::sss::test
