// `skinlab stimuli build|list|merge|contact|visibility|slurm|status|calibrate`: stimulus sets (docs/stimuli.md). `import`: in
// cmd_stimuli_import.cpp.
#include "analysis/metrics/cvvdp.h"
#include "cli/commands.h"
#include "cli/options.h"
#include "common/error.h"
#include "common/files.h"
#include "stimuli/build.h"
#include "stimuli/calibrate.h"
#include "stimuli/contact_sheet.h"
#include "stimuli/merge.h"
#include "stimuli/output_folder.h"
#include "stimuli/slurm.h"
#include "stimuli/visibility.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <memory>

namespace skinlab::cli {

namespace {

struct StimuliOptions {
    bool noPredict = false;
    DisplayArguments display; // build (predictions) and calibrate: ColorVideoVDP's display, --display and --display-*
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
    // slurm
    int shards = 4;
    std::string partition, time, account, mem;
    int gpusPerTask = 0;
    int cpusPerTask = 0;
    std::vector<std::string> sbatchArgs;
    int onlyShard = 0;
    bool dryRun = false;
    std::string skinlab;
    // calibrate
    std::string factor, targetJod, range, stimulus; // and `display` (shared with build)
    std::optional<double> referenceLevel;
    double tolerance = 0.05;
    int maxProbes = 24;
    // visibility
    std::optional<std::string> visibilityDisplay;
    std::vector<double> visibilityPpd = stimuli::kVisibilityPixelsPerDegree;
    int visibilityJobs = 2;
};

// The submission as one command line (absolute paths, without --only-shard and --dry-run), recorded so that
// `stimuli status` can say how to resubmit a failed shard.
std::string slurmCommandLine(const StimuliOptions& o) {
    namespace fs = std::filesystem;
    auto q = [](const std::string& v) { return stimuli::shellQuote(v); };
    auto abs = [&](const std::string& p) { return q(fs::absolute(p).lexically_normal().string()); };
    std::string c =
        "skinlab stimuli slurm " + abs(o.spec) + " -o " + abs(o.output) + " --shards " + std::to_string(o.shards);
    if (!o.assets.empty()) c += " --assets " + abs(o.assets);
    for (const auto& v : o.overrides) c += " --set " + q(v);
    if (!o.partition.empty()) c += " --partition " + q(o.partition);
    if (!o.time.empty()) c += " --time " + q(o.time);
    if (!o.account.empty()) c += " --account " + q(o.account);
    if (o.gpusPerTask > 0) c += " --gpus-per-task " + std::to_string(o.gpusPerTask);
    if (o.cpusPerTask > 0) c += " --cpus-per-task " + std::to_string(o.cpusPerTask);
    if (!o.mem.empty()) c += " --mem " + q(o.mem);
    if (o.jobs > 1) c += " --jobs " + std::to_string(o.jobs);
    for (const auto& a : o.sbatchArgs) c += " --sbatch=" + q(a);
    if (!o.skinlab.empty()) c += " --skinlab " + abs(o.skinlab);
    return c;
}

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
    options.predict = !o.noPredict;
    if (options.predict) options.display = o.display.resolve(); // a bad display fails before anything renders
    options.progress = o.progress == "bar"     ? stimuli::BuildOptions::ProgressStyle::bar
                       : o.progress == "lines" ? stimuli::BuildOptions::ProgressStyle::lines
                                               : stimuli::BuildOptions::ProgressStyle::automatic;
    stimuli::BuildSummary summary = stimuli::buildSet(options);
    std::printf("stimuli: %zu stimuli (%zu rendered, %zu unchanged) in %.1f s; manifest: %s\n", summary.stimuli,
                summary.rendered, summary.kept, summary.wallSeconds, summary.manifest.string().c_str());
    if (!summary.contactHtml.empty()) std::printf("contact sheet: %s\n", summary.contactHtml.string().c_str());
    for (const std::string& line : summary.predictions) std::printf("stimuli: predicted: %s\n", line.c_str());
    if (summary.invisibleBlock)
        std::printf("stimuli: warning: some blocks' conditions are predicted to look alike (see above); a study of "
                    "them would measure (almost) nothing\n");
}

void runList(const StimuliOptions& o) {
    stimuli::BuildPlan plan = stimuli::planBuild(o.spec, o.overrides, shardOption(o.shard), o.assets);
    if (o.format == "json") {
        nlohmann::json out = nlohmann::json::array();
        for (size_t i = 0; i < plan.selected.size(); ++i)
            out.push_back(stimuli::plannedEntryJson(plan.selected[i], plan.resolved[i]));
        std::cout << out.dump(2) << "\n";
        return;
    }
    std::printf("set %s: %zu stimuli%s\n", plan.spec.name.c_str(), plan.selected.size(),
                o.shard.empty() ? "" : (" (shard " + o.shard + " of " + std::to_string(plan.all.size()) + ")").c_str());
    for (const auto& s : plan.selected) {
        std::string overrides;
        for (const auto& a : s.overrides) overrides += " " + a;
        // Presentation (docs/stimuli.md): only when it is not the whole frame at magnification 1.
        if (const auto& c = s.presentation.crop)
            overrides += " crop=" + std::to_string(c->x) + "," + std::to_string(c->y) + "," + std::to_string(c->width) +
                         "x" + std::to_string(c->height);
        if (s.presentation.magnification != 1)
            overrides += " magnification=" + std::to_string(s.presentation.magnification);
        if (s.presentation.method == stimuli::PresentationMethod::replicate && s.presentation.magnification != 1)
            overrides += " presentation=replicate";
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

void runVisibility(const StimuliOptions& o) {
    std::optional<stimuli::Manifest> manifest = stimuli::readManifest(o.output);
    if (!manifest) throwInput(o.output, "", "holds no stimulus set (no manifest.json)");
    stimuli::VisibilityOptions options;
    options.display = o.visibilityDisplay.value_or("");
    options.pixelsPerDegree = o.visibilityPpd;
    options.jobs = o.visibilityJobs;
    const stimuli::VisibilityTable table = stimuli::computeVisibility(o.output, *manifest, options);
    stimuli::writeVisibility(o.output, table);
    const stimuli::ContactSheetFiles files = stimuli::writeContactSheet(o.output, *manifest);
    std::printf("visibility: %zu stimuli x %zu pixels per degree on %s (%s) in %.1f s\n", table.rows.size(),
                table.pixelsPerDegree.size(), table.display.name.c_str(), table.displaySource.c_str(), table.seconds);
    std::printf("visibility: %s, %s, %s; contact sheet: %s\n",
                (std::filesystem::path(o.output) / "visibility.json").c_str(),
                (std::filesystem::path(o.output) / "visibility.csv").c_str(),
                (std::filesystem::path(o.output) / "visibility.svg").c_str(), files.html.c_str());
}

void runSlurm(const StimuliOptions& o) {
    stimuli::SlurmOptions options;
    options.spec = o.spec;
    options.specOverrides = o.overrides;
    options.outputDir = o.output;
    options.assetsDir = o.assets;
    options.shards = o.shards;
    options.jobsPerTask = o.jobs;
    options.partition = o.partition;
    options.time = o.time;
    options.account = o.account;
    options.mem = o.mem;
    options.gpusPerTask = o.gpusPerTask;
    options.cpusPerTask = o.cpusPerTask;
    options.sbatchArgs = o.sbatchArgs;
    if (o.onlyShard > 0) options.onlyShard = o.onlyShard;
    options.dryRun = o.dryRun;
    options.skinlab = o.skinlab;
    options.command = slurmCommandLine(o);
    stimuli::SlurmSubmission submission = stimuli::submitSlurm(options);
    const auto& scripts = submission.scripts;
    if (o.dryRun) {
        std::printf("# %s\n%s\n# %s\n%s\n", scripts.buildPath.string().c_str(), scripts.build.c_str(),
                    scripts.mergePath.string().c_str(), scripts.merge.c_str());
        std::printf("# dry run, nothing written or submitted; without --dry-run:\n#   sbatch --parsable %s\n"
                    "#   sbatch --parsable --dependency=afterok:ARRAY_JOB_ID %s\n",
                    scripts.buildPath.string().c_str(), scripts.mergePath.string().c_str());
        return;
    }
    if (!submission.cancelledMergeJob.empty())
        std::printf("stimuli: cancelled the earlier merge job %s (this submission merges the set)\n",
                    submission.cancelledMergeJob.c_str());
    std::printf("stimuli: set '%s': array job %s (%zu shard task(s)), merge job %s (afterok:%s)\n", scripts.set.c_str(),
                submission.arrayJob.c_str(), scripts.shards.size(), submission.mergeJob.c_str(),
                submission.arrayJob.c_str());
    std::printf("scripts: %s, %s; logs: %s\n", scripts.buildPath.string().c_str(), scripts.mergePath.string().c_str(),
                (scripts.buildPath.parent_path() / "logs").string().c_str());
    std::printf("progress: skinlab stimuli status %s\n", o.output.c_str());
}

void runStatus(const StimuliOptions& o) {
    stimuli::SlurmStatus status = stimuli::slurmStatus(o.output);
    if (o.format == "json") {
        nlohmann::json out = {
            {"set", status.set},
            {"shards", nlohmann::json::array()},
            {"merge", {{"job", status.mergeJob}, {"state", status.mergeState}, {"log", status.mergeLog.string()}}}};
        for (const auto& s : status.shard)
            out["shards"].push_back({{"shard", s.index},
                                     {"state", s.state},
                                     {"done", s.done},
                                     {"total", s.total},
                                     {"job", s.job},
                                     {"slurm_state", s.slurmState},
                                     {"log", s.log.string()},
                                     {"error", s.lastError}});
        std::cout << out.dump(2) << "\n";
        return;
    }
    std::printf("set %s: %d shards%s\n", status.set.c_str(), status.shards,
                status.slurmQueried ? "" : " (no Slurm commands on PATH: states from the shard folders only)");
    std::vector<int> failed;
    for (const auto& s : status.shard) {
        std::printf("shard %d/%d  %-13s %zu/%zu stimuli  job %s%s%s\n", s.index, status.shards, s.state.c_str(), s.done,
                    s.total, s.job.empty() ? "-" : s.job.c_str(), s.slurmState.empty() ? "" : "  ",
                    s.slurmState.c_str());
        if (s.state == "failed") {
            failed.push_back(s.index);
            std::printf("    log: %s\n", s.log.string().c_str());
            if (!s.lastError.empty()) std::printf("    %s\n", s.lastError.c_str());
        }
    }
    if (!status.mergeJob.empty())
        std::printf("merge  %s  job %s  log: %s\n", status.mergeState.c_str(), status.mergeJob.c_str(),
                    status.mergeLog.string().c_str());
    for (int i : failed)
        std::printf("resubmit shard %d: %s --only-shard %d\n", i,
                    status.resubmit.empty() ? "skinlab stimuli slurm SPEC -o OUT ..." : status.resubmit.c_str(), i);
}

// "a,b,c" → numbers; InputError naming `option` for anything else.
std::vector<double> numberList(const std::string& text, const std::string& option) {
    std::vector<double> out;
    size_t begin = 0;
    while (true) {
        size_t end = text.find(',', begin);
        std::string item = text.substr(begin, end == std::string::npos ? std::string::npos : end - begin);
        char* stop = nullptr;
        double v = std::strtod(item.c_str(), &stop);
        if (item.empty() || stop != item.c_str() + item.size() || !std::isfinite(v))
            throwInput(option, "", "'" + item + "' in '" + text + "' is not a number");
        out.push_back(v);
        if (end == std::string::npos) return out;
        begin = end + 1;
    }
}

void runCalibrate(const StimuliOptions& o) {
    stimuli::CalibrateOptions options;
    options.spec = o.spec;
    options.specOverrides = o.overrides;
    options.assetsDir = o.assets;
    options.factor = o.factor;
    options.targets = numberList(o.targetJod, "--target-jod");
    options.referenceLevel = o.referenceLevel;
    if (!o.range.empty()) {
        std::vector<double> range = numberList(o.range, "--range");
        if (range.size() != 2) throwInput("--range", "", "'" + o.range + "' must be LO,HI");
        options.range = std::pair{range[0], range[1]};
    }
    options.tolerance = o.tolerance;
    options.maxProbes = o.maxProbes;
    options.display = o.display.resolve();
    options.stimulus = o.stimulus;
    if (!o.output.empty() && std::filesystem::is_directory(o.output))
        throwInput("-o", "", o.output + " is a folder (give the TOML file to write)");
    stimuli::CalibrationReport report = stimuli::calibrateLevels(options);
    const auto& r = report.result;
    std::printf("calibrate %s: stimulus %s against %s\n", report.key.c_str(), report.stimulus.c_str(),
                report.reference.c_str());
    std::printf("display %s; tolerance %g JOD\n", report.display.c_str(), report.search.tolerance);
    std::printf("range %s .. %s: difference %.3f JOD at %s, %.3f JOD at %s\n",
                stimuli::levelText(report.search.lo, report.integral).c_str(),
                stimuli::levelText(report.search.hi, report.integral).c_str(), r.differenceAtLo,
                stimuli::levelText(report.search.lo, report.integral).c_str(), r.differenceAtHi,
                stimuli::levelText(report.search.hi, report.integral).c_str());
    std::printf("%-10s %-14s %-12s %s\n", "target", "value", "achieved", "renders");
    for (const auto& level : r.levels) {
        std::printf("%-10g %-14s %-12.3f %d%s%s\n", level.targetJod,
                    stimuli::levelText(level.value, report.integral).c_str(), level.achievedJod, level.renders,
                    level.reached ? "" : "  NOT REACHED: ", level.note.c_str());
    }
    std::printf("renders: %d (the reference, both ends and %d probes) in %.1f s\n", report.renders, r.predictions - 2,
                report.wallSeconds);
    for (const auto& w : r.warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
    const std::string toml = stimuli::levelsToml(report);
    if (o.output.empty()) {
        std::printf("\n%s", toml.c_str());
    } else {
        writeFileAtomic(o.output, toml);
        std::printf("levels: %s\n", o.output.c_str());
    }
}

} // namespace

void registerStimuli(CLI::App& app) {
    auto options = std::make_shared<StimuliOptions>();
    CLI::App* stimuli = app.add_subcommand(
        "stimuli", "Build, list, merge and inspect stimulus sets, locally or on a Slurm cluster (docs/stimuli.md)");
    stimuli->require_subcommand(1);

    // `stimuli slurm` shards by --shards itself, so it has no --shard.
    auto specOptions = [&](CLI::App* cmd, bool shard = true) {
        cmd->add_option("spec", options->spec, "Stimulus-set spec (TOML), e.g. stimuli/specs/demo.toml")->required();
        if (shard) cmd->add_option("--shard", options->shard, "Only slice i of n (1-based), e.g. 2/8");
        addAssetsOption(*cmd, options->assets);
        addOverridesOption(*cmd, options->overrides, "spec value");
    };

    CLI::App* build = stimuli->add_subcommand("build", "Render a stimulus set (resumable) into a folder");
    specOptions(build);
    build->add_option("-o,--output", options->output, "Output folder of the set")->required();
    build->add_option("--jobs", options->jobs, "Parallel renderers, one EGL context each (default 1)")
        ->check(CLI::Range(1, 64));
    build->add_flag("--no-contact-sheet", options->noContactSheet, "Do not write contact.html / contact.png");
    build->add_flag("--no-predict", options->noPredict,
                    "Do not predict each stimulus's visibility against its block's reference (ColorVideoVDP)");
    addDisplayOptions(*build, options->display, "Display model of the predictions (default standard_fhd)");
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

    CLI::App* visibility = stimuli->add_subcommand(
        "visibility", "Predicted JOD of every condition against its block's reference at a range of pixels per degree "
                      "(viewing distances): visibility.json, .csv, .svg and the contact sheet (docs/stimuli.md)");
    visibility->add_option("dir", options->output, "Set folder (built, with a reference in its blocks)")->required();
    visibility->add_option("--display", options->visibilityDisplay,
                           "Display model whose photometry is used (default: the display of the set's predictions)");
    visibility
        ->add_option("--ppd", options->visibilityPpd,
                     "Pixels per degree to predict at, ascending, comma-separated (default 20,30,40,60,80,120)")
        ->delimiter(',');
    visibility->add_option("--jobs", options->visibilityJobs, "Threads (default 2)");
    visibility->callback([options] { runVisibility(*options); });

    CLI::App* slurm = stimuli->add_subcommand(
        "slurm", "Build a set on a Slurm cluster: a job array (one task per shard) and a merge job (afterok)");
    specOptions(slurm, false);
    slurm
        ->add_option("-o,--output", options->output,
                     "Folder on the shared file system: shards/I, set (the merged set), slurm (scripts, logs, job ids)")
        ->required();
    slurm->add_option("--shards", options->shards, "Number of shards = array tasks (default 4)")
        ->check(CLI::Range(1, 100000));
    slurm->add_option("--partition", options->partition, "sbatch --partition");
    slurm->add_option("--time", options->time, "sbatch --time of each task and of the merge, e.g. 1:00:00");
    slurm->add_option("--account", options->account, "sbatch --account");
    slurm
        ->add_option("--gpus-per-task", options->gpusPerTask,
                     "sbatch --gpus-per-task (GPU through the EGL device platform)")
        ->check(CLI::Range(0, 64));
    slurm->add_option("--cpus-per-task", options->cpusPerTask, "sbatch --cpus-per-task")->check(CLI::Range(0, 4096));
    slurm->add_option("--mem", options->mem, "sbatch --mem of each task, e.g. 8G");
    slurm->add_option("--jobs", options->jobs, "Renderers per task (build --jobs, default 1)")
        ->check(CLI::Range(1, 64));
    slurm
        ->add_option("--sbatch", options->sbatchArgs,
                     "Another sbatch option for both jobs, e.g. --sbatch=--qos=high (repeatable)")
        ->allow_extra_args(false);
    slurm->add_option("--only-shard", options->onlyShard, "Resubmit shard I alone (and a new merge job)")
        ->check(CLI::Range(1, 100000));
    slurm->add_flag("--dry-run", options->dryRun, "Print the sbatch scripts; write and submit nothing");
    slurm->add_option("--skinlab", options->skinlab, "The skinlab executable the tasks run (default: this one)");
    slurm->callback([options] { runSlurm(*options); });

    CLI::App* status =
        stimuli->add_subcommand("status", "Per shard of a Slurm build: done, running, pending or failed");
    status->add_option("dir", options->output, "The folder given to `stimuli slurm -o`")->required();
    status->add_option("--format", options->format, "text or json")->check(CLI::IsMember({"text", "json"}));
    status->callback([options] { runStatus(*options); });

    CLI::App* calibrate = stimuli->add_subcommand(
        "calibrate", "Levels of a numeric parameter whose predicted difference (ColorVideoVDP) from the reference "
                     "is a given number of JOD");
    calibrate->add_option("spec", options->spec, "Stimulus-set spec (TOML)")->required();
    addAssetsOption(*calibrate, options->assets);
    addOverridesOption(*calibrate, options->overrides, "spec value");
    calibrate->add_option("--factor", options->factor, "Numeric scene key to calibrate, e.g. sss.width_mm")->required();
    calibrate
        ->add_option("--target-jod", options->targetJod,
                     "Wanted differences from the reference in JOD, comma-separated, e.g. 0.5,1,2")
        ->required();
    calibrate->add_option("--reference-level", options->referenceLevel,
                          "Reference = the stimulus at this value of the key (default: the block's [[reference]])");
    calibrate->add_option("--range", options->range,
                          "LO,HI searched (default: the smallest and largest level of the spec's factor)");
    calibrate->add_option("--tolerance", options->tolerance, "JOD within which a target counts as reached (0.05)");
    calibrate->add_option("--max-probes", options->maxProbes, "Renders per target at most (24)");
    addDisplayOptions(*calibrate, options->display, "ColorVideoVDP display model (default standard_fhd)");
    calibrate->add_option("--stimulus", options->stimulus,
                          "Id of the stimulus whose key varies (default: the first that is not a reference)");
    calibrate->add_option("-o,--output", options->output, "Write the [[factor]] snippet to this file (atomically)");
    calibrate->callback([options] { runCalibrate(*options); });

    registerStimuliImport(*stimuli); // cmd_stimuli_import.cpp
}

} // namespace skinlab::cli
