// `skinlab pathtraced fit-profile`: measures the edge response of Cycles' random walk on a flat skin slab and fits
// the per-channel radii that match d'Eon's sum of Gaussians (docs/pathtraced.md, "Matched profiles").
#include "cli/commands.h"
#include "common/error.h"
#include "common/files.h"
#include "renderer/sss/pathtraced_params.h"
#include "renderer/pathtraced/profile_fit.h"

#include <cstdio>
#include <memory>
#include <sstream>

namespace skinlab::cli {

namespace {

namespace pt = renderer::pathtraced;

struct FitOptions {
    std::string output;
    pt::EdgeMeasurementSettings settings;
};

void runFit(const FitOptions& options) {
    const std::filesystem::path folder = options.output;
    ensureDirectory(folder);
    const pt::EdgeResponse response = pt::measureEdgeResponse(options.settings);
    const pt::ProfileFit fit = pt::fitRadii(response, pt::fittedRadiusMm());

    nlohmann::json out;
    out["radius_mm"] = fit.radiusMm;
    out["rms_error"] = fit.rmsError;
    out["max_error"] = fit.maxError;
    out["previous_radius_mm"] = pt::fittedRadiusMm();
    out["previous_rms_error"] = fit.initialRmsError;
    out["fit_range_mm"] = 8.0;
    out["plateau"] = response.plateau;
    out["measurement"] = {{"samples", options.settings.samples},
                          {"seed", options.settings.seed},
                          {"pixels", options.settings.pixels},
                          {"rows", options.settings.rows},
                          {"half_length_mm", options.settings.halfLengthMm},
                          {"albedo", options.settings.albedo},
                          {"blender_version", response.blenderVersion},
                          {"render_seconds", response.renderSeconds}};
    writeFileAtomic(folder / "profile_fit.json", out.dump(2) + "\n");

    std::ostringstream csv;
    csv << "x_mm_at_radius_1mm,E_R,E_G,E_B\n";
    for (std::size_t i = 0; i < response.xMm.size(); ++i)
        csv << response.xMm[i] << "," << response.value[0][i] << "," << response.value[1][i] << ","
            << response.value[2][i] << "\n";
    writeFileAtomic(folder / "edge_response.csv", csv.str());
    pt::writeFitPlot(folder / "profile_fit.png", response, fit);
    std::printf("radius_mm %.4f %.4f %.4f\nrms_error %.5f %.5f %.5f\n", fit.radiusMm[0], fit.radiusMm[1],
                fit.radiusMm[2], fit.rmsError[0], fit.rmsError[1], fit.rmsError[2]);
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
    fit->add_option("--blender", options->settings.blender, "The Blender program");
    fit->add_option("--threads", options->settings.threads, "Cycles threads (0: all cores)")
        ->check(CLI::Range(0, 1024));
    fit->callback([options] { runFit(*options); });
}

} // namespace skinlab::cli
