#pragma once
// Each subcommand lives in its own cmd_*.cpp and registers itself on the CLI11 app.
// Callbacks throw skinlab::InputError for bad input (exit 2) and skinlab::RuntimeError for failures (exit 1).
#include <CLI/CLI.hpp>

namespace skinlab::cli {
void registerRender(CLI::App& app);
void registerKernel(CLI::App& app);
void registerStimuli(CLI::App& app);
void registerStudy(CLI::App& app);
void registerAnalyze(CLI::App& app);
void registerReport(CLI::App& app);
void registerPathtraced(CLI::App& app);
void registerMethods(CLI::App& app);
void registerTune(CLI::App& app);
} // namespace skinlab::cli

namespace skinlab::cli {
// `skinlab analyze` sub-subcommands, registered by cmd_analyze.cpp on the `analyze` subcommand.
void registerAnalyzeScale(CLI::App& analyze);     // scale, validate
void registerAnalyzeMetrics(CLI::App& analyze);   // metrics
void registerAnalyzeSeedMean(CLI::App& analyze);  // seed-mean
void registerAnalyzeAgreement(CLI::App& analyze); // agreement
// `skinlab stimuli import`, registered by cmd_stimuli.cpp on the `stimuli` subcommand.
void registerStimuliImport(CLI::App& stimuli);
} // namespace skinlab::cli
