// `skinlab stimuli build|list|merge|contact`: stimulus sets (docs/stimuli.md).
#include "cli/commands.h"
#include "common/error.h"
#include "stimuli/build.h"
#include "stimuli/contact_sheet.h"
#include "stimuli/merge.h"
#include "stimuli/output_folder.h"

#include <cstdio>
#include <iostream>
#include <memory>

namespace skinlab::cli {

namespace {

struct StimuliOptions {
    std::string spec;
    std::string output;
    std::string shard;
    int jobs = 1;
    std::string assets;
    std::vector<std::string> overrides;
    bool noContactSheet = false;
    std::string progress = "auto";
    std::vector<std::string> shardDirs;
    std::string format = "text";
};

std::optional<stimuli::Shard> shardOption(const std::string& text) {
    if (text.empty()) return std::nullopt;
    return stimuli::parseShard(text);
}

void runBuild(const StimuliOptions& o) {
    stimuli::BuildOptions options;
    options.spec = o.spec;
    options.specOverrides = o.overrides;
    options.outputDir = o.output;
    options.shard = shardOption(o.shard);
    options.jobs = o.jobs;
    options.assetsDir = o.assets;
    options.contactSheet = !o.noContactSheet;
    options.progress = o.progress == "bar"     ? stimuli::BuildOptions::ProgressStyle::bar
                       : o.progress == "lines" ? stimuli::BuildOptions::ProgressStyle::lines
                                               : stimuli::BuildOptions::ProgressStyle::automatic;
    stimuli::BuildSummary summary = stimuli::buildSet(options);
    std::printf("stimuli: %zu stimuli (%zu rendered, %zu unchanged) in %.1f s; manifest: %s\n", summary.stimuli,
                summary.rendered, summary.kept, summary.wallSeconds, summary.manifest.string().c_str());
    if (!summary.contactHtml.empty()) std::printf("contact sheet: %s\n", summary.contactHtml.string().c_str());
}

void runList(const StimuliOptions& o) {
    stimuli::BuildPlan plan = stimuli::planBuild(o.spec, o.overrides, shardOption(o.shard), o.assets);
    if (o.format == "json") {
        nlohmann::json out = nlohmann::json::array();
        for (size_t i = 0; i < plan.selected.size(); ++i)
            out.push_back(stimuli::stimulusEntry(plan.selected[i], plan.resolved[i]));
        std::cout << out.dump(2) << "\n";
        return;
    }
    std::printf("set %s: %zu stimuli%s\n", plan.spec.name.c_str(), plan.selected.size(),
                o.shard.empty() ? "" : (" (shard " + o.shard + " of " + std::to_string(plan.all.size()) + ")").c_str());
    for (const auto& s : plan.selected) {
        std::string overrides;
        for (const auto& a : s.overrides) overrides += " " + a;
        std::printf("%s\t%s\t%s\tscene=%s%s\n", s.id.c_str(), s.block.c_str(), s.reference ? "reference" : "-",
                    s.factors.front().second.value.c_str(), overrides.c_str());
    }
}

void runMerge(const StimuliOptions& o) {
    std::vector<std::filesystem::path> dirs(o.shardDirs.begin(), o.shardDirs.end());
    stimuli::MergeSummary summary = stimuli::mergeShards(dirs, o.output, !o.noContactSheet);
    std::printf("stimuli: merged %zu shard(s), %zu stimuli; manifest: %s\n", dirs.size(), summary.stimuli,
                summary.manifest.string().c_str());
    if (!summary.contactHtml.empty()) std::printf("contact sheet: %s\n", summary.contactHtml.string().c_str());
}

void runContact(const StimuliOptions& o) {
    std::optional<stimuli::Manifest> manifest = stimuli::readManifest(o.output);
    if (!manifest) throwInput(o.output, "", "holds no stimulus set (no manifest.json)");
    stimuli::ContactSheetFiles files = stimuli::writeContactSheet(o.output, *manifest);
    std::printf("contact sheet: %s\n", files.html.string().c_str());
}

} // namespace

void registerStimuli(CLI::App& app) {
    auto options = std::make_shared<StimuliOptions>();
    CLI::App* stimuli = app.add_subcommand("stimuli", "Build, list and merge stimulus sets (docs/stimuli.md)");
    stimuli->require_subcommand(1);

    auto specOptions = [&](CLI::App* cmd) {
        cmd->add_option("spec", options->spec, "Stimulus-set spec (TOML), e.g. stimuli/specs/demo.toml")->required();
        cmd->add_option("--shard", options->shard, "Only slice i of n (1-based), e.g. 2/8");
        cmd->add_option("--assets", options->assets, "Folder of shared assets (default: $SKINLAB_ASSETS)");
        cmd->add_option("--set", options->overrides, "Override a spec value: key=value (repeatable)");
    };

    CLI::App* build = stimuli->add_subcommand("build", "Render a stimulus set (resumable) into a folder");
    specOptions(build);
    build->add_option("-o,--output", options->output, "Output folder of the set")->required();
    build->add_option("--jobs", options->jobs, "Parallel renderers, one EGL context each (default 1)")
        ->check(CLI::Range(1, 64));
    build->add_flag("--no-contact-sheet", options->noContactSheet, "Do not write contact.html / contact.png");
    build->add_option("--progress", options->progress, "Progress display: auto (bar on a terminal), bar, lines")
        ->check(CLI::IsMember({"auto", "bar", "lines"}));
    build->callback([options] { runBuild(*options); });

    CLI::App* list = stimuli->add_subcommand("list", "Print the stimuli of a spec (checked, not rendered)");
    specOptions(list);
    list->add_option("--format", options->format, "text or json")->check(CLI::IsMember({"text", "json"}));
    list->callback([options] { runList(*options); });

    CLI::App* merge = stimuli->add_subcommand("merge", "Join shard folders of one set into one set folder");
    merge->add_option("shards", options->shardDirs, "Shard folders (built with --shard i/n)")->required();
    merge->add_option("-o,--output", options->output, "Output folder of the merged set")->required();
    merge->add_flag("--no-contact-sheet", options->noContactSheet, "Do not write contact.html / contact.png");
    merge->callback([options] { runMerge(*options); });

    CLI::App* contact = stimuli->add_subcommand("contact", "Rewrite the contact sheet of a set folder");
    contact->add_option("dir", options->output, "Set folder")->required();
    contact->callback([options] { runContact(*options); });
}

} // namespace skinlab::cli
