#include "cli/commands.h"

namespace skinlab::cli {
void registerAnalyze(CLI::App& app) {
    CLI::App* analyze = app.add_subcommand("analyze", "Perceptual scaling of 2AFC responses; image-difference metrics");
    analyze->require_subcommand(1);
    registerAnalyzeScale(*analyze);
    registerAnalyzeMetrics(*analyze);
    registerAnalyzeSeedMean(*analyze);
    registerAnalyzeAgreement(*analyze);
}
} // namespace skinlab::cli
