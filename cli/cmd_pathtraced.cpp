// `skinlab pathtraced fit-profile`: measures the edge response of Cycles' random walk on a flat skin slab and fits
// the per-channel radii that match d'Eon's sum of Gaussians (docs/pathtraced.md, "Matched profiles").
#include "cli/commands.h"
#include "common/error.h"
#include "common/files.h"
#include "renderer/sss/pathtraced_params.h"
#include "renderer/pathtraced/profile_fit.h"

#include <algorithm>
#include <cstdio>
#include <iomanip>
#include <memory>
#include <sstream>
#include <vector>

namespace skinlab::cli {

namespace {

namespace pt = renderer::pathtraced;

struct FitOptions {
    std::string output;
    pt::EdgeMeasurementSettings settings;
    std::vector<double> albedo;
    std::vector<double> albedos;
    std::string radiusModel = "scaled";
    bool reuse = false;
};

// `scale` (optional): the fitted radii at this colour; radius / fitted − 1 is the error as a scale of the profile.
nlohmann::json matchJson(const pt::ProfileMatch& m, const std::array<double, 3>* scale = nullptr) {
    nlohmann::json out = {{"radius_mm", m.radiusMm},
                          {"rms_error", m.rmsError},
                          {"max_error", m.maxError},
                          {"integral_error", m.integralError},
                          {"crossing_0_1_error", m.crossingError}};
    if (scale)
        out["scale_error"] = {m.radiusMm[0] / (*scale)[0] - 1.0, m.radiusMm[1] / (*scale)[1] - 1.0,
                              m.radiusMm[2] / (*scale)[2] - 1.0};
    return out;
}

// The radii pathtraced.radius_model gives at this slab's colour (default radius_mm), per channel.
std::array<double, 3> modelRadii(const std::string& model, const std::array<double, 3>& albedo) {
    pt::PathtracedParams params;
    params.radiusModel = model;
    std::array<double, 3> radius{};
    for (int c = 0; c < 3; ++c)
        radius[static_cast<std::size_t>(c)] = pt::radiusAtAlbedoMm(params, c, albedo[static_cast<std::size_t>(c)]);
    return radius;
}

void printMatch(const char* name, const pt::ProfileMatch& m, const std::array<double, 3>* scale = nullptr) {
    std::printf("%-9s radius %7.3f %7.3f %7.3f  rms %.4f %.4f %.4f  integral %+6.1f%% %+6.1f%% %+6.1f%%  "
                "E=0.1 at %+6.1f%% %+6.1f%% %+6.1f%%",
                name, m.radiusMm[0], m.radiusMm[1], m.radiusMm[2], m.rmsError[0], m.rmsError[1], m.rmsError[2],
                100.0 * m.integralError[0], 100.0 * m.integralError[1], 100.0 * m.integralError[2],
                100.0 * m.crossingError[0], 100.0 * m.crossingError[1], 100.0 * m.crossingError[2]);
    if (scale)
        std::printf("  scale %+6.1f%% %+6.1f%% %+6.1f%%", 100.0 * (m.radiusMm[0] / (*scale)[0] - 1.0),
                    100.0 * (m.radiusMm[1] / (*scale)[1] - 1.0), 100.0 * (m.radiusMm[2] / (*scale)[2] - 1.0));
    std::printf("\n");
}

// One slab colour: the render (or, in a sweep, the one already in `folder`), the fit, and how the constant and
// the albedo-driven radii of [pathtraced] match d'Eon at that colour.
pt::ProfileFit fitOne(pt::EdgeMeasurementSettings settings, const std::filesystem::path& folder, bool reuse) {
    ensureDirectory(folder);
    bool scaled = settings.radiusTable.is_null();
    pt::EdgeResponse response;
    nlohmann::json measurement;
    if (reuse && std::filesystem::exists(folder / "edge_response.csv") &&
        std::filesystem::exists(folder / "profile_fit.json")) {
        // The colour and the radii are the stored measurement's.
        response = pt::readEdgeResponseCsv(folder / "edge_response.csv");
        measurement = nlohmann::json::parse(readFile(folder / "profile_fit.json")).at("measurement");
        settings.albedo = measurement.at("albedo").get<std::array<double, 3>>();
        scaled = !measurement.contains("radius") || !measurement.at("radius").is_object();
        std::printf("reusing %s\n", (folder / "edge_response.csv").string().c_str());
    } else {
        response = pt::measureEdgeResponse(settings);
        measurement = {{"samples", settings.samples},
                       {"seed", settings.seed},
                       {"pixels", settings.pixels},
                       {"rows", settings.rows},
                       {"half_length_mm", settings.halfLengthMm},
                       {"albedo", settings.albedo},
                       {"radius", scaled ? nlohmann::json("1 mm (scale-free)") : settings.radiusTable},
                       {"blender_version", response.blenderVersion},
                       {"render_seconds", response.renderSeconds},
                       {"plateau", response.plateau}};
        std::ostringstream csv;
        csv << std::setprecision(9) << (scaled ? "x_mm_at_radius_1mm" : "x_mm") << ",E_R,E_G,E_B\n";
        for (std::size_t i = 0; i < response.xMm.size(); ++i)
            csv << response.xMm[i] << "," << response.value[0][i] << "," << response.value[1][i] << ","
                << response.value[2][i] << "\n";
        writeFileAtomic(folder / "edge_response.csv", csv.str());
    }
    nlohmann::json out;
    out["measurement"] = measurement;
    out["fit_range_mm"] = 8.0;
    pt::ProfileFit fit;
    std::printf("albedo %.3f %.3f %.3f\n", settings.albedo[0], settings.albedo[1], settings.albedo[2]);
    if (scaled) {
        fit = pt::fitRadii(response, pt::fittedRadiusMm());
        out["radius_mm"] = fit.radiusMm;
        out["rms_error"] = fit.rmsError;
        out["max_error"] = fit.maxError;
        out["previous_radius_mm"] = pt::fittedRadiusMm();
        out["previous_rms_error"] = fit.initialRmsError;
        const pt::ProfileMatch fitted = pt::matchProfile(response, fit.radiusMm);
        const pt::ProfileMatch constant = pt::matchProfile(response, modelRadii("constant", settings.albedo));
        const pt::ProfileMatch albedo = pt::matchProfile(response, modelRadii("albedo", settings.albedo));
        out["fitted"] = matchJson(fitted);
        out["radius_model_constant"] = matchJson(constant, &fit.radiusMm);
        out["radius_model_albedo"] = matchJson(albedo, &fit.radiusMm);
        printMatch("fitted", fitted);
        printMatch("constant", constant, &fit.radiusMm);
        printMatch("albedo", albedo, &fit.radiusMm);
        pt::writeFitPlot(folder / "profile_fit.png", response, fit);
    } else {
        // Rendered at the table's radii: x is in mm, compared with d'Eon as it is (the radii shown are the
        // model's at this colour).
        pt::ProfileMatch table = pt::matchProfile(response, {1.0, 1.0, 1.0});
        table.radiusMm = modelRadii("albedo", settings.albedo);
        out["radius_table"] = matchJson(table);
        printMatch("table", table);
        fit.radiusMm = {1.0, 1.0, 1.0};
        fit.rmsError = table.rmsError;
        fit.maxError = table.maxError;
        pt::writeFitPlot(folder / "profile_fit.png", response, fit);
    }
    writeFileAtomic(folder / "profile_fit.json", out.dump(2) + "\n");
    return fit;
}

// The strip of a sweep's render at grey albedo a (radius 1 mm): the walk is shorter at low albedo, so a shorter
// strip keeps its pixels small against the first 0.1 mm of d'Eon's profile; it still holds E down to < 1e-4.
double sweepHalfLengthMm(double albedo) { return albedo < 0.25 ? 1.5 : albedo < 0.55 ? 2.0 : 3.0; }

void runSweep(const FitOptions& options) {
    const std::filesystem::path folder = options.output;
    ensureDirectory(folder);
    nlohmann::json table = {{"albedo", nlohmann::json::array()},
                            {"radius_mm", {nlohmann::json::array(), nlohmann::json::array(), nlohmann::json::array()}},
                            {"rms_error", {nlohmann::json::array(), nlohmann::json::array(), nlohmann::json::array()}}};
    std::vector<double> albedos = options.albedos;
    std::sort(albedos.begin(), albedos.end());
    for (const double a : albedos) {
        pt::EdgeMeasurementSettings settings = options.settings;
        settings.albedo = {a, a, a};
        settings.halfLengthMm = sweepHalfLengthMm(a);
        char name[32];
        std::snprintf(name, sizeof name, "albedo-%.3f", a);
        const pt::ProfileFit fit = fitOne(settings, folder / name, true);
        table["albedo"].push_back(a);
        for (std::size_t c = 0; c < 3; ++c) {
            table["radius_mm"][c].push_back(fit.radiusMm[c]);
            table["rms_error"][c].push_back(fit.rmsError[c]);
        }
    }
    // The table's values: ln r smoothed along the albedo by a cubic (the fits' noise is a few per cent at 1024
    // samples, the dependence on albedo smooth).
    if (albedos.size() >= 4) {
        table["smoothed_radius_mm"] = nlohmann::json::array();
        table["smoothing_rms_log_residual"] = nlohmann::json::array();
        for (std::size_t c = 0; c < 3; ++c) {
            double residual = 0.0;
            table["smoothed_radius_mm"].push_back(
                pt::smoothRadii(albedos, table["radius_mm"][c].get<std::vector<double>>(), 3, &residual));
            table["smoothing_rms_log_residual"].push_back(residual);
        }
    }
    table["measurement"] = {{"samples", options.settings.samples},
                            {"seed", options.settings.seed},
                            {"pixels", options.settings.pixels},
                            {"rows", options.settings.rows}};
    writeFileAtomic(folder / "radius_table.json", table.dump(2) + "\n");
    const bool smoothed = table.contains("smoothed_radius_mm");
    std::printf("albedo radius_R radius_G radius_B (mm at width 3 mm)%s\n",
                smoothed ? "  smoothed_R smoothed_G smoothed_B" : "");
    for (std::size_t k = 0; k < table["albedo"].size(); ++k) {
        std::printf("%.3f %.4f %.4f %.4f", table["albedo"][k].get<double>(), table["radius_mm"][0][k].get<double>(),
                    table["radius_mm"][1][k].get<double>(), table["radius_mm"][2][k].get<double>());
        if (smoothed)
            std::printf("  %.4f %.4f %.4f", table["smoothed_radius_mm"][0][k].get<double>(),
                        table["smoothed_radius_mm"][1][k].get<double>(),
                        table["smoothed_radius_mm"][2][k].get<double>());
        std::printf("\n");
    }
    if (smoothed)
        std::printf("smoothing rms log residual %.4f %.4f %.4f\n", table["smoothing_rms_log_residual"][0].get<double>(),
                    table["smoothing_rms_log_residual"][1].get<double>(),
                    table["smoothing_rms_log_residual"][2].get<double>());
}

void runFit(FitOptions options) {
    if (!options.albedo.empty()) {
        if (options.albedo.size() != 3)
            throwInput("fit-profile", "--albedo",
                       "needs three values R,G,B (got " + std::to_string(options.albedo.size()) + ")");
        for (std::size_t c = 0; c < 3; ++c) options.settings.albedo[c] = options.albedo[c];
    }
    if (!options.albedos.empty()) {
        if (!options.albedo.empty()) throwInput("fit-profile", "--albedos", "cannot be combined with --albedo");
        if (options.radiusModel != "scaled")
            throwInput("fit-profile", "--albedos", "fits radii at radius 1 mm: cannot be combined with --radius-model");
        runSweep(options);
        return;
    }
    if (options.radiusModel == "albedo") {
        // The table as radius_model = "albedo" writes it for Cycles (mm: width 3 mm, mm_per_unit 1).
        pt::PathtracedParams params;
        const pt::AlbedoRadiusTable& table = pt::albedoRadiusTable();
        nlohmann::json radius = nlohmann::json::array();
        for (int c = 0; c < 3; ++c) {
            nlohmann::json channel = nlohmann::json::array();
            for (const double a : table.albedo) channel.push_back(pt::radiusAtAlbedoMm(params, c, a));
            radius.push_back(channel);
        }
        options.settings.radiusTable = {{"albedo", table.albedo}, {"radius", radius}};
    }
    fitOne(options.settings, options.output, options.reuse);
}

} // namespace

void registerPathtraced(CLI::App& app) {
    CLI::App* pathtraced = app.add_subcommand("pathtraced", "Blender Cycles ground truth: tools (docs/pathtraced.md)");
    pathtraced->require_subcommand(1);
    auto options = std::make_shared<FitOptions>();
    CLI::App* fit = pathtraced->add_subcommand(
        "fit-profile", "Fit Cycles' random-walk radii to d'Eon's sum of Gaussians (edge response on a skin slab)");
    fit->add_option("-o,--output", options->output,
                    "Output folder (profile_fit.json, profile_fit.png, edge_response.csv)")
        ->required();
    fit->add_option("--samples", options->settings.samples, "Cycles samples per pixel")->check(CLI::Range(1, 1 << 20));
    fit->add_option("--seed", options->settings.seed, "Cycles seed")->check(CLI::Range(0, 2147483647));
    fit->add_option("--pixels", options->settings.pixels, "Pixels along the strip (even)")
        ->check(CLI::Range(16, 65536));
    fit->add_option("--rows", options->settings.rows, "Rows across the strip (averaged; at least 4)")
        ->check(CLI::Range(4, 4096));
    fit->add_option("--half-length-mm", options->settings.halfLengthMm, "Half length of the strip at radius 1 mm")
        ->check(CLI::Range(1.0, 1000.0));
    fit->add_option("--albedo", options->albedo, "Subsurface colour of the slab R,G,B (default: the built-in skin)")
        ->delimiter(',')
        ->check(CLI::Range(0.0, 1.0));
    fit->add_option("--albedos", options->albedos,
                    "Sweep: grey slab colours a1,a2,... (one render each, radius table in radius_table.json; an "
                    "albedo whose folder already holds a render is not rendered again; the strip's half length "
                    "follows the albedo: 1.5 mm below 0.25, 2 mm below 0.55, else 3 mm)")
        ->delimiter(',')
        ->check(CLI::Range(0.0, 1.0));
    fit->add_option("--radius-model", options->radiusModel,
                    "\"scaled\" (default: radius 1 mm, fitted) or \"albedo\" (render at the radii of "
                    "pathtraced.radius_model = \"albedo\" through Cycles' shader and compare in mm)")
        ->check(CLI::IsMember({"scaled", "albedo"}));
    fit->add_flag("--reuse", options->reuse,
                  "Read the edge response from the output folder (a previous run's edge_response.csv and "
                  "profile_fit.json) instead of rendering: fits and compares again");
    fit->add_option("--blender", options->settings.blender, "The Blender program");
    fit->add_option("--threads", options->settings.threads, "Cycles threads (0: all cores)")
        ->check(CLI::Range(0, 1024));
    fit->callback([options] { runFit(*options); });
}

} // namespace skinlab::cli
