// `skinlab stimuli import TABLE -o DIR`: a stimulus set from images made elsewhere (docs/stimuli.md, "Importing
// images from other renderers").
#include "analysis/metrics/cvvdp.h"
#include "cli/commands.h"
#include "cli/options.h"
#include "stimuli/import.h"

#include <cstdio>
#include <memory>

namespace skinlab::cli {

namespace {
struct ImportArguments {
    std::string table;
    std::string output;
    std::string images;
    std::string name;
    bool noContactSheet = false;
    bool noPredict = false;
    DisplayArguments display; // of the predictions: --display and --display-*
};
} // namespace

void registerStimuliImport(CLI::App& stimuli) {
    auto arguments = std::make_shared<ImportArguments>();
    CLI::App* command = stimuli.add_subcommand(
        "import", "Make a stimulus set of images from other renderers or photographs, listed in a CSV/TOML table");
    command->add_option("table", arguments->table, "Table of the images (.csv with a header row, or .toml)")
        ->required();
    command->add_option("-o,--output", arguments->output, "Output folder of the set")->required();
    command->add_option("--images", arguments->images,
                        "Folder the table's file paths are relative to (default: "
                        "the table's folder)");
    command->add_option("--name", arguments->name, "Set name (default: the table's name, else its file name)");
    command->add_flag("--no-contact-sheet", arguments->noContactSheet, "Do not write contact.html / contact.png");
    command->add_flag("--no-predict", arguments->noPredict,
                      "Do not predict each stimulus's visibility against its block's reference (ColorVideoVDP)");
    addDisplayOptions(*command, arguments->display, "Display model of the predictions (default standard_fhd)");
    command->callback([arguments] {
        stimuli::ImportOptions options;
        options.table = arguments->table;
        options.outputDir = arguments->output;
        options.images = arguments->images;
        options.name = arguments->name;
        options.contactSheet = !arguments->noContactSheet;
        options.predict = !arguments->noPredict;
        if (options.predict) options.display = arguments->display.resolve(); // a bad display fails before writing
        const stimuli::ImportSummary summary = stimuli::importStimuli(options);
        std::printf("stimuli: imported set '%s': %zu stimuli in %zu block(s); manifest: %s\n", summary.set.c_str(),
                    summary.stimuli, summary.blocks, summary.manifest.string().c_str());
        if (!summary.contactHtml.empty()) std::printf("contact sheet: %s\n", summary.contactHtml.string().c_str());
        for (const std::string& line : summary.predictions) std::printf("stimuli: predicted: %s\n", line.c_str());
    });
}

} // namespace skinlab::cli
