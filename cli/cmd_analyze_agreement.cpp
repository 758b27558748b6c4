// `skinlab analyze agreement STUDY.db --metrics DIR -o OUT`: image metrics against the study's JOD scale
// (docs/metrics.md, "Metrics against perception").
#include "analysis/agreement/metric_agreement.h"
#include "analysis/scaling/responses.h"
#include "cli/commands.h"
#include "common/error.h"
#include "common/files.h"
#include "experiments/study_store.h"

#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

#include <cstdio>
#include <filesystem>
#include <memory>

namespace skinlab::cli {

void registerAnalyzeAgreement(CLI::App& analyze) {
    struct Arguments {
        std::string study, metrics, output;
        int bootstrap = 1000;
        std::uint64_t seed = 1;
    };
    auto arguments = std::make_shared<Arguments>();
    CLI::App* command = analyze.add_subcommand(
        "agreement", "Image metrics against the JOD scale: Pearson/Spearman with bootstrap intervals over observers, "
                     "share of significant pairs each metric orders correctly (docs/metrics.md)");
    command->add_option("study", arguments->study, "Study file (study.db)")->required();
    command
        ->add_option("--metrics", arguments->metrics,
                     "Folder with metrics.json from `skinlab analyze metrics --stimuli` on the study's stimulus set")
        ->required();
    command->add_option("-o,--output", arguments->output, "Output folder: agreement.json, agreement.csv")->required();
    command->add_option("--bootstrap", arguments->bootstrap, "Bootstrap resamples (default 1000)")
        ->check(CLI::Range(100, 100000));
    command->add_option("--seed", arguments->seed, "Bootstrap seed (default 1)");
    command->callback([arguments] {
        namespace fs = std::filesystem;
        namespace scaling = analysis::scaling;
        namespace agreement = analysis::agreement;
        const fs::path metricsFile = fs::path(arguments->metrics) / "metrics.json";
        if (!fs::is_regular_file(metricsFile)) throwInput(metricsFile.string(), "", "file not found");
        nlohmann::json metricsJson;
        try {
            metricsJson = nlohmann::json::parse(readFile(metricsFile));
        } catch (const nlohmann::json::exception& e) {
            throwInput(metricsFile.string(), "", std::string("not valid JSON (") + e.what() + ")");
        }
        if (!fs::is_regular_file(arguments->study)) throwInput(arguments->study, "", "file not found");
        std::map<std::string, std::pair<std::string, std::string>> conditionOfStimulus;
        {
            experiments::StudyStore store(arguments->study);
            const experiments::StudyDefinition& definition = store.definition();
            for (const experiments::StudyBlock& block : definition.blocks)
                for (std::size_t c = 0; c < block.conditions.size(); ++c)
                    conditionOfStimulus[definition.stimuli[static_cast<std::size_t>(block.conditionStimulus[c])].id] = {
                        block.name, block.conditions[c]};
        }
        auto metrics = agreement::conditionMetricsFromJson(metricsJson, metricsFile.string(), conditionOfStimulus);
        if (metrics.empty())
            throwInput(metricsFile.string(), "comparisons",
                       "no comparison is a stimulus of the study " + arguments->study);
        scaling::AnalysisOptions options;
        options.bootstrap.samples = arguments->bootstrap;
        options.bootstrap.seed = arguments->seed;
        const scaling::Dataset dataset = scaling::buildDataset(scaling::readResponses(arguments->study), {});
        const scaling::Analysis analysis = scaling::analyzeDataset(dataset, options);
        agreement::AgreementOptions agreementOptions;
        agreementOptions.samples = arguments->bootstrap;
        agreementOptions.seed = arguments->seed;
        auto result = agreement::computeAgreement(dataset, analysis, metrics, options.fit, agreementOptions);
        for (const std::string& warning : result.warnings) spdlog::warn("{}", warning);
        ensureDirectory(arguments->output);
        writeFileAtomic(fs::path(arguments->output) / "agreement.csv", agreement::agreementCsv(result));
        writeFileAtomic(fs::path(arguments->output) / "agreement.json",
                        agreement::agreementJson(result).dump(2) + "\n");
        for (const agreement::MetricAgreement& row : result.rows)
            if (row.metric.key == "image.flip_mean" || row.metric.key == "image.delta_e00_mean")
                std::printf("%s  %-22s r = %+.3f [%+.3f, %+.3f]  rho = %+.3f  pairs %d/%d\n", row.block.c_str(),
                            row.metric.label.c_str(), row.pearson, row.pearsonLow, row.pearsonHigh, row.spearman,
                            row.predictedPairs, row.significantPairs);
        std::printf("wrote %s\n", (fs::path(arguments->output) / "agreement.json").c_str());
    });
}

} // namespace skinlab::cli
