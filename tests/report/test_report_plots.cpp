// The report's SVG plots and number formatting: bounded output whatever the intervals (±1e9 JOD, infinite,
// NaN), clipped bars marked, and no "nan"/"inf" text.
#include "report/prediction_section.h"
#include "report/report_plots.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <regex>

namespace skinlab::report {
namespace {

int count(const std::string& text, const std::string& what) {
    int n = 0;
    for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
    return n;
}

TEST(ReportPlots, HugeAndUndefinedIntervalsAreClippedAndMarked) {
    const double inf = std::numeric_limits<double>::infinity();
    std::vector<IntervalPoint> points = {{"a", 1.0, -1e9, 1e9}, {"b", 0.0, -0.5, 0.5}, {"c", -1.0, NAN, inf}};
    std::string svg = scaleSvg(points);
    EXPECT_LT(svg.size(), 20000u) << "the plot's size must not depend on the bounds";
    EXPECT_EQ(count(svg, "class=\"clip\""), 4); // a: both ends; c: both ends (undefined and infinite)
    EXPECT_EQ(count(svg, "<circle"), 3);
    EXPECT_EQ(count(svg, "class=\"grid\""), count(svg, "class=\"tick\""));
    EXPECT_LE(count(svg, "class=\"grid\""), 12);
    EXPECT_EQ(svg.find("nan"), std::string::npos);
    EXPECT_EQ(svg.find("inf"), std::string::npos);
}

// A long condition label fits left of the axis: the margin grows with the longest label (the figure with it).
TEST(ReportPlots, ScaleMarginHoldsTheLongestLabel) {
    const std::string label = "halo-silhouette-separable-no-follow_surface-cbf";
    const std::string svg = scaleSvg({{"none", 0.0, -0.5, 0.5}, {label, 1.0, 0.5, 1.5}});
    const std::size_t text = svg.find(">" + label + "<");
    ASSERT_NE(text, std::string::npos) << svg;
    const std::size_t x = svg.rfind("<text x=\"", text);
    ASSERT_NE(x, std::string::npos);
    const double labelRight = std::stod(svg.substr(x + 9));
    EXPECT_GE(labelRight, kLabelCharacterPx * static_cast<double>(label.size())) << svg.substr(x, 120);
    const std::size_t viewBox = svg.find("viewBox=\"0 0 ");
    ASSERT_NE(viewBox, std::string::npos);
    EXPECT_GE(std::stod(svg.substr(viewBox + 13)), labelRight + 470.0);
    // Short labels keep the former 150 px margin.
    EXPECT_NE(scaleSvg({{"a", 0.0, -0.5, 0.5}}).find("viewBox=\"0 0 640.0 "), std::string::npos);
}

// A correlation without an interval says why (Fisher z needs 4 conditions) instead of "[—, —]".
TEST(ReportPlots, CorrelationIntervalSaysWhyThereIsNone) {
    EXPECT_EQ(correlationIntervalText(0.1, 0.9, 10), "[0.10, 0.90]");
    EXPECT_EQ(correlationIntervalText(NAN, NAN, 3), "(no interval with 3 conditions: Fisher z needs 4)");
    PredictionAgreement a;
    a.block = "silhouette";
    a.anchor = "separable";
    a.conditions = {"separable", "no-follow", "cbf"};
    a.predicted = {0.0, 0.4, 0.9};
    a.measured = {0.0, 0.3, 1.1};
    a.low = {NAN, 0.1, 0.8};
    a.high = {NAN, 0.5, 1.4};
    a.spearman = 1.0;
    a.spearmanLow = a.spearmanHigh = NAN;
    const std::string html = predictionSectionHtml({a}, "", {});
    EXPECT_NE(html.find("Spearman ρ = 1.00 (no interval with 3 conditions: Fisher z needs 4), exact p = "),
              std::string::npos)
        << html;
    EXPECT_NE(html.find(", over 3 conditions."), std::string::npos) << html;
    EXPECT_EQ(html.find("ρ = 1.00 [—, —]"), std::string::npos) << html;
}

// An interval with an unbounded end says so in words: never "[—, —]" (an infinite end printed as a dash).
TEST(ReportPlots, UnboundedIntervalsAreWordsNotDashes) {
    EXPECT_EQ(intervalText(-0.5, 1.25, 2), "[\u22120.50, 1.25]");
    EXPECT_EQ(intervalText(0.5, INFINITY, 2), "at least 0.50");
    EXPECT_EQ(intervalText(-INFINITY, 1.0, 2), "at most 1.00");
    EXPECT_EQ(intervalText(-INFINITY, INFINITY, 2), "none");
    EXPECT_EQ(intervalText(NAN, NAN, 2), "none");
}

TEST(ReportPlots, ScatterSkipsUndefinedPoints) {
    std::vector<ScatterPoint> points = {
        {"a", 0.1, 1.0, 0.5, 1.5}, {"b", NAN, 0.0, -0.5, 0.5}, {"c", 0.3, -1.0, -1e9, 1e9}};
    std::string svg = scatterSvg(points, "mean FLIP");
    EXPECT_EQ(count(svg, "<circle"), 2);
    EXPECT_LT(svg.size(), 20000u);
    EXPECT_EQ(svg.find("nan"), std::string::npos);
}

// An interval far beyond the points is clipped with a red arrow at each end it leaves (the value in the tooltip),
// and a label of a point in the right part of the plot is anchored at its end, so it is not cut at the figure's edge.
TEST(ReportPlots, ScatterMarksClippedBarsAndKeepsLabelsInside) {
    std::vector<ScatterPoint> points = {{"gaussian-sum", 0.9, 0.5, -200, 200}, {"none", 0.1, -0.5, -0.8, -0.2}};
    std::string svg = scatterSvg(points, "mean FLIP");
    EXPECT_EQ(count(svg, "class=\"clip\""), 2);
    EXPECT_NE(svg.find("interval continues to 200.00 JOD"), std::string::npos);
    EXPECT_NE(svg.find("text-anchor=\"end\">gaussian-sum</text>"), std::string::npos) << svg;
    EXPECT_NE(svg.find("class=\"point\">none</text>"), std::string::npos);
}

TEST(ReportPlots, ScatterLabelsDoNotOverlap) {
    // The demo's patches block: gaussian-sum and separable 0.17 JOD apart on x and 0.02 on y. Each label's box (10 px
    // high, at most 6 px a character at the labels' 10 px font) must not overlap another's.
    std::vector<ScatterPoint> points = {{"bleed-patches-none", 0.0, -0.13, -0.42, 0.16},
                                        {"bleed-patches-gaussian-sum", -1.07, -1.01, -1.29, -0.72},
                                        {"bleed-patches-separable", -0.90, -0.99, -1.24, -0.74},
                                        {"bleed-patches-artistic", -0.35, -0.35, -0.61, -0.09},
                                        {"bleed-patches-pscbf", -1.83, -1.68, -1.97, -1.39}};
    ScatterOptions options;
    options.identity = true;
    const std::string svg = scatterSvg(points, "predicted", options);
    struct Box {
        double left, right, y;
    };
    std::vector<Box> boxes;
    const std::regex label(
        R"re(<text x="([-0-9.]+)" y="([-0-9.]+)" class="point"( text-anchor="end")?>([^<]*)</text>)re");
    for (auto it = std::sregex_iterator(svg.begin(), svg.end(), label); it != std::sregex_iterator(); ++it) {
        const double x = std::stod((*it)[1]), width = 6.0 * double((*it)[4].length());
        boxes.push_back({(*it)[3].matched ? x - width : x, (*it)[3].matched ? x : x + width, std::stod((*it)[2])});
        EXPECT_GE(boxes.back().y, 14.0 + 8.0) << (*it)[4];
        EXPECT_LE(boxes.back().y, 212.0) << (*it)[4];
    }
    ASSERT_EQ(boxes.size(), points.size()) << svg;
    for (std::size_t i = 0; i < boxes.size(); ++i)
        for (std::size_t j = i + 1; j < boxes.size(); ++j) {
            const bool sideBySide = boxes[i].right <= boxes[j].left || boxes[j].right <= boxes[i].left;
            EXPECT_TRUE(sideBySide || std::abs(boxes[i].y - boxes[j].y) >= 10.0)
                << points[i].label << " and " << points[j].label << " overlap\n"
                << svg;
        }
}

TEST(ReportPlots, NumbersNeverShowNan) {
    EXPECT_EQ(formatNumber(NAN, 2), "\u2014");
    EXPECT_EQ(formatNumber(std::numeric_limits<double>::infinity(), 2), "\u2014");
    EXPECT_EQ(formatNumber(-0.001, 2), "0.00");
    EXPECT_EQ(formatNumber(-1.234, 2), "\u22121.23");
    EXPECT_EQ(formatNumber(0.5, 3), "0.500");
}

} // namespace
} // namespace skinlab::report
