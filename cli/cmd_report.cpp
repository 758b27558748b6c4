// `skinlab report STUDY.db -o REPORT/`: the study report, HTML and PDF (docs/report.md).
#include "cli/commands.h"
#include "cli/options.h"
#include "report/study_report.h"

#include <spdlog/spdlog.h>

#include <cstdio>
#include <memory>

namespace skinlab::cli {

void registerReport(CLI::App& app) {
    struct Arguments {
        std::string study, stimuli, metrics, output;
        report::ReportOptions options;
        bool noPdf = false;
        DisplayArguments display; // --display, --ppd, --display-* (cli/options.h)
    };
    auto arguments = std::make_shared<Arguments>();
    CLI::App* command = app.add_subcommand(
        "report", "One study report (HTML + PDF): design, participants, stimuli, JOD scale, objective errors, "
                  "metrics against perception, findings (docs/report.md)");
    command->add_option("study", arguments->study, "Study file (study.db)")->required();
    command->add_option("--stimuli", arguments->stimuli, "Stimulus folder (default: the one recorded in the study)");
    command->add_option("--metrics", arguments->metrics,
                        "Folder with metrics.json from `skinlab analyze metrics --stimuli` (default: computed against "
                        "the set's references)");
    command->add_option("-o,--output", arguments->output, "Report folder: index.html, report.pdf, images, tables")
        ->required();
    command->add_option("--bootstrap", arguments->options.bootstrapSamples, "Bootstrap resamples (default 1000)")
        ->check(CLI::Range(100, 100000));
    command->add_option("--seed", arguments->options.seed, "Bootstrap seed (default 1)");
    addDisplayOptions(*command, arguments->display,
                      "Display model of the metrics computed here, the viewing geometry of FLIP and ColorVideoVDP "
                      "(default: the display of the set's predictions, else standard_fhd)");
    command->add_option("--chromium", arguments->options.chromium,
                        "Chromium executable for the PDF (default chromium)");
    command->add_flag("--no-pdf", arguments->noPdf, "Write only the HTML page");
    command->callback([arguments] {
        report::ReportOptions options = arguments->options;
        options.study = arguments->study;
        options.stimuli = arguments->stimuli;
        options.metrics = arguments->metrics;
        options.output = arguments->output;
        options.pdf = !arguments->noPdf;
        (void)arguments->display.resolve(); // option errors before any file is read
        options.display = arguments->display.name;
        options.displayChanges = arguments->display.changes();
        report::ReportSummary summary = report::writeStudyReport(options);
        std::printf("wrote %s%s%s\n", summary.html.c_str(), summary.pdf.empty() ? "" : " and ",
                    summary.pdf.empty() ? "" : summary.pdf.c_str());
    });
}

} // namespace skinlab::cli
