#include "stimuli/slurm.h"

#include "common/error.h"
#include "common/files.h"
#include "common/process.h"
#include "common/time.h"
#include "stimuli/manifest.h"

#include <cctype>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <unistd.h>

namespace skinlab::stimuli {

namespace fs = std::filesystem;

namespace {

constexpr const char* kJobsFile = "jobs.json";
constexpr const char* kJobsFormat = "skinlab-slurm";

// ---- running Slurm's commands -------------------------------------------------------------------------------

// Slurm's commands run through common/process.h: found on PATH, stdout and stderr collected.
using ProgramRun = CapturedRun;
ProgramRun runProgram(const std::vector<std::string>& argv) {
    return runCaptured(argv.front(), std::vector<std::string>(argv.begin() + 1, argv.end()));
}
fs::path findOnPath(const std::string& program) { return findProgram(program); }

std::string trim(std::string text) {
    while (!text.empty() && std::isspace(static_cast<unsigned char>(text.back()))) text.pop_back();
    size_t start = 0;
    while (start < text.size() && std::isspace(static_cast<unsigned char>(text[start]))) ++start;
    return text.substr(start);
}

std::string firstLine(const std::string& text) {
    std::string t = trim(text);
    return t.substr(0, t.find('\n'));
}

// ---- the scripts ----------------------------------------------------------------------------------------------

fs::path absoluteNormal(const fs::path& p) { return fs::absolute(p).lexically_normal(); }

fs::path ownExecutable() {
    std::error_code ec;
    fs::path self = fs::read_symlink("/proc/self/exe", ec);
    if (ec)
        throw RuntimeError(std::string("cannot find the skinlab executable (/proc/self/exe: ") + ec.message() + ")");
    return self;
}

// The resource lines: the build task gets the per-task resources, both jobs the partition, account, time and
// the extra sbatch options.
std::string sbatchLines(const SlurmOptions& o, bool buildTask) {
    std::string s;
    if (!o.partition.empty()) s += "#SBATCH --partition=" + o.partition + "\n";
    if (!o.account.empty()) s += "#SBATCH --account=" + o.account + "\n";
    if (!o.time.empty()) s += "#SBATCH --time=" + o.time + "\n";
    if (buildTask) {
        s += "#SBATCH --ntasks=1\n";
        if (o.cpusPerTask > 0) s += "#SBATCH --cpus-per-task=" + std::to_string(o.cpusPerTask) + "\n";
        if (!o.mem.empty()) s += "#SBATCH --mem=" + o.mem + "\n";
        if (o.gpusPerTask > 0) s += "#SBATCH --gpus-per-task=" + std::to_string(o.gpusPerTask) + "\n";
    }
    for (const auto& a : o.sbatchArgs) s += "#SBATCH " + a + "\n";
    return s;
}

// "0-3" for shards 1..4; "2" for shard 3 alone.
std::string arrayRange(const std::vector<int>& shards) {
    if (shards.size() == 1) return std::to_string(shards.front() - 1);
    return std::to_string(shards.front() - 1) + "-" + std::to_string(shards.back() - 1);
}

void checkOption(bool ok, const std::string& option, const std::string& value, const std::string& message) {
    if (!ok) throwInput(option, "", "'" + value + "' " + message);
}

// Slurm option values go into "#SBATCH --x=VALUE" lines: one word, no newline.
void checkWord(const std::string& option, const std::string& value) {
    for (char c : value)
        checkOption(!std::isspace(static_cast<unsigned char>(c)) && c != '\'' && c != '"', option, value,
                    "must be one word without quotes");
}

nlohmann::json readJobs(const fs::path& out) {
    fs::path file = slurmFolder(out) / kJobsFile;
    if (!fs::exists(file)) return nullptr;
    nlohmann::json jobs;
    try {
        jobs = nlohmann::json::parse(readFile(file));
    } catch (const nlohmann::json::exception& e) {
        throwInput(file.string(), "", std::string("is not valid JSON (") + e.what() + ")");
    }
    if (!jobs.is_object() || jobs.value("format", "") != kJobsFormat || !jobs.contains("submissions"))
        throwInput(file.string(), "", "is not a skinlab Slurm job record");
    return jobs;
}

// "1234" from sbatch --parsable's "1234" or "1234;cluster".
std::string parsableJobId(const ProgramRun& run, const fs::path& script) {
    std::string id = firstLine(run.out);
    id = id.substr(0, id.find(';'));
    bool numeric = !id.empty() && id.find_first_not_of("0123456789") == std::string::npos;
    if (!numeric)
        throw RuntimeError("sbatch " + script.string() + ": no job id in its output ('" + firstLine(run.out) + "')");
    return id;
}

} // namespace

std::string shellQuote(const std::string& text) {
    std::string out = "'";
    for (char c : text) {
        if (c == '\'') out += "'\\''";
        else out += c;
    }
    return out + "'";
}

fs::path slurmFolder(const fs::path& out) { return out / "slurm"; }
fs::path shardFolder(const fs::path& out, int index) { return out / "shards" / std::to_string(index); }
fs::path mergedSetFolder(const fs::path& out) { return out / "set"; }

SlurmScripts slurmScripts(const SlurmOptions& o) {
    checkOption(o.shards >= 1, "--shards", std::to_string(o.shards), "is not a positive number");
    checkOption(o.jobsPerTask >= 1, "--jobs", std::to_string(o.jobsPerTask), "is not a positive number");
    checkOption(o.gpusPerTask >= 0, "--gpus-per-task", std::to_string(o.gpusPerTask), "is negative");
    for (const auto& [option, value] :
         {std::pair{"--partition", &o.partition}, {"--time", &o.time}, {"--account", &o.account}, {"--mem", &o.mem}})
        checkWord(option, *value);
    for (const auto& a : o.sbatchArgs) {
        checkOption(a.rfind("-", 0) == 0, "--sbatch", a, "is not an sbatch option (e.g. --qos=high)");
        checkOption(a.find('\n') == std::string::npos, "--sbatch", a, "holds a line break");
        for (const char* owned :
             {"--array", "--output", "--error", "--dependency", "--open-mode", "-a", "-o", "-e", "-d"})
            checkOption(a != owned && a.rfind(std::string(owned) + "=", 0) != 0 &&
                            (std::string(owned).size() != 2 || a.rfind(owned, 0) != 0),
                        "--sbatch", a, "is set by skinlab itself");
    }
    if (o.onlyShard)
        checkOption(*o.onlyShard >= 1 && *o.onlyShard <= o.shards, "--only-shard", std::to_string(*o.onlyShard),
                    "is not a shard of 1.." + std::to_string(o.shards));

    // The spec is checked here, once, rather than failing in every task.
    BuildPlan plan = planBuild(o.spec, o.specOverrides, std::nullopt, o.assetsDir);
    if (static_cast<size_t>(o.shards) > plan.all.size())
        throwInput("--shards", "",
                   std::to_string(o.shards) + " is more than the " + std::to_string(plan.all.size()) +
                       " stimuli of set '" + plan.spec.name + "'");

    const fs::path out = absoluteNormal(o.outputDir);
    std::error_code ec;
    if (fs::exists(out, ec)) {
        if (!fs::is_directory(out, ec)) throwInput(out.string(), "", "exists and is not a folder");
        nlohmann::json jobs = readJobs(out);
        if (jobs.is_null() && !fs::is_empty(out, ec))
            throwInput(out.string(), "",
                       "is not empty and holds no Slurm build (no slurm/jobs.json); choose a new or empty folder");
        if (!jobs.is_null()) {
            if (jobs.value("set", "") != plan.spec.name)
                throwInput(out.string(), "",
                           "holds a Slurm build of set '" + jobs.value("set", "") + "', not '" + plan.spec.name +
                               "'; choose another folder");
            if (jobs.value("shards", 0) != o.shards)
                throwInput(out.string(), "",
                           "was submitted with --shards " + std::to_string(jobs.value("shards", 0)) +
                               "; use the same number or a new folder");
        }
    }

    const fs::path skinlab = o.skinlab.empty() ? ownExecutable() : absoluteNormal(o.skinlab);
    const fs::path spec = absoluteNormal(o.spec);
    SlurmScripts s;
    s.set = plan.spec.name;
    s.stimuli = plan.all.size();
    s.buildPath = slurmFolder(out) / "build.sbatch";
    s.mergePath = slurmFolder(out) / "merge.sbatch";
    if (o.onlyShard) s.shards = {*o.onlyShard};
    else
        for (int i = 1; i <= o.shards; ++i) s.shards.push_back(i);
    const fs::path logs = slurmFolder(out) / "logs";

    std::string buildCommand = shellQuote(skinlab.string()) + " stimuli build " + shellQuote(spec.string()) +
                               " -o \"$dir\" --shard \"$i/$n\" --progress lines --no-contact-sheet";
    if (o.jobsPerTask > 1) buildCommand += " --jobs " + std::to_string(o.jobsPerTask);
    if (!o.assetsDir.empty()) buildCommand += " --assets " + shellQuote(absoluteNormal(o.assetsDir).string());
    for (const auto& v : o.specOverrides) buildCommand += " --set " + shellQuote(v);

    std::ostringstream b;
    b << "#!/bin/bash\n"
      << "# skinlab stimulus set '" << plan.spec.name << "': one array task per shard (" << plan.all.size()
      << " stimuli in " << o.shards << " shards).\n"
      << "# Written by `skinlab stimuli slurm`; a requeued task resumes its shard (finished stimuli are kept).\n"
      << "#SBATCH --job-name=skinlab-" << plan.spec.name << "\n"
      << "#SBATCH --array=" << arrayRange(s.shards) << "\n"
      << "#SBATCH --output=" << (logs / "build-%A_%a.log").string() << "\n"
      << "#SBATCH --open-mode=append\n"
      << "#SBATCH --requeue\n"
      << sbatchLines(o, true) << "set -euo pipefail\n"
      << ": \"${SLURM_ARRAY_TASK_ID:?submit this script with sbatch: it is a job array}\"\n"
      << "n=" << o.shards << "\n"
      << "i=$((SLURM_ARRAY_TASK_ID + 1))\n"
      << "dir=" << shellQuote((out / "shards").string()) << "/$i\n"
      << "echo \"skinlab: shard $i/$n of set '" << plan.spec.name
      << "' on $(hostname), job ${SLURM_ARRAY_JOB_ID}_${SLURM_ARRAY_TASK_ID}, attempt $((${SLURM_RESTART_COUNT:-0} + "
         "1)),"
         " $(date -u +%Y-%m-%dT%H:%M:%SZ)\"\n";
    if (o.assetsDir.empty()) {
        if (const char* assets = std::getenv("SKINLAB_ASSETS"); assets && *assets)
            b << "export SKINLAB_ASSETS=" << shellQuote(absoluteNormal(assets).string()) << "\n";
    }
    b << "status=0\n"
      << buildCommand << " || status=$?\n"
      << "if [ \"$status\" != 0 ]; then\n"
      << "  signal=\"\"; [ \"$status\" -gt 128 ] && signal=\" (signal $((status - 128)))\"\n"
      << "  echo \"skinlab: shard $i/$n failed: exit status $status$signal\" >&2\n"
      << "fi\n"
      << "exit \"$status\"\n";
    s.build = b.str();

    std::string mergeCommand = shellQuote(skinlab.string()) + " stimuli merge";
    for (int i = 1; i <= o.shards; ++i) mergeCommand += " " + shellQuote(shardFolder(out, i).string());
    mergeCommand += " -o " + shellQuote(mergedSetFolder(out).string());
    std::ostringstream m;
    m << "#!/bin/bash\n"
      << "# skinlab stimulus set '" << plan.spec.name << "': merges the " << o.shards
      << " shard folders once every array task has succeeded (submitted with --dependency=afterok).\n"
      << "#SBATCH --job-name=skinlab-" << plan.spec.name << "-merge\n"
      << "#SBATCH --output=" << (logs / "merge-%j.log").string() << "\n"
      << "#SBATCH --open-mode=append\n"
      << sbatchLines(o, false) << "set -euo pipefail\n"
      << "echo \"skinlab: merging set '" << plan.spec.name
      << "' on $(hostname), job ${SLURM_JOB_ID}, $(date -u +%Y-%m-%dT%H:%M:%SZ)\"\n"
      << mergeCommand << "\n";
    s.merge = m.str();
    return s;
}

SlurmSubmission submitSlurm(const SlurmOptions& o) {
    SlurmSubmission submission;
    submission.scripts = slurmScripts(o);
    if (o.dryRun) return submission;

    const fs::path sbatch = findOnPath("sbatch");
    if (sbatch.empty())
        throw RuntimeError("sbatch not found: install slurm-client (Debian/Ubuntu: apt-get install slurm-client) "
                           "or load your cluster's Slurm module, then submit again");

    const fs::path out = absoluteNormal(o.outputDir);
    ensureDirectory(slurmFolder(out) / "logs");
    ensureDirectory(out / "shards");
    writeFileAtomic(submission.scripts.buildPath, submission.scripts.build);
    writeFileAtomic(submission.scripts.mergePath, submission.scripts.merge);

    nlohmann::json jobs = readJobs(out);
    if (jobs.is_null())
        jobs = {{"format", kJobsFormat},
                {"version", 1},
                {"set", submission.scripts.set},
                {"spec", absoluteNormal(o.spec).string()},
                {"shards", o.shards},
                {"stimuli", submission.scripts.stimuli},
                {"submissions", nlohmann::json::array()}};
    // The new submission has its own merge job; an earlier one still waiting (on a failed shard, whose afterok
    // can never be satisfied, or on tasks now submitted again) is cancelled so that the set is merged once.
    if (!jobs["submissions"].empty()) {
        std::string oldMerge = jobs["submissions"].back().value("merge_job", "");
        fs::path scancel = findOnPath("scancel");
        fs::path squeue = findOnPath("squeue");
        if (!oldMerge.empty() && !scancel.empty() && !squeue.empty()) {
            ProgramRun state = runProgram({squeue.string(), "-h", "-j", oldMerge, "-o", "%T"});
            if (state.exitCode == 0 && trim(state.out) == "PENDING") {
                runProgram({scancel.string(), oldMerge});
                submission.cancelledMergeJob = oldMerge;
            }
        }
    }
    // The folder is this set's from now on, even if sbatch refuses the scripts (a corrected command may retry).
    writeFileAtomic(slurmFolder(out) / kJobsFile, jobs.dump(2) + "\n");
    nlohmann::json record = {
        {"submitted", utcTimestamp()}, {"shards", submission.scripts.shards}, {"command", o.command}};

    ProgramRun array = runProgram({sbatch.string(), "--parsable", submission.scripts.buildPath.string()});
    if (array.exitCode != 0)
        throw RuntimeError("sbatch " + submission.scripts.buildPath.string() + " failed (exit " +
                           std::to_string(array.exitCode) + "): " + firstLine(array.err + array.out));
    submission.arrayJob = parsableJobId(array, submission.scripts.buildPath);
    record["array_job"] = submission.arrayJob;
    jobs["submissions"].push_back(record);
    writeFileAtomic(slurmFolder(out) / kJobsFile, jobs.dump(2) + "\n");

    ProgramRun merge = runProgram({sbatch.string(), "--parsable", "--dependency=afterok:" + submission.arrayJob,
                                   submission.scripts.mergePath.string()});
    if (merge.exitCode != 0)
        throw RuntimeError("sbatch " + submission.scripts.mergePath.string() + " failed (exit " +
                           std::to_string(merge.exitCode) + "): " + firstLine(merge.err + merge.out) +
                           "; the array job " + submission.arrayJob + " was submitted");
    submission.mergeJob = parsableJobId(merge, submission.scripts.mergePath);
    jobs["submissions"].back()["merge_job"] = submission.mergeJob;
    writeFileAtomic(slurmFolder(out) / kJobsFile, jobs.dump(2) + "\n");
    return submission;
}

// ---- status ---------------------------------------------------------------------------------------------------

namespace {

struct JobState {
    std::string state; // Slurm's word, e.g. RUNNING, PENDING, FAILED
    std::string exitCode;
    std::string reason; // squeue's reason of a pending job, e.g. Dependency, DependencyNeverSatisfied
};

// Slurm's view of the given job ids ("12_3", "13"): squeue for queued and recent jobs, then sacct (accounting),
// then scontrol (jobs the controller still remembers, MinJobAge) for any id the others did not report.
std::map<std::string, JobState> queryJobs(const std::vector<std::string>& arrayJobs,
                                          const std::vector<std::string>& plainJobs, bool& queried) {
    std::map<std::string, JobState> states;
    std::vector<std::string> all = arrayJobs;
    all.insert(all.end(), plainJobs.begin(), plainJobs.end());
    queried = !findOnPath("squeue").empty() || !findOnPath("sacct").empty() || !findOnPath("scontrol").empty();
    if (all.empty()) return states;
    std::string list;
    for (const auto& id : all) list += (list.empty() ? "" : ",") + id;

    if (fs::path squeue = findOnPath("squeue"); !squeue.empty()) {
        queried = true;
        // One id at a time: squeue fails for the whole list when one id is unknown to the controller.
        for (const auto& id : all) {
            ProgramRun run = runProgram({squeue.string(), "-h", "-r", "-j", id, "-o", "%i|%T|%r"});
            if (run.exitCode != 0) continue;
            std::istringstream lines(run.out);
            std::string line;
            while (std::getline(lines, line)) {
                std::vector<std::string> f;
                std::stringstream fields(line);
                std::string field;
                while (std::getline(fields, field, '|')) f.push_back(trim(field));
                if (f.size() >= 2) states[f[0]] = {f[1], "", f.size() >= 3 && f[2] != "None" ? f[2] : ""};
            }
        }
    }
    if (fs::path sacct = findOnPath("sacct"); !sacct.empty()) {
        queried = true;
        ProgramRun run = runProgram({sacct.string(), "-n", "-P", "-X", "-j", list, "--format=JobID,State,ExitCode"});
        if (run.exitCode == 0) {
            std::istringstream lines(run.out);
            std::string line;
            while (std::getline(lines, line)) {
                std::vector<std::string> f;
                std::stringstream fields(line);
                std::string field;
                while (std::getline(fields, field, '|')) f.push_back(trim(field));
                if (f.size() < 3) continue;
                std::string word = f[1].substr(0, f[1].find(' ')); // "CANCELLED by 0"
                if (!states.count(f[0])) states[f[0]] = {word, f[2]};
                else states[f[0]].exitCode = f[2];
            }
        }
    }
    if (fs::path scontrol = findOnPath("scontrol"); !scontrol.empty()) {
        queried = true;
        for (const auto& id : all) {
            ProgramRun run = runProgram({scontrol.string(), "show", "job", "-o", id});
            if (run.exitCode != 0) continue;
            std::istringstream lines(run.out);
            std::string line;
            while (std::getline(lines, line)) {
                std::map<std::string, std::string> kv;
                std::istringstream words(line);
                std::string word;
                while (words >> word)
                    if (auto eq = word.find('='); eq != std::string::npos) kv[word.substr(0, eq)] = word.substr(eq + 1);
                std::string key = kv["JobId"];
                if (kv.count("ArrayJobId") && kv.count("ArrayTaskId")) {
                    const std::string& task = kv["ArrayTaskId"];
                    if (task.find_first_not_of("0123456789") != std::string::npos) continue; // a pending range
                    key = kv["ArrayJobId"] + "_" + task;
                }
                if (key.empty()) continue;
                auto& s = states[key];
                if (s.state.empty()) s.state = kv["JobState"];
                if (s.exitCode.empty()) s.exitCode = kv["ExitCode"];
            }
        }
    }
    return states;
}

std::string shardStateOf(const std::string& slurmState) {
    static const std::map<std::string, std::string> words = {
        {"PENDING", "pending"},     {"REQUEUED", "pending"},      {"REQUEUE_HOLD", "pending"},
        {"REQUEUE_FED", "pending"}, {"RESV_DEL_HOLD", "pending"}, {"CONFIGURING", "running"},
        {"RUNNING", "running"},     {"COMPLETING", "running"},    {"SUSPENDED", "running"},
        {"STAGE_OUT", "running"},   {"SIGNALING", "running"},     {"RESIZING", "running"}};
    auto it = words.find(slurmState);
    return it == words.end() ? "" : it->second;
}

std::string lastErrorLine(const fs::path& log) {
    std::ifstream in(log);
    std::string line, last;
    while (std::getline(in, line))
        if (line.rfind("skinlab: error:", 0) == 0 || line.rfind("skinlab: failure:", 0) == 0 ||
            (line.rfind("skinlab: shard ", 0) == 0 && line.find(" failed: ") != std::string::npos) ||
            (line.rfind("slurmstepd", 0) == 0 && line.find(" error: ") != std::string::npos))
            last = line;
    return last;
}

} // namespace

SlurmStatus slurmStatus(const fs::path& outArg) {
    const fs::path out = absoluteNormal(outArg);
    nlohmann::json jobs = readJobs(out);
    if (jobs.is_null())
        throwInput(out.string(), "",
                   "holds no Slurm build (no slurm/jobs.json); submit one with `skinlab stimuli slurm`");
    SlurmStatus status;
    status.set = jobs.value("set", "");
    status.shards = jobs.value("shards", 0);

    std::map<int, std::string> latestJob; // shard → ARRAYID_TASK
    std::vector<std::string> arrayJobs, mergeJobs;
    for (const auto& sub : jobs["submissions"]) {
        std::string array = sub.value("array_job", "");
        if (array.empty()) continue;
        arrayJobs.push_back(array);
        for (int i : sub.value("shards", std::vector<int>{})) latestJob[i] = array + "_" + std::to_string(i - 1);
        if (sub.contains("merge_job")) {
            status.mergeJob = sub["merge_job"].get<std::string>();
            if (!sub.value("command", "").empty()) status.resubmit = sub["command"].get<std::string>();
        }
    }
    if (!status.mergeJob.empty()) mergeJobs.push_back(status.mergeJob);
    std::map<std::string, JobState> slurm = queryJobs(arrayJobs, mergeJobs, status.slurmQueried);

    for (int i = 1; i <= status.shards; ++i) {
        ShardStatus s;
        s.index = i;
        bool complete = false;
        std::optional<Manifest> manifest;
        try {
            manifest = readManifest(shardFolder(out, i));
        } catch (const InputError&) {
        }
        // Shard i holds the stimuli whose index k has k mod n == i - 1.
        const size_t all = manifest ? manifest->setIds.size() : jobs.value("stimuli", size_t{0});
        const size_t n = static_cast<size_t>(status.shards);
        s.total = all / n + (static_cast<size_t>(i) <= all % n ? 1 : 0);
        if (manifest) {
            s.done = manifest->stimuli.size();
            complete = manifest->complete;
        }
        if (auto it = latestJob.find(i); it != latestJob.end()) {
            s.job = it->second;
            std::string array = s.job.substr(0, s.job.find('_'));
            s.log = slurmFolder(out) / "logs" / ("build-" + s.job + ".log");
            auto state = slurm.find(s.job);
            if (state == slurm.end()) state = slurm.find(array); // a pending array not yet split into tasks
            if (state != slurm.end()) {
                s.slurmState = state->second.state;
                if (!state->second.exitCode.empty() && state->second.exitCode != "0:0")
                    s.slurmState += " (exit " + state->second.exitCode + ")";
            }
            std::string queued = state == slurm.end() ? "" : shardStateOf(state->second.state);
            if (!queued.empty()) s.state = queued;
            else if (complete) s.state = "done";
            else if (state != slurm.end() || fs::exists(s.log)) s.state = "failed";
            else s.state = status.slurmQueried ? "failed" : "not started";
            if (s.state == "failed") s.lastError = lastErrorLine(s.log);
        } else {
            s.state = complete ? "done" : "not submitted";
        }
        status.shard.push_back(std::move(s));
    }

    std::optional<Manifest> merged;
    try {
        merged = readManifest(mergedSetFolder(out));
    } catch (const InputError&) {
    }
    if (!status.mergeJob.empty()) {
        status.mergeLog = slurmFolder(out) / "logs" / ("merge-" + status.mergeJob + ".log");
        auto state = slurm.find(status.mergeJob);
        std::string queued = state == slurm.end() ? "" : shardStateOf(state->second.state);
        if (!queued.empty()) {
            status.mergeState = queued;
            if (state->second.reason == "DependencyNeverSatisfied")
                status.mergeState += " (never runs: a shard failed; resubmit it)";
            else if (!state->second.reason.empty()) status.mergeState += " (" + state->second.reason + ")";
        } else if (merged && merged->complete) status.mergeState = "done";
        else if (state != slurm.end()) status.mergeState = "failed (" + state->second.state + ")";
        else status.mergeState = fs::exists(status.mergeLog) ? "failed" : "unknown";
    }
    return status;
}

} // namespace skinlab::stimuli
