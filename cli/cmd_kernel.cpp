// `skinlab kernel`: prints the SSS kernel a method actually uses (taps: offset in mm on the surface + RGB weight),
// optionally with per-channel statistics (RMS width, energy beyond a distance). docs/methods.md.
#include "cli/commands.h"
#include "common/error.h"
#include "common/files.h"
#include "common/spec.h"
#include "renderer/sss/kernel.h"
#include "renderer/sss/method.h"
#include "renderer/sss/sss_params.h"

#include <cmath>
#include <cstdio>
#include <memory>
#include <sstream>

namespace skinlab::cli {

namespace {

namespace sss = renderer::sss;

struct KernelOptions {
    std::string method;
    int samples = 0;
    std::string profile;
    std::string material;
    std::string sampling;
    double widthMm = 0.0;
    std::vector<std::string> overrides;
    std::string format = "json";
    bool statistics = false;
    double beyondMm = 2.0;
    std::string output;
};

// Errors name "command line" as the file: `skinlab: error: command line: sss.samples: 20 is even; ...`.
constexpr const char* kSource = "command line";

sss::SssParams resolveParams(const KernelOptions& options) {
    toml::table root;
    auto set = [&](const std::string& assignment) { applyOverride(root, assignment, kSource); };
    set("sss.method=\"" + options.method + "\"");
    for (const auto& o : options.overrides) set(o);
    if (options.samples != 0) set("sss.samples=" + std::to_string(options.samples));
    if (!options.profile.empty()) set("sss.profile=\"" + options.profile + "\"");
    if (!options.material.empty()) set("sss.material=\"" + options.material + "\"");
    if (!options.sampling.empty()) set("sss.sampling=\"" + options.sampling + "\"");
    if (options.widthMm != 0.0) {
        std::ostringstream value;
        value.precision(17);
        value << "sss.width_mm=" << options.widthMm;
        set(value.str());
    }
    const SpecReader reader(root, kSource);
    sss::SssParams params = sss::readSssParams(reader);
    reader.finish(); // a --set outside [sss] is an unknown key
    return params;
}

nlohmann::json statisticsJson(const sss::SssParams& params, const sss::Kernel& kernel, double beyondMm) {
    nlohmann::json out;
    out["beyond_mm"] = beyondMm;
    out["stages"] = nlohmann::json::array();
    for (const auto& stage : kernel.stages) {
        const auto stats = sss::tapStatistics(stage.taps, beyondMm);
        out["stages"].push_back({{"rms_width_mm", stats.rmsWidthMm}, {"energy_beyond", stats.energyBeyond}});
    }
    // The continuous marginal the taps discretise (a method with taps and a physical profile), at the same surface
    // scale (width_mm / 3).
    if (const auto marginal = sss::methodInfo(params.method).model->profileMarginal(params);
        marginal && !kernel.stages.empty()) {
        const double scale = sss::profileScale(params.widthMm);
        std::array<double, 3> rms{}, beyond{};
        for (int c = 0; c < 3; ++c) {
            rms[c] = std::sqrt(marginal->secondMoment(c)) * scale;
            beyond[c] = marginal->tailEnergy(c, beyondMm / scale);
        }
        out["continuous"] = {{"source", marginal->description()}, {"rms_width_mm", rms}, {"energy_beyond", beyond}};
    }
    return out;
}

std::string formatCsv(const sss::Kernel& kernel) {
    std::ostringstream csv;
    csv.precision(9);
    csv << "stage,offset_mm,weight_r,weight_g,weight_b,accumulate_r,accumulate_g,accumulate_b\n";
    for (size_t s = 0; s < kernel.stages.size(); ++s) {
        const auto& stage = kernel.stages[s];
        for (const auto& tap : stage.taps)
            csv << s << ',' << tap.offsetMm << ',' << tap.weight[0] << ',' << tap.weight[1] << ',' << tap.weight[2]
                << ',' << stage.accumulate[0] << ',' << stage.accumulate[1] << ',' << stage.accumulate[2] << '\n';
    }
    return csv.str();
}

void runKernel(const KernelOptions& options) {
    const sss::SssParams params = resolveParams(options);
    const sss::Kernel kernel = sss::makeKernel(params);
    std::string text;
    if (options.format == "csv") {
        if (options.statistics) throw InputError("--stats: only with --format json");
        text = formatCsv(kernel);
    } else {
        nlohmann::json out;
        out["params"] = params.toJson();
        out["kernel"] = kernel.toJson();
        if (options.statistics) out["statistics"] = statisticsJson(params, kernel, options.beyondMm);
        text = out.dump(2) + "\n";
    }
    if (options.output.empty()) std::fputs(text.c_str(), stdout);
    else writeFileAtomic(options.output, text);
}

} // namespace

void registerKernel(CLI::App& app) {
    auto options = std::make_shared<KernelOptions>();
    CLI::App* kernel = app.add_subcommand(
        "kernel", "Print the SSS kernel a method actually uses: taps (offset in mm on the surface, RGB weight)");
    std::string names;
    for (const std::string& name : sss::methodNames()) names += (names.empty() ? "" : " | ") + name;
    kernel
        ->add_option("--method", options->method,
                     names + " (`skinlab methods`; pscbf: its broad Gaussian stage, the pass adds the spike; "
                             "reference, pathtraced and eevee: no taps)")
        ->required();
    kernel->add_option("--samples", options->samples,
                       "Taps per 1-D pass, odd, 3…101 (sss.samples; default 21, pscbf 13)");
    kernel->add_option("--profile", options->profile, "deon | burley | file:PATH.bn (sss.profile; default deon)");
    kernel->add_option("--material", options->material,
                       "skin | skin1 | skin2 | marble | apple | ketchup | wholemilk (sss.material; default skin)");
    kernel->add_option("--sampling", options->sampling, "quadratic | importance (sss.sampling; default quadratic)");
    kernel->add_option("--width-mm", options->widthMm, "Kernel width in mm, 3 = physical scale (sss.width_mm)");
    kernel->add_option("--set", options->overrides, "Any [sss] key: sss.key=value (repeatable)")
        ->type_name("KEY=VALUE")
        ->take_all();
    kernel->add_option("--format", options->format, "json or csv")->check(CLI::IsMember({"json", "csv"}));
    kernel->add_flag(
        "--stats", options->statistics,
        "Add per-channel RMS width and energy beyond --beyond-mm, per stage and for the continuous marginal");
    kernel->add_option("--beyond-mm", options->beyondMm, "Distance for --stats' tail energy, mm (default 2)")
        ->check(CLI::Range(0.0, 1000.0));
    kernel->add_option("-o,--output", options->output, "Write to this file (atomically) instead of stdout");
    kernel->callback([options] { runKernel(*options); });
}

} // namespace skinlab::cli
