#include "analysis/metrics/metrics_report.h"
#include "analysis/metrics/seed_mean.h"
#include "common/csv.h"

#include "common/version.h"

#include <cmath>
#include <map>
#include <cstdio>

namespace skinlab::metrics {

const char* const displayEncodingDescription =
    "linear Rec.709 beauty x exposure, each channel clipped to [0,1], to CIE XYZ (D65, Y_white = 1), to CIELAB "
    "(D65); PSNR and SSIM on the sRGB-encoded clipped values scaled to 0-255";

namespace {

std::string csvNumber(double value) {
    if (std::isnan(value)) return "";
    if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
    char text[40];
    std::snprintf(text, sizeof text, "%.9g", value);
    return text;
}

std::string csvText(const std::string& text) { return csvField(text); }

nlohmann::json jsonNumber(double value) { return std::isfinite(value) ? nlohmann::json(value) : nlohmann::json(); }

nlohmann::json regionJson(const RegionScores& scores) {
    return {{"pixels", scores.pixels},
            {"psnr_db", jsonNumber(scores.psnrDecibels)},
            {"ssim", jsonNumber(scores.ssim)},
            {"delta_e00_mean", jsonNumber(scores.deltaE00Mean)},
            {"delta_e00_p95", jsonNumber(scores.deltaE00P95)},
            {"flip_mean", jsonNumber(scores.flipMean)},
            {"cvvdp_map_mean", jsonNumber(scores.cvvdpMapMean)}};
}

nlohmann::json bandJson(const BandScores& scores) {
    return {{"pixels", scores.pixels},
            {"fraction_of_image", jsonNumber(scores.fractionOfImage)},
            {"fraction_of_skin", jsonNumber(scores.fractionOfSkin)},
            {"delta_e00_mean", jsonNumber(scores.deltaE00Mean)},
            {"delta_e00_p95", jsonNumber(scores.deltaE00P95)},
            {"flip_mean", jsonNumber(scores.flipMean)},
            {"cvvdp_map_mean", jsonNumber(scores.cvvdpMapMean)},
            {"excess", jsonNumber(scores.excess)},
            {"leak_energy", jsonNumber(scores.leakEnergy)}};
}

} // namespace

std::string metricsCsv(const std::vector<ComparisonRecord>& records) {
    std::string out = "reference,test,block,width,height,sss_radius_mm,mm_per_unit,support_radius_world,f_px,cvvdp_jod";
    for (const char* region : {"image", "skin"})
        for (const char* field :
             {"pixels", "psnr_db", "ssim", "delta_e00_mean", "delta_e00_p95", "flip_mean", "cvvdp_map_mean"})
            out += std::string(",") + region + "_" + field;
    for (Band band : allBands)
        for (const char* field : {"pixels", "fraction_of_image", "fraction_of_skin", "delta_e00_mean", "delta_e00_p95",
                                  "flip_mean", "cvvdp_map_mean", "excess", "leak_energy"})
            out += "," + std::string(bandName(band)) + "_" + field;
    out += ",heatmap,flip_heatmap,cvvdp_heatmap,bands_measured\n";
    for (const ComparisonRecord& record : records) {
        out += csvText(record.job.referenceName) + "," + csvText(record.job.testName) + "," + csvText(record.job.block);
        out += "," + std::to_string(record.width) + "," + std::to_string(record.height);
        for (double v : {record.sssRadiusMillimetres, record.millimetresPerUnit, record.geometry.supportRadiusWorld,
                         record.geometry.focalLengthPixels, record.cvvdpJod})
            out += "," + csvNumber(v);
        for (const RegionScores* region : {&record.image, &record.skin}) {
            out += "," + std::to_string(region->pixels);
            for (double v : {region->psnrDecibels, region->ssim, region->deltaE00Mean, region->deltaE00P95,
                             region->flipMean, region->cvvdpMapMean})
                out += "," + csvNumber(v);
        }
        for (const BandScores& band : record.bands) {
            out += "," + std::to_string(band.pixels);
            for (double v : {band.fractionOfImage, band.fractionOfSkin, band.deltaE00Mean, band.deltaE00P95,
                             band.flipMean, band.cvvdpMapMean, band.excess, band.leakEnergy})
                out += "," + csvNumber(v);
        }
        out += "," + csvText(record.heatmap) + "," + csvText(record.flipHeatmap) + "," + csvText(record.cvvdpHeatmap) +
               "," + (record.bandsMeasured ? "1" : "0") + "\n";
    }
    return out;
}

nlohmann::json metricsJson(const std::vector<ComparisonRecord>& records, const ReportSettings& settings,
                           const std::vector<std::string>& blocksWithoutReference) {
    nlohmann::json comparisons = nlohmann::json::array();
    std::map<std::filesystem::path, nlohmann::json> truths; // what each reference is as a truth, read once
    for (const ComparisonRecord& record : records) {
        auto truth = truths.find(record.job.referencePath);
        if (truth == truths.end())
            truth = truths.emplace(record.job.referencePath, describeTruth(record.job.referencePath)).first;
        nlohmann::json bands = nlohmann::json::object();
        for (Band band : allBands) bands[std::string(bandName(band))] = bandJson(record.bands[size_t(band)]);
        comparisons.push_back({
            {"reference",
             {{"name", record.job.referenceName},
              {"path", record.job.referencePath.string()},
              {"truth", truth->second}}},
            {"test",
             {{"name", record.job.testName}, {"path", record.job.testPath.string()}, {"factors", record.job.factors}}},
            {"block", record.job.block},
            {"width", record.width},
            {"height", record.height},
            {"sss_radius_mm", record.sssRadiusMillimetres},
            {"mm_per_unit", record.millimetresPerUnit},
            {"support_radius_world", record.geometry.supportRadiusWorld},
            {"f_px", record.geometry.focalLengthPixels},
            {"cvvdp_jod", jsonNumber(record.cvvdpJod)},
            {"image", regionJson(record.image)},
            {"bands_measured", record.bandsMeasured},
            {"skin", record.bandsMeasured ? regionJson(record.skin) : nlohmann::json()},
            {"bands", record.bandsMeasured ? bands : nlohmann::json()},
            {"heatmap", record.heatmap.empty() ? nlohmann::json() : nlohmann::json(record.heatmap)},
            {"flip_heatmap", record.flipHeatmap.empty() ? nlohmann::json() : nlohmann::json(record.flipHeatmap)},
            {"cvvdp_heatmap", record.cvvdpHeatmap.empty() ? nlohmann::json() : nlohmann::json(record.cvvdpHeatmap)},
            {"heatmap_scale", record.heatmap.empty() ? nlohmann::json()
                                                     : nlohmann::json{{"delta_e00", record.heatmapMax},
                                                                      {"flip", record.flipHeatmapMax},
                                                                      {"cvvdp", record.cvvdpHeatmapMax}}},
        });
    }
    const char* shown = settings.presented ? "the presented PNGs (files.png: what observers see), sRGB-decoded"
                                           : "the renders x exposure";
    return {{"format", "skinlab-metrics"},
            {"version", 1},
            {"skinlab_version", version()},
            {"settings",
             {{"exposure", settings.exposure},
              {"viewing",
               {{"display", settings.display.name},
                {"pixels_per_degree", settings.display.pixelsPerDegree},
                {"source", settings.displaySource},
                {"note", "one viewing geometry: FLIP and ColorVideoVDP at these pixels per degree"}}},
              {"display_referred",
               {{"scores", "delta_e00, psnr_db, ssim, flip_mean, cvvdp_jod, cvvdp_map_mean"}, {"input", shown}}},
              {"linear", {{"scores", "leak_energy"}, {"input", "the linear EXR renders x exposure, unclipped"}}},
              {"display_encoding", displayEncodingDescription},
              {"skin_mask_threshold", 0.5},
              {"percentile", "p95 with linear interpolation between order statistics"},
              {"heatmap_max_delta_e00", settings.heatmapMax > 0.0 ? nlohmann::json(settings.heatmapMax)
                                                                  : nlohmann::json("per map (heatmap_scale)")},
              {"flip",
               {{"variant", "LDR-FLIP (Andersson et al. 2020)"},
                {"pixels_per_degree", settings.pixelsPerDegree},
                {"input", settings.presented ? "the presented PNGs, sRGB-decoded to linear [0,1]"
                                             : "linear RGB x exposure, clamped to [0,1]"}}},
              {"cvvdp",
               {{"variant", "ColorVideoVDP v0.5.6 parameters (Mantiuk et al. 2024), still image"},
                {"display", settings.display.name},
                {"display_description", settings.display.description},
                {"pixels_per_degree", settings.display.pixelsPerDegree},
                {"peak_luminance", settings.display.peakLuminance},
                {"black_level", settings.display.blackLevel()},
                {"reflected_level", settings.display.reflectedLevel()},
                {"eotf", settings.display.eotf},
                {"input", settings.presented
                              ? "the presented PNGs, sRGB-decoded, as the display's relative value (1 = peak)"
                              : "linear Rec.709 RGB x exposure as the display's relative value (1 = peak)"},
                {"map", "per-pixel JOD loss, 10 - JOD"}}},
              {"encoding", imageEncodingName(settings.encoding)}}},
            {"blocks_without_reference", blocksWithoutReference},
            {"comparisons", comparisons}};
}

} // namespace skinlab::metrics
